// bench_presets: every method preset under one memory budget, in the layout of Table 2 of the
// variable k-buffer paper (Vasilakis, Vardis, Papaioannou, Fudos 2017: time, k range, captured
// fragments and loss under a fixed M, per scene with its maximum depth complexity D).
//
// Scenes: IridescentDishWithOlives (real glTF from ../shared/scenes, rendered with a global alpha
// override of 0.5 as the papers render whole scenes transparent; skipped with a message when the
// file is absent) and procedural:hairball, at 1024x1024 with M = 20 MiB (20 * 2^20 bytes). Presets:
// zbuffer, abuffer (no budget: the exact reference), fkb, kplus-array, kplus-heap, kplus-sb,
// kplus-dynamic, and the +occupancy variant of every bounded one. For each: total time and time per
// pass (median of --reps runs), bytes used, k range over covered pixels, captured fragments and the
// % of generated fragments lost. A preset whose buffers do not fit M is reported as a row carrying
// the budget error. CSV: presets.csv (one row per scene and preset).
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

#include "mfr/core/units.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/render.hpp"
#include "mfr/raster/raster_frame.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/load.hpp"

namespace {

using namespace mfr;

constexpr uint64_t kBudgetAt1024 = 20ull << 20;  // M = 20 MiB at 1024x1024
constexpr float kAlphaOverride = 0.5f;           // real scenes rendered fully transparent

constexpr const char* kUsage =
    "[--out DIR] [--size N] [--threads N] [--reps N] [--quick] [--budget M]\n"
    "  --out DIR     directory for presets.csv (default bench-results)\n"
    "  --size N      image is N x N pixels (default 1024; --quick: 256)\n"
    "  --threads N   worker threads (default 0 = all cores)\n"
    "  --reps N      runs per measurement, the median is reported (default 3; --quick: 1)\n"
    "  --quick       smoke run: smaller image, one run\n"
    "  --budget M    memory budget, e.g. 20MB (default 20 MiB at 1024x1024, scaled with the pixel\n"
    "                count at other sizes so the bytes per pixel stay the same)\n";

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

std::string mib(uint64_t bytes) {
  return fixed(static_cast<double>(bytes) / (1 << 20), 1);
}

// Pulls "--budget M" out of argv (the shared parser knows only the common options).
bool takeBudget(int& argc, char** argv, std::optional<uint64_t>& budget) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) != "--budget") continue;
    if (i + 1 >= argc) {
      std::fprintf(stderr, "%s: --budget needs a value such as 20MB\n", argv[0]);
      return false;
    }
    auto parsed = parseByteSize(argv[i + 1]);
    if (!parsed) {
      std::fprintf(stderr, "%s: %s\n", argv[0], parsed.error().message.c_str());
      return false;
    }
    budget = *parsed;
    for (int j = i; j + 2 <= argc; ++j) argv[j] = argv[j + 2];
    argc -= 2;
    --i;
  }
  return true;
}

struct SceneCase {
  std::string label, source;
  bool file;  // a real scene under MFR_SCENES_DIR (skipped when absent)
};

}  // namespace

