// bench_abuffer: rasterize + capture throughput of the A-buffer (the unbounded reference every
// bounded method is measured against; "foundation" item 8).
//
// For procedural:layers (defaults: n = 128 fragments on half of the pixels) and procedural:hairball
// it times, as the median of --reps runs at --size x --size:
//   set-up   RasterFrame::build (transform, clip, bin)       once per frame, shared by every method
//   count    the count pass (coverage raster, n(p))
//   alloc    allocate + clear (prefix sum, node buffer)
//   capture  the store pass (full shading, append into exact-size arrays)
//   resolve  per-pixel sort + front-to-back compositing
// and reports throughput in fragments/s and ns/fragment for count + capture (the "rasterize +
// capture" figure: the A-buffer rasterizes every fragment twice) and for each pass alone. The goal
// printed next to it is at least 100 M fragments/s for layers on the 2-core reference machine.
// It mirrors the A-buffer / S-buffer cost the papers take as ground truth (k+-buffer paper sec. 4,
// variable k-buffer paper Table 2 reference column). CSV: abuffer.csv.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "mfr/method/method.hpp"
#include "mfr/method/render.hpp"
#include "mfr/raster/raster_frame.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/load.hpp"

namespace {

using namespace mfr;
using Clock = std::chrono::steady_clock;

constexpr double kGoalMFragPerS = 100.0;  // layers, rasterize + capture, 1024x1024, 2 cores

constexpr const char* kUsage =
    "[--out DIR] [--size N] [--threads N] [--reps N] [--quick]\n"
    "  --out DIR     directory for abuffer.csv (default bench-results)\n"
    "  --size N      image is N x N pixels (default 1024; --quick: 256)\n"
    "  --threads N   worker threads (default 0 = all cores)\n"
    "  --reps N      runs per measurement, the median is reported (default 3; --quick: 1)\n"
    "  --quick       smoke run: smaller image, one run\n";

// ---- command line (the same options in every bench program) -----------------------------

struct Args {
  std::string out = "bench-results";
  int size = 1024;
  int threads = 0;  // 0 = all cores
  int reps = 3;
  bool quick = false;
};

void usage(const char* prog) {
  std::printf("usage: %s %s", prog, kUsage);
}

bool parseInt(const char* text, int lo, int hi, int& value) {
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (errno != 0 || end == text || *end != '\0' || v < lo || v > hi) return false;
  value = static_cast<int>(v);
  return true;
}

bool parseArgs(int argc, char** argv, Args& a) {
  bool sizeSet = false, repsSet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
    auto intOption = [&](int lo, int hi, int& target) {
      if (!value || !parseInt(value, lo, hi, target)) {
        std::fprintf(stderr, "%s: %s needs an integer in [%d, %d]\n", argv[0], arg.c_str(), lo, hi);
        return false;
      }
      ++i;
      return true;
    };
    if (arg == "--out" && value) {
      a.out = value;
      ++i;
    } else if (arg == "--size") {
      if (!intOption(16, kMaxImageSize, a.size)) return false;
      sizeSet = true;
    } else if (arg == "--threads") {
      if (!intOption(0, 1024, a.threads)) return false;
    } else if (arg == "--reps") {
      if (!intOption(1, 1000, a.reps)) return false;
      repsSet = true;
    } else if (arg == "--quick") {
      a.quick = true;
    } else if (arg == "--help" || arg == "-h") {
      usage(argv[0]);
      std::exit(0);
    } else {
      std::fprintf(stderr, "%s: unknown or incomplete option '%s'\n", argv[0], arg.c_str());
      usage(argv[0]);
      return false;
    }
  }
  if (a.quick && !sizeSet) a.size = 256;
  if (a.quick && !repsSet) a.reps = 1;
  return true;
}

// ---- formatting: aligned tables on stdout, CSV files -------------------------------------------

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string num(uint64_t v) {
  return std::to_string(v);
}

