// bench_k_sweep: max-array vs max-heap k+-buffer as k grows, at a fixed n = 128 fragments per
// covered pixel (k+-buffer paper, Vasilakis & Fudos 2015, sec. 4.1 / the array-vs-heap timing
// figure: "the heap wins above about k = 16", which also motivates the K+B-SB rule of using the
// heap when n(p) > k(p) > 16).
//
// Scene: procedural:layers?k=K&r=128/K&pd=0.5 (n = r*k randomly ordered full-square quads over half
// of the image). For k in {4, 8, 12, 16, 24, 32, 48, 64}, kplus-array and kplus-heap run with the
// explicit k (no budget); the program times the capture pass, the resolve pass and the whole render
// (median of --reps runs) and prints which store wins at each k. For k = 12, 24, 48, 128/k is not
// an integer: the layers scene depends only on n = r*k (the split into k and r is the paper's
// notation), so those points use the n = 128 scene layers?k=1&r=128 to keep n exact.
// CSV: k_sweep.csv.
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

constexpr int kFragmentsPerPixel = 128;  // n

constexpr const char* kUsage =
    "[--out DIR] [--size N] [--threads N] [--reps N] [--quick]\n"
    "  --out DIR     directory for k_sweep.csv (default bench-results)\n"
    "  --size N      image is N x N pixels (default 1024; --quick: 256)\n"
    "  --threads N   worker threads (default 0 = all cores)\n"
    "  --reps N      runs per measurement, the median is reported (default 3; --quick: 1)\n"
    "  --quick       smoke run: smaller image, k in {4, 16, 64}, one run\n";

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

// The paper's scene for k: n = r*k = 128 quads; when k does not divide 128 the same n = 128 scene
// under the split k=1, r=128 (the geometry depends on n only).
std::string layersSpec(int k) {
  const int k1 = kFragmentsPerPixel % k == 0 ? k : 1;
  std::string spec = "procedural:layers?k=";
  spec += std::to_string(k1);
  spec += "&r=";
  spec += std::to_string(kFragmentsPerPixel / k1);
  spec += "&pd=0.5";
  return spec;
}

