// What every bench_* program shares: the command line (--out, --size, --threads, --reps, --quick),
// aligned tables on stdout and CSV files, timing and medians over interleaved runs, and loading a
// scene and building its frame under the scene's default camera. Each program is a single
// translation unit that includes this header, so everything here is inline.
#pragma once

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "mfr/core/image.hpp"
#include "mfr/core/plot.hpp"
#include "mfr/core/result.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::bench {

using Clock = std::chrono::steady_clock;

// What sets one program apart on the command line and in its messages.
struct Program {
  const char* name;              // "bench_NAME": the prefix of its error messages
  const char* csv;               // the file it writes into --out, e.g. "abuffer.csv"
  const char* quick = "";        // what --quick trims besides image and runs, e.g. "d in {1, 4}, "
  const char* options = "";      // synopsis of its own options, e.g. " [--budget M]"
  const char* optionsHelp = "";  // their help lines, each ending in '\n'
};

inline void printError(const Program& program, const std::string& message) {
  std::fprintf(stderr, "%s: %s\n", program.name, message.c_str());
}

/// Pulls "--budget BYTES" (e.g. 20MB) out of argv, before parseArgs, which knows only the common
/// options; false (with a one-line error) when its value is missing or not a size.
inline bool takeBudget(const Program& program, int& argc, char** argv,
                       std::optional<uint64_t>& budget) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) != "--budget") continue;
    if (i + 1 >= argc) {
      printError(program, "--budget needs a value such as 20MB");
      return false;
    }
    auto parsed = parseByteSize(argv[i + 1]);
    if (!parsed) {
      printError(program, parsed.error().message);
      return false;
    }
    budget = *parsed;
    for (int j = i; j + 2 <= argc; ++j) argv[j] = argv[j + 2];
    argc -= 2;
    --i;
  }
  return true;
}

/// Draws `series` into OUT/fileName and prints its path; false (with the message) if it failed.
/// Nothing is written for no series.
inline bool writePlotPng(const Program& program, const std::string& outDir,
                         const std::string& fileName, const std::vector<PlotSeries>& series,
                         const PlotOptions& options) {
  if (series.empty()) return true;
  auto png = plotLines(series, options);
  const std::filesystem::path path = std::filesystem::path(outDir) / fileName;
  if (!png || !writePng(path.string(), *png).ok()) {
    printError(program, "cannot write " + path.string());
    return false;
  }
  std::printf("PNG: %s\n", path.string().c_str());
  return true;
}

// ---- command line (the same options in every bench program) ----------------------------------

struct Args {
  std::string out = "bench-results";
  int size = 1024;
  int threads = 0;  // 0 = all cores
  int reps = 3;
  bool quick = false;
};

inline void usage(const char* prog, const Program& program) {
  std::printf(
      "usage: %s [--out DIR] [--size N] [--threads N] [--reps N] [--quick]%s\n"
      "  --out DIR     directory for %s (default bench-results)\n"
      "  --size N      image is N x N pixels (default 1024; --quick: 256)\n"
      "  --threads N   worker threads (default 0 = all cores)\n"
      "  --reps N      runs per measurement, the median is reported (default 3; --quick: 1)\n"
      "  --quick       smoke run: smaller image, %sone run\n"
      "%s",
      prog, program.options, program.csv, program.quick, program.optionsHelp);
}

inline bool parseInt(const char* text, int lo, int hi, int& value) {
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (errno != 0 || end == text || *end != '\0' || v < lo || v > hi) return false;
  value = static_cast<int>(v);
  return true;
}

// The common options. --help prints the usage and exits (0); a bad command line is reported and
// exits (2). A program with options of its own takes them out of argv first.
inline Args parseArgs(int argc, char** argv, const Program& program) {
  Args a;
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
      if (!intOption(16, kMaxImageSize, a.size)) std::exit(2);
      sizeSet = true;
    } else if (arg == "--threads") {
      if (!intOption(0, 1024, a.threads)) std::exit(2);
    } else if (arg == "--reps") {
      if (!intOption(1, 1000, a.reps)) std::exit(2);
      repsSet = true;
    } else if (arg == "--quick") {
      a.quick = true;
    } else if (arg == "--help" || arg == "-h") {
      usage(argv[0], program);
      std::exit(0);
    } else {
      std::fprintf(stderr, "%s: unknown or incomplete option '%s'\n", argv[0], arg.c_str());
      usage(argv[0], program);
      std::exit(2);
    }
  }
  if (a.quick && !sizeSet) a.size = 256;
  if (a.quick && !repsSet) a.reps = 1;
  return a;
}

// "WxH, T thread(s) (C cores), median of R run(s)": the set-up line every program opens with.
inline std::string runDescription(const Args& args, int threads) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%dx%d, %d thread(s) (%u cores), median of %d run(s)", args.size,
                args.size, threads, std::thread::hardware_concurrency(), args.reps);
  return buf;
}

// ---- formatting: aligned tables on stdout, CSV files -------------------------------------------

inline std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

inline std::string num(uint64_t v) {
  return std::to_string(v);
}