int main(int argc, char** argv) {
  std::optional<uint64_t> budgetOption;
  if (!takeBudget(argc, argv, budgetOption)) return 2;
  Args args;
  if (!parseArgs(argc, argv, args)) return 2;
  const double pixelScale = static_cast<double>(args.size) * args.size / (1024.0 * 1024.0);
  const uint64_t budget =
      budgetOption.value_or(static_cast<uint64_t>(static_cast<double>(kBudgetAt1024) * pixelScale));

  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  Csv csv(std::filesystem::path(args.out) / "presets.csv",
          "scene,scene_index,method,method_index,width,height,budget_bytes,max_depth,status,"
          "k_min,k_max,global_k,bytes_used,fragments,captured,lost,loss_pct,total_ms,count_ms,"
          "alloc_ms,occupancy_ms,capture_ms,resolve_ms,error");
  if (!csv.ok()) {
    std::fprintf(stderr, "bench_presets: cannot write %s\n", csv.path().c_str());
    return 1;
  }
  std::printf(
      "bench_presets: every preset under M = %s (%llu bytes)%s, %dx%d, %d thread(s) (%u cores), "
      "median of %d run(s)\n",
      formatBytes(budget).c_str(), static_cast<unsigned long long>(budget),
      budgetOption ? "" : (args.size == 1024 ? "" : " (20 MiB scaled to the pixel count)"),
      args.size, args.size, resolveThreads(args.threads), std::thread::hardware_concurrency(),
      args.reps);

  std::vector<std::string> presets = presetNames();
  for (const std::string& name : presetNames())
    if (name != "abuffer") presets.push_back(name + "+occupancy");

  const std::string dish = std::string(MFR_SCENES_DIR) +
                           "/khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf";
  const std::vector<SceneCase> scenes = {{"IridescentDishWithOlives", dish, true},
                                         {"hairball", "procedural:hairball", false}};
  bool failed = false;
  int sceneIndex = 0;
  for (const SceneCase& sc : scenes) {
    if (sc.file && !std::filesystem::exists(sc.source)) {
      std::printf("\nskipping %s: %s not found (the shared scenes folder is absent)\n",
                  sc.label.c_str(), sc.source.c_str());
      continue;
    }
    auto scene = loadScene(sc.source);
    if (!scene) {
      std::fprintf(stderr, "bench_presets: %s\n", scene.error().message.c_str());
      failed = true;
      continue;
    }
    std::string note;
    if (sc.file) {
      scene->alphaOverride = kAlphaOverride;
      note = ", global alpha override 0.5 (whole scene transparent, as in the papers)";
    }
    auto frame = RasterFrame::build(*scene, sceneCamera(*scene),
                                    RasterOptions{args.size, args.size, 32, args.threads});
    if (!frame) {
      std::fprintf(stderr, "bench_presets: %s\n", frame.error().message.c_str());
      failed = true;
      continue;
    }
    // D and the A-buffer's needs, from one count pass
    const std::vector<uint32_t> n = countFragments(*frame);
    uint64_t total = 0;
    uint32_t maxDepth = 0;
    for (uint32_t c : n) {
      total += c;
      maxDepth = std::max(maxDepth, c);
    }
    std::printf("\n%s: %zu triangles, D = %u, %llu fragments%s\n", sc.label.c_str(),
                scene->triangleCount(), maxDepth, static_cast<unsigned long long>(total),
                note.c_str());

    Table table({"method", "k", "MiB", "total ms", "count", "alloc", "occupancy", "capture",
                 "resolve", "captured", "loss", "note"});
    table.leftAlign(11);
    int methodIndex = 0;
    for (const std::string& name : presets) {
      auto method = methodPreset(name);
      MFR_CHECK(method.ok());
      RenderOptions options;
      if (method->allocation != AllocationPolicy::Unbounded) options.budgetBytes = budget;
      auto measured = measure(*frame, *method, options, args.reps);
      std::vector<std::string> row = {sc.label,
                                      std::to_string(sceneIndex),
                                      name,
                                      std::to_string(methodIndex),
                                      num(frame->width()),
                                      num(frame->height()),
                                      options.budgetBytes ? num(budget) : "",
                                      num(maxDepth)};
      if (!measured) {
        const std::string& message = measured.error().message;
        table.add({name, "-", "-", "-", "-", "-", "-", "-", "-", "-", "-", "error: " + message});
        row.insert(row.end(),
                   {"error", "", "", "", "", "", "", "", "", "", "", "", "", "", "", message});
        csv.row(row);
        ++methodIndex;
        continue;
      }
      const Measured& m = measured.value();
      const RenderStats& s = m.stats;
      const double alloc = m.pass("allocate") + m.pass("clear");
      const double occupancy =
          m.pass("depth_range") + m.pass("occupancy_fill") + m.pass("occupancy_count");
      std::string k = std::to_string(s.kMin);
      if (s.kMax != s.kMin) {
        k += "-";
        k += std::to_string(s.kMax);
      }
      table.add({name, k, mib(s.bytesUsed), fixed(m.totalMs, 1), fixed(m.pass("count"), 1),
                 fixed(alloc, 1), fixed(occupancy, 1), fixed(m.pass("capture"), 1),
                 fixed(m.pass("resolve"), 1), num(s.captured), fixed(s.lostPercent(), 1) + "%",
                 options.budgetBytes ? "" : "no budget"});
      row.insert(row.end(), {"ok", num(s.kMin), num(s.kMax), s.globalK ? num(*s.globalK) : "",
                             num(s.bytesUsed), num(s.fragmentsGenerated), num(s.captured),
                             num(s.lost), fixed(s.lostPercent(), 3), fixed(m.totalMs, 3),
                             fixed(m.pass("count"), 3), fixed(alloc, 3), fixed(occupancy, 3),
                             fixed(m.pass("capture"), 3), fixed(m.pass("resolve"), 3), ""});
      csv.row(row);
      ++methodIndex;
    }
    table.print();
    ++sceneIndex;
  }
  std::printf(
      "\nk: slots per covered pixel (min-max); MiB: bytes used (abuffer: what it needs, no budget);"
      "\nloss: %% of generated fragments not captured; pass times in ms (alloc = allocate + clear,"
      "\noccupancy = depth range + fill + count passes)\nwrote %s\n",
      csv.path().c_str());
  return failed ? 1 : 0;
}