class Table {
 public:
  explicit Table(std::vector<std::string> header) { rows_.push_back(std::move(header)); }
  void add(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
  // text columns are left-aligned (the first one always), numbers right-aligned
  void leftAlign(size_t column) { left_.push_back(column); }
  void print() const {
    std::vector<size_t> width;
    for (const auto& row : rows_)
      for (size_t c = 0; c < row.size(); ++c) {
        if (width.size() <= c) width.push_back(0);
        width[c] = std::max(width[c], row[c].size());
      }
    for (size_t r = 0; r < rows_.size(); ++r) {
      std::string line;
      for (size_t c = 0; c < rows_[r].size(); ++c) {
        const std::string& cell = rows_[r][c];
        const std::string pad(width[c] - cell.size(), ' ');
        const bool left = c == 0 || std::find(left_.begin(), left_.end(), c) != left_.end();
        if (c > 0) line += "  ";
        line += left ? cell : pad;
        line += left ? pad : cell;
      }
      while (!line.empty() && line.back() == ' ') line.pop_back();
      std::printf("%s\n", line.c_str());
      if (r == 0) {
        size_t total = 0;
        for (size_t w : width) total += w + 2;
        std::printf("%s\n", std::string(total - 2, '-').c_str());
      }
    }
  }

 private:
  std::vector<std::vector<std::string>> rows_;
  std::vector<size_t> left_;
};

class Csv {
 public:
  // header: the column names, comma-separated
  Csv(const std::filesystem::path& path, const std::string& header) : path_(path), file_(path) {
    file_ << header << '\n';
  }
  bool ok() const { return static_cast<bool>(file_); }
  const std::filesystem::path& path() const { return path_; }
  void row(const std::vector<std::string>& cells) {
    for (size_t c = 0; c < cells.size(); ++c) {
      if (c) file_ << ',';
      const std::string& s = cells[c];
      if (s.find_first_of(",\"\n") == std::string::npos) {
        file_ << s;
      } else {
        file_ << '"';
        for (char ch : s) file_ << (ch == '"' ? "\"\"" : std::string(1, ch));
        file_ << '"';
      }
    }
    file_ << '\n' << std::flush;
  }

 private:
  std::filesystem::path path_;
  std::ofstream file_;
};

// ---- measurement -------------------------------------------------------------------------------

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

struct Measured {
  RenderStats stats;                     // statistics of the last run (counters are deterministic)
  ImageRGB image;                        // image of the last run
  std::map<std::string, double> passMs;  // median over the runs, per pass
  double totalMs = 0.0;                  // median of the runs' totals
  double pass(const std::string& name) const {
    const auto it = passMs.find(name);
    return it == passMs.end() ? 0.0 : it->second;
  }
};

Result<Measured> measure(const RasterFrame& frame, const MethodDesc& method,
                         const RenderOptions& options, int reps) {
  std::map<std::string, std::vector<double>> samples;
  std::vector<double> totals;
  Measured m;
  for (int r = 0; r < reps; ++r) {
    auto out = render(frame, method, options);
    if (!out) return out.error();
    for (const PassTime& p : out->stats.passes) samples[p.name].push_back(p.ms);
    totals.push_back(out->stats.totalMs());
    if (r + 1 == reps) {
      m.stats = std::move(out->stats);
      m.image = std::move(out->image);
    }
  }
  for (auto& [name, values] : samples) m.passMs[name] = median(values);
  m.totalMs = median(totals);
  return m;
}

Camera sceneCamera(const Scene& scene) {
  return scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
}

// throughput of `fragments` processed in `ms`
double mfragPerS(uint64_t fragments, double ms) {
  return ms > 0.0 ? static_cast<double>(fragments) / (ms * 1e3) : 0.0;
}
double nsPerFrag(uint64_t fragments, double ms) {
  return fragments ? ms * 1e6 / static_cast<double>(fragments) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parseArgs(argc, argv, args)) return 2;
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  Csv csv(std::filesystem::path(args.out) / "abuffer.csv",
          "scene,source,width,height,threads,reps,triangles,fragments,covered_pixels,max_depth,"
          "setup_ms,count_ms,alloc_ms,capture_ms,resolve_ms,total_ms,rc_ms,rc_mfrag_s,"
          "rc_ns_frag,count_mfrag_s,count_ns_frag,capture_mfrag_s,capture_ns_frag,"
          "resolve_mfrag_s,resolve_ns_frag,total_mfrag_s,goal_mfrag_s");
  if (!csv.ok()) {
    std::fprintf(stderr, "bench_abuffer: cannot write %s\n", csv.path().c_str());
    return 1;
  }

  std::printf(
      "bench_abuffer: A-buffer rasterize + capture throughput, %dx%d, %d thread(s) (%u cores),"
      " median of %d run(s)\n",
      args.size, args.size, resolveThreads(args.threads), std::thread::hardware_concurrency(),
      args.reps);