inline std::string mib(uint64_t bytes) {
  return fixed(static_cast<double>(bytes) / (1 << 20), 1);
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
      if (r == 0) std::printf("%s\n", std::string(line.size(), '-').c_str());
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

// Creates the --out directory and starts the program's CSV file there with its header line (the
// column names, comma-separated). A file that cannot be written is reported and exits (1).
inline Csv openCsv(const Program& program, const Args& args, const std::string& header) {
  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  Csv csv(std::filesystem::path(args.out) / program.csv, header);
  if (!csv.ok()) {
    printError(program, "cannot write " + csv.path().string());
    std::exit(1);
  }
  return csv;
}

// ---- measurement -------------------------------------------------------------------------------

inline double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

// throughput of `fragments` processed in `ms`
inline double mfragPerS(uint64_t fragments, double ms) {
  return ms > 0.0 ? static_cast<double>(fragments) / (ms * 1e3) : 0.0;
}
inline double nsPerFrag(uint64_t fragments, double ms) {
  return fragments ? ms * 1e6 / static_cast<double>(fragments) : 0.0;
}

inline double percent(uint64_t part, uint64_t whole) {
  return whole ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0;
}

// largest per-channel difference of two images (infinite when their sizes differ)
inline float maxAbsDiff(const ImageRGB& a, const ImageRGB& b) {
  if (a.pixels.size() != b.pixels.size()) return INFINITY;
  float d = 0.0f;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const glm::vec3 e = glm::abs(a.pixels[i] - b.pixels[i]);
    d = std::max({d, e.x, e.y, e.z});
  }
  return d;
}

// One configuration to time: a frame, a method and the render options, and what its runs gave.
struct Case {
  const RasterFrame* frame = nullptr;
  MethodDesc method;
  RenderOptions options;
  bool keepImage = false;

  std::optional<std::string> error;  // the render's error (e.g. a budget too small)
  RenderStats stats;                 // statistics of the last run (the counters are deterministic)
  ImageRGB image;                    // image of the last run, with keepImage
  std::map<std::string, std::vector<double>> passSamples;  // ms per pass, one per run
  std::vector<double> totalSamples;                        // ms per run, all passes

  // medians over the runs
  double pass(const std::string& name) const {
    const auto it = passSamples.find(name);
    return it == passSamples.end() ? 0.0 : median(it->second);
  }
  double totalMs() const { return median(totalSamples); }
  double allocMs() const { return pass("allocate") + pass("clear"); }
  // the three occupancy-map passes
  double occupancyMs() const {
    return pass("depth_range") + pass("occupancy_fill") + pass("occupancy_count");
  }
};

// Runs every case once per round, for `reps` rounds. Interleaving the cases, rather than
// repeating each one back to back, spreads the slow periods of a shared machine over all cases
// alike, so their medians compare fairly. A case whose render fails is not run again.
inline void runInterleaved(std::vector<Case>& cases, int reps) {
  std::fflush(stdout);  // the tables so far before the progress lines on stderr
  for (int round = 0; round < reps; ++round) {
    std::fprintf(stderr, "  round %d/%d: %zu case(s)\n", round + 1, reps, cases.size());
    for (Case& c : cases) {
      if (c.error) continue;
      auto out = render(*c.frame, c.method, c.options);
      if (!out) {
        c.error = out.error().message;
        continue;
      }
      for (const PassTime& p : out->stats.passes) c.passSamples[p.name].push_back(p.ms);
      c.totalSamples.push_back(out->stats.totalMs());
      c.stats = std::move(out->stats);
      if (c.keepImage) c.image = std::move(out->image);
    }
  }
}

// ---- scenes and frames -------------------------------------------------------------------------

// A scene to measure: its label in the tables and CSV, and what loadScene() gets.
struct SceneCase {
  std::string label, source;
  bool file = false;  // a real scene under MFR_SCENES_DIR (skipped when absent)
};

inline Camera sceneCamera(const Scene& scene) {
  return scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
}

// The frame every program renders: --size x --size, 32-pixel tiles, --threads workers.
inline Result<RasterFrame> buildFrame(const Scene& scene, const Args& args) {
  return RasterFrame::build(scene, sceneCamera(scene),
                            RasterOptions{args.size, args.size, 32, args.threads});
}

// The scenes and frames of one run: a frame points into its scene (textures), so both stay alive,
// at fixed addresses, as long as the store. Failures are reported under the program's name.
class FrameStore {
 public:
  explicit FrameStore(const Program& program) : program_(program) {}

  // nullptr (after printing why) when `source` does not load
  Scene* load(const std::string& source) {
    auto loaded = loadScene(source);
    if (!loaded) {
      printError(program_, loaded.error().message);
      return nullptr;
    }
    return &scenes_.emplace_back(std::move(loaded.value()));
  }

  // buildFrame() of a stored scene; nullptr (after printing why) when it fails
  const RasterFrame* build(const Scene& scene, const Args& args) {
    auto frame = buildFrame(scene, args);
    if (!frame) {
      printError(program_, frame.error().message);
      return nullptr;
    }
    return &frames_.emplace_back(std::move(frame.value()));
  }

 private:
  const Program& program_;
  std::deque<Scene> scenes_;
  std::deque<RasterFrame> frames_;
};

}  // namespace mfr::bench
