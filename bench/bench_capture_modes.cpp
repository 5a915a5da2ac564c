// bench_capture_modes: fragment-parallel capture (the k+-buffer paper's Algorithm 3 as written:
// triangles from many threads, per-pixel spin-locks, the k+ test outside the critical section and
// again inside) vs tile-owned capture (each tile one worker's, no locks), at k = 8 for kplus-array,
// kplus-heap and fkb on procedural:hairball and procedural:layers. Mirrors the k+-buffer paper's
// comparison of its spin-lock store against lock-free variants (sec. 4, performance figures).
//
// For each (scene, method, mode): capture-pass time (median of --reps runs), fragments/s through
// the capture pass, fragments culled by the k+ test and rejected inside the store (the in-store
// re-check only fires when another thread got there first), and whether the fragment-parallel
// image equals the tile-owned one (it should: both keep the k nearest fragments of every pixel).
// CSV: capture_modes.csv (one row per scene and method, both modes side by side).
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
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

constexpr uint32_t kK = 8;

constexpr const char* kUsage =
    "[--out DIR] [--size N] [--threads N] [--reps N] [--quick]\n"
    "  --out DIR     directory for capture_modes.csv (default bench-results)\n"
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

float maxAbsDiff(const ImageRGB& a, const ImageRGB& b) {
  if (a.pixels.size() != b.pixels.size()) return INFINITY;
  float d = 0.0f;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const glm::vec3 e = glm::abs(a.pixels[i] - b.pixels[i]);
    d = std::max({d, e.x, e.y, e.z});
  }
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parseArgs(argc, argv, args)) return 2;
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  Csv csv(std::filesystem::path(args.out) / "capture_modes.csv",
          "scene,method,k,width,height,threads,reps,fragments,tile_capture_ms,tile_mfrag_s,"
          "parallel_capture_ms,parallel_mfrag_s,tile_speedup,tile_culled_kplus,"
          "parallel_culled_kplus,tile_in_store,parallel_in_store,tile_captured,"
          "parallel_captured,image_max_diff");
  if (!csv.ok()) {
    std::fprintf(stderr, "bench_capture_modes: cannot write %s\n", csv.path().c_str());
    return 1;
  }
  std::printf(
      "bench_capture_modes: tile-owned vs fragment-parallel capture, k = %u, %dx%d, %d thread(s) "
      "(%u cores), median of %d run(s)\n",
      kK, args.size, args.size, resolveThreads(args.threads), std::thread::hardware_concurrency(),
      args.reps);

  struct SceneCase {
    std::string label, source;
  };
  const std::vector<SceneCase> scenes = {{"hairball", "procedural:hairball"},
                                         {"layers", "procedural:layers"}};
  const std::vector<std::string> methods = {"kplus-array", "kplus-heap", "fkb"};
  const CaptureMode modes[2] = {CaptureMode::TileOwned, CaptureMode::FragmentParallel};
  const char* modeNames[2] = {"tile-owned", "fragment-parallel"};

  Table table({"scene", "method", "mode", "capture ms", "M frag/s", "culled k+",
               "rejected in store", "captured", "same image"});
  table.leftAlign(1);
  table.leftAlign(2);
  table.leftAlign(8);
  bool failed = false;
  for (const SceneCase& sc : scenes) {
    auto scene = loadScene(sc.source);
    if (!scene) {
      std::fprintf(stderr, "bench_capture_modes: %s\n", scene.error().message.c_str());
      failed = true;
      continue;
    }
    const auto setupStart = Clock::now();
    auto frame = RasterFrame::build(*scene, sceneCamera(*scene),
                                    RasterOptions{args.size, args.size, 32, args.threads});
    if (!frame) {
      std::fprintf(stderr, "bench_capture_modes: %s\n", frame.error().message.c_str());
      return 1;
    }
    std::printf("%s (%s): frame set-up %.1f ms\n", sc.label.c_str(), sc.source.c_str(),
                msSince(setupStart));
    for (const std::string& name : methods) {
      auto method = methodPreset(name);
      MFR_CHECK(method.ok());
      method->k = kK;
      std::optional<Measured> results[2];
      for (int i = 0; i < 2; ++i) {
        RenderOptions options;
        options.capture = modes[i];
        auto measured = measure(*frame, *method, options, args.reps);
        if (!measured) {
          std::fprintf(stderr, "bench_capture_modes: %s %s %s: %s\n", sc.label.c_str(),
                       name.c_str(), modeNames[i], measured.error().message.c_str());
          failed = true;
          break;
        }
        results[i] = std::move(measured.value());
      }
      if (!results[0] || !results[1]) continue;
      const float diff = maxAbsDiff(results[0]->image, results[1]->image);
      for (int i = 0; i < 2; ++i) {
        const RenderStats& s = results[i]->stats;
        const double ms = results[i]->pass("capture");
        std::string same = "-";
        if (i == 1) same = diff == 0.0f ? "yes" : "NO (max diff " + fixed(diff, 4) + ")";
        table.add({i == 0 ? sc.label : "", i == 0 ? name : "", modeNames[i], fixed(ms, 1),
                   fixed(mfragPerS(s.fragmentsGenerated, ms), 1), num(s.culledKPlus),
                   num(s.rejectedInStore), num(s.captured), same});
      }
      const RenderStats& t = results[0]->stats;
      const RenderStats& p = results[1]->stats;
      const double tileMs = results[0]->pass("capture"), parMs = results[1]->pass("capture");
      csv.row({sc.label,
               name,
               std::to_string(kK),
               num(frame->width()),
               num(frame->height()),
               num(frame->threads()),
               num(args.reps),
               num(t.fragmentsGenerated),
               fixed(tileMs, 3),
               fixed(mfragPerS(t.fragmentsGenerated, tileMs), 3),
               fixed(parMs, 3),
               fixed(mfragPerS(p.fragmentsGenerated, parMs), 3),
               fixed(tileMs > 0 ? parMs / tileMs : 0.0, 3),
               num(t.culledKPlus),
               num(p.culledKPlus),
               num(t.rejectedInStore),
               num(p.rejectedInStore),
               num(t.captured),
               num(p.captured),
               fixed(diff, 6)});
    }
  }
  std::printf("\n");
  table.print();
  std::printf("\nM frag/s = fragments generated / capture-pass time\nwrote %s\n",
              csv.path().c_str());
  return failed ? 1 : 0;
}