double allocMs(const Measured& m) {
  return m.pass("allocate") + m.pass("clear");
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!parseArgs(argc, argv, args)) return 2;
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  Csv csv(std::filesystem::path(args.out) / "k_sweep.csv",
          "k,n,scene,width,height,threads,reps,fragments,covered_pixels,culled_kplus,captured,"
          "array_alloc_ms,array_capture_ms,array_resolve_ms,array_total_ms,heap_alloc_ms,"
          "heap_capture_ms,heap_resolve_ms,heap_total_ms,heap_speedup_capture,"
          "heap_speedup_total,winner_capture,winner_total");
  if (!csv.ok()) {
    std::fprintf(stderr, "bench_k_sweep: cannot write %s\n", csv.path().c_str());
    return 1;
  }
  const std::vector<int> ks =
      args.quick ? std::vector<int>{4, 16, 64} : std::vector<int>{4, 8, 12, 16, 24, 32, 48, 64};
  std::printf(
      "bench_k_sweep: kplus-array vs kplus-heap, n = %d fragments per covered pixel, pd = 0.5, "
      "%dx%d, %d thread(s) (%u cores), median of %d run(s); times in ms\n\n",
      kFragmentsPerPixel, args.size, args.size, resolveThreads(args.threads),
      std::thread::hardware_concurrency(), args.reps);

  Table table({"k", "n", "capture array", "capture heap", "resolve array", "resolve heap",
               "total array", "total heap", "heap speed-up", "faster (capture)", "faster (total)"});
  std::vector<std::pair<int, bool>> heapWinsTotal;  // (k, heap faster in total)
  bool failed = false;
  for (const int k : ks) {
    const std::string spec = layersSpec(k);
    auto scene = loadScene(spec);
    if (!scene) {
      std::fprintf(stderr, "bench_k_sweep: %s\n", scene.error().message.c_str());
      return 1;
    }
    auto frame = RasterFrame::build(*scene, sceneCamera(*scene),
                                    RasterOptions{args.size, args.size, 32, args.threads});
    if (!frame) {
      std::fprintf(stderr, "bench_k_sweep: %s\n", frame.error().message.c_str());
      return 1;
    }
    std::optional<Measured> results[2];
    const char* names[2] = {"kplus-array", "kplus-heap"};
    for (int i = 0; i < 2; ++i) {
      auto method = methodPreset(names[i]);
      MFR_CHECK(method.ok());
      method->k = static_cast<uint32_t>(k);
      auto measured = measure(*frame, *method, RenderOptions{}, args.reps);
      if (!measured) {
        std::fprintf(stderr, "bench_k_sweep: %s k=%d: %s\n", names[i], k,
                     measured.error().message.c_str());
        failed = true;
        break;
      }
      results[i] = std::move(measured.value());
    }
    if (!results[0] || !results[1]) continue;
    const Measured& arr = *results[0];
    const Measured& heap = *results[1];
    const RenderStats& s = arr.stats;
    if (s.captured != heap.stats.captured || s.fragmentsGenerated != heap.stats.fragmentsGenerated)
      std::printf("note: k=%d: array captured %llu of %llu, heap %llu of %llu\n", k,
                  static_cast<unsigned long long>(s.captured),
                  static_cast<unsigned long long>(s.fragmentsGenerated),
                  static_cast<unsigned long long>(heap.stats.captured),
                  static_cast<unsigned long long>(heap.stats.fragmentsGenerated));
    const double n =
        s.coveredPixels ? static_cast<double>(s.fragmentsGenerated) / s.coveredPixels : 0.0;
    const double capA = arr.pass("capture"), capH = heap.pass("capture");
    const double speedCapture = capH > 0 ? capA / capH : 0.0;
    const double speedTotal = heap.totalMs > 0 ? arr.totalMs / heap.totalMs : 0.0;
    const char* winCapture = capH < capA ? "heap" : "array";
    const char* winTotal = heap.totalMs < arr.totalMs ? "heap" : "array";
    heapWinsTotal.emplace_back(k, heap.totalMs < arr.totalMs);
    table.add({std::to_string(k), fixed(n, 1), fixed(capA, 1), fixed(capH, 1),
               fixed(arr.pass("resolve"), 1), fixed(heap.pass("resolve"), 1), fixed(arr.totalMs, 1),
               fixed(heap.totalMs, 1), fixed(speedTotal, 2) + "x", winCapture, winTotal});
    csv.row({std::to_string(k),
             fixed(n, 2),
             spec,
             num(frame->width()),
             num(frame->height()),
             num(frame->threads()),
             num(args.reps),
             num(s.fragmentsGenerated),
             num(s.coveredPixels),
             num(s.culledKPlus),
             num(s.captured),
             fixed(allocMs(arr), 3),
             fixed(capA, 3),
             fixed(arr.pass("resolve"), 3),
             fixed(arr.totalMs, 3),
             fixed(allocMs(heap), 3),
             fixed(capH, 3),
             fixed(heap.pass("resolve"), 3),
             fixed(heap.totalMs, 3),
             fixed(speedCapture, 3),
             fixed(speedTotal, 3),
             winCapture,
             winTotal});
  }
  table.print();
  // the crossover: the smallest k from which the heap wins at every larger k of the sweep
  std::optional<int> from;
  for (auto it = heapWinsTotal.rbegin(); it != heapWinsTotal.rend() && it->second; ++it)
    from = it->first;
  if (from)
    std::printf("\nheap faster in total from k = %d on (paper: above about k = 16)\n", *from);
  else
    std::printf("\nheap not faster in total at the largest k (paper: above about k = 16)\n");
  std::printf("heap speed-up = array total / heap total\nwrote %s\n", csv.path().c_str());
  return failed ? 1 : 0;
}
