// bench_occupancy: occupancy-map culling on a high-depth-complexity scene (Vasilakis & Papaioannou
// 2015, "Improving k-buffer methods via occupancy maps": the speed-up-vs-d figure and the
// culled-fragments counts of its evaluation).
//
// procedural:hairball at k = 8: kplus-array with the explicit k = 8 as the baseline, then
// kplus-array+occupancy with occupancyWords = d for d in {1, 2, 4, 8, 16, 32, 64} (32*d depth
// buckets per pixel). For each: fragments rejected by the occupancy test, by the k+ test (before
// the critical section) and inside the store, as counts and as % of the generated fragments; the
// time of the three occupancy passes, the capture pass and the whole render (median of --reps
// runs); and the speed-up over the baseline in total time and in capture-pass time. Occupancy
// culling is conservative (Lemma 2.1), so each variant must capture what the baseline captures and
// produce the same image: the "same" column checks it. CSV: occupancy.csv.
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
constexpr const char* kScene = "procedural:hairball";

constexpr const char* kUsage =
    "[--out DIR] [--size N] [--threads N] [--reps N] [--quick]\n"
    "  --out DIR     directory for occupancy.csv (default bench-results)\n"
    "  --size N      image is N x N pixels (default 1024; --quick: 256)\n"
    "  --threads N   worker threads (default 0 = all cores)\n"
    "  --reps N      runs per measurement, the median is reported (default 3; --quick: 1)\n"
    "  --quick       smoke run: smaller image, d in {1, 4, 64}, one run\n";

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

double percent(uint64_t part, uint64_t whole) {
  return whole ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0;
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

double occupancyMs(const Measured& m) {
  return m.pass("depth_range") + m.pass("occupancy_fill") + m.pass("occupancy_count");
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parseArgs(argc, argv, args)) return 2;
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  Csv csv(std::filesystem::path(args.out) / "occupancy.csv",
          "d,buckets,width,height,threads,reps,fragments,culled_occupancy,culled_kplus,"
          "rejected_in_store,inserted,evicted,captured,occupancy_pct,kplus_pct,in_store_pct,"
          "rejected_pct,bytes_used,occupancy_passes_ms,capture_ms,resolve_ms,total_ms,"
          "speedup_capture,speedup_total,image_max_diff");
  if (!csv.ok()) {
    std::fprintf(stderr, "bench_occupancy: cannot write %s\n", csv.path().c_str());
    return 1;
  }
  const std::vector<int> ds =
      args.quick ? std::vector<int>{1, 4, 64} : std::vector<int>{1, 2, 4, 8, 16, 32, 64};

  auto scene = loadScene(kScene);
  if (!scene) {
    std::fprintf(stderr, "bench_occupancy: %s\n", scene.error().message.c_str());
    return 1;
  }
  const auto setupStart = Clock::now();
  auto frame = RasterFrame::build(*scene, sceneCamera(*scene),
                                  RasterOptions{args.size, args.size, 32, args.threads});
  if (!frame) {
    std::fprintf(stderr, "bench_occupancy: %s\n", frame.error().message.c_str());
    return 1;
  }
  std::printf(
      "bench_occupancy: %s, kplus-array k = %u with and without occupancy culling, %dx%d, %d "
      "thread(s) (%u cores), median of %d run(s)\n"
      "frame set-up %.1f ms (shared by every run, not in the times below); times in ms; rejected "
      "as %% of generated fragments\n\n",
      kScene, kK, args.size, args.size, frame->threads(), std::thread::hardware_concurrency(),
      args.reps, msSince(setupStart));

  Table table({"d", "buckets", "by occupancy", "by k+", "in store", "captured", "MiB",
               "occ. passes", "capture", "total", "capture speed-up", "total speed-up",
               "same image"});
  table.leftAlign(12);
  std::optional<Measured> base;
  bool failed = false;
  // d = 0: the baseline without occupancy
  for (int i = -1; i < static_cast<int>(ds.size()); ++i) {
    const int d = i < 0 ? 0 : ds[static_cast<size_t>(i)];
    auto method = methodPreset(d == 0 ? "kplus-array" : "kplus-array+occupancy");
    MFR_CHECK(method.ok());
    method->k = kK;
    method->occupancyWords = d;
    auto measured = measure(*frame, *method, RenderOptions{}, args.reps);
    if (!measured) {
      std::fprintf(stderr, "bench_occupancy: d=%d: %s\n", d, measured.error().message.c_str());
      if (d == 0) return 1;
      failed = true;
      continue;
    }
    const Measured& m = measured.value();
    if (d == 0) base = m;
    const RenderStats& s = m.stats;
    const uint64_t gen = s.fragmentsGenerated;
    const double speedCapture =
        m.pass("capture") > 0 ? base->pass("capture") / m.pass("capture") : 0.0;
    const double speedTotal = m.totalMs > 0 ? base->totalMs / m.totalMs : 0.0;
    const float diff = maxAbsDiff(m.image, base->image);
    const bool same = diff == 0.0f && s.captured == base->stats.captured;
    const std::string label = d == 0 ? "off" : std::to_string(d);
    table.add({label, d == 0 ? "-" : std::to_string(32 * d),
               fixed(percent(s.culledOccupancy, gen), 2) + "%",
               fixed(percent(s.culledKPlus, gen), 2) + "%",
               fixed(percent(s.rejectedInStore, gen), 2) + "%", num(s.captured),
               fixed(static_cast<double>(s.bytesUsed) / (1 << 20), 1), fixed(occupancyMs(m), 1),
               fixed(m.pass("capture"), 1), fixed(m.totalMs, 1), fixed(speedCapture, 2) + "x",
               fixed(speedTotal, 2) + "x", same ? "yes" : "NO (max diff " + fixed(diff, 4) + ")"});
    csv.row({std::to_string(d),
             std::to_string(32 * d),
             num(frame->width()),
             num(frame->height()),
             num(frame->threads()),
             num(args.reps),
             num(gen),
             num(s.culledOccupancy),
             num(s.culledKPlus),
             num(s.rejectedInStore),
             num(s.inserted),
             num(s.evicted),
             num(s.captured),
             fixed(percent(s.culledOccupancy, gen), 3),
             fixed(percent(s.culledKPlus, gen), 3),
             fixed(percent(s.rejectedInStore, gen), 3),
             fixed(percent(s.culledOccupancy + s.culledKPlus + s.rejectedInStore, gen), 3),
             num(s.bytesUsed),
             fixed(occupancyMs(m), 3),
             fixed(m.pass("capture"), 3),
             fixed(m.pass("resolve"), 3),
             fixed(m.totalMs, 3),
             fixed(speedCapture, 3),
             fixed(speedTotal, 3),
             fixed(diff, 6)});
  }
  table.print();
  if (base)
    std::printf(
        "\n%llu fragments generated per run; speed-up = baseline time / time (baseline: "
        "d = off)\n",
        static_cast<unsigned long long>(base->stats.fragmentsGenerated));
  std::printf("wrote %s\n", csv.path().c_str());
  return failed ? 1 : 0;
}