  struct SceneCase {
    std::string label, source;
  };
  const std::vector<SceneCase> scenes = {{"layers", "procedural:layers"},
                                         {"hairball", "procedural:hairball"}};
  bool failed = false;
  for (const SceneCase& sc : scenes) {
    auto loaded = loadScene(sc.source);
    if (!loaded) {
      std::fprintf(stderr, "bench_abuffer: %s\n", loaded.error().message.c_str());
      failed = true;
      continue;
    }
    const Scene& scene = loaded.value();
    const RasterOptions ro{args.size, args.size, 32, args.threads};
    std::vector<double> setupTimes;
    std::optional<RasterFrame> frame;
    for (int r = 0; r < args.reps; ++r) {
      const auto start = Clock::now();
      auto built = RasterFrame::build(scene, sceneCamera(scene), ro);
      setupTimes.push_back(msSince(start));
      if (!built) {
        std::fprintf(stderr, "bench_abuffer: %s\n", built.error().message.c_str());
        return 1;
      }
      frame.emplace(std::move(built.value()));
    }
    const double setupMs = median(setupTimes);

    auto method = methodPreset("abuffer");
    MFR_CHECK(method.ok());
    auto measured = measure(*frame, method.value(), RenderOptions{}, args.reps);
    if (!measured) {
      std::fprintf(stderr, "bench_abuffer: %s: %s\n", sc.label.c_str(),
                   measured.error().message.c_str());
      failed = true;
      continue;
    }
    const Measured& m = measured.value();
    const RenderStats& s = m.stats;
    const uint64_t frags = s.fragmentsGenerated;
    const double countMs = m.pass("count"), captureMs = m.pass("capture");
    const double allocMs = m.pass("allocate") + m.pass("clear"), resolveMs = m.pass("resolve");
    const double rcMs = countMs + captureMs;

    std::printf("\n%s (%s): %zu triangles, %llu fragments, %llu covered pixels, max depth %u\n",
                sc.label.c_str(), sc.source.c_str(), scene.triangleCount(),
                static_cast<unsigned long long>(frags),
                static_cast<unsigned long long>(s.coveredPixels), s.maxDepthComplexity.value_or(0));
    if (s.fragmentSlots != frags)
      std::printf("  note: count pass saw %llu fragments but capture generated %llu\n",
                  static_cast<unsigned long long>(s.fragmentSlots),
                  static_cast<unsigned long long>(frags));
    Table t({"pass", "ms", "M frag/s", "ns/frag"});
    auto rate = [&](const std::string& name, double ms) {
      t.add({name, fixed(ms, 1), fixed(mfragPerS(frags, ms), 1), fixed(nsPerFrag(frags, ms), 2)});
    };
    t.add({"set-up (build)", fixed(setupMs, 1), "-", "-"});
    rate("count", countMs);
    t.add({"alloc + clear", fixed(allocMs, 1), "-", "-"});
    rate("capture (store)", captureMs);
    rate("count + capture", rcMs);
    rate("resolve", resolveMs);
    rate("render total", m.totalMs);
    t.print();
    const double rc = mfragPerS(frags, rcMs);
    if (sc.label == "layers") {
      std::string where;
      if (args.size != 1024) {
        where = " (measured at ";
        where += std::to_string(args.size);
        where += "x";
        where += std::to_string(args.size);
        where += "; the goal is stated for 1024x1024)";
      }
      std::printf("goal: rasterize + capture >= %.0f M fragments/s: %.1f M/s -> %s%s\n",
                  kGoalMFragPerS, rc, rc >= kGoalMFragPerS ? "MET" : "NOT MET", where.c_str());
    }

    csv.row({sc.label,
             sc.source,
             std::to_string(args.size),
             std::to_string(args.size),
             std::to_string(frame->threads()),
             std::to_string(args.reps),
             num(scene.triangleCount()),
             num(frags),
             num(s.coveredPixels),
             num(s.maxDepthComplexity.value_or(0)),
             fixed(setupMs, 3),
             fixed(countMs, 3),
             fixed(allocMs, 3),
             fixed(captureMs, 3),
             fixed(resolveMs, 3),
             fixed(m.totalMs, 3),
             fixed(rcMs, 3),
             fixed(rc, 2),
             fixed(nsPerFrag(frags, rcMs), 3),
             fixed(mfragPerS(frags, countMs), 2),
             fixed(nsPerFrag(frags, countMs), 3),
             fixed(mfragPerS(frags, captureMs), 2),
             fixed(nsPerFrag(frags, captureMs), 3),
             fixed(mfragPerS(frags, resolveMs), 2),
             fixed(nsPerFrag(frags, resolveMs), 3),
             fixed(mfragPerS(frags, m.totalMs), 2),
             sc.label == "layers" ? fixed(kGoalMFragPerS, 0) : ""});
  }
  std::printf("\nwrote %s\n", csv.path().c_str());
  return failed ? 1 : 0;
}
