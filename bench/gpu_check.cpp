// gpu_check: every preset on the GL engine's native raster against the CPU engine, one CSV. What
// scripts/gpu-check.sh runs on a machine with a GPU (it prints the GL context first and finds the
// runtime libraries); on llvmpipe the same checks at a small size keep the script from rotting.
//
// Scenes (in this order, the cheap ones first so that --time-limit trims the heaviest):
//   layers    procedural:layers?k=8&r=2&pd=0.55
//   bottles   procedural:bottles
//   Dish      IridescentDishWithOlives (../shared/scenes, or --dish PATH), alpha 0.5, zoom 1.6 as
//             in bench_engines; a row with status "skipped" when the file is absent
//   hairball  procedural:hairball
// Presets: every name presetNames() lists that the GL engine runs (every one) and the +occupancy
// form of each that has one, as
// tests/gl/test_gl_native.cpp enumerates them; bounded ones under M = 64 bytes per pixel (64 MiB
// at 1024x1024; the GlNative ctest gives 50-67), or --budget: bench_presets' 20 MiB would leave
// every preset whose per-pixel buffers take more than 20 bytes (the deep and optimal k-buffers,
// the peer methods, most +occupancy forms; up to 48 bytes) refused. Per scene and preset: the CPU
// engine renders once (its frame's wall time; its image is the reference); the GL engine (native,
// --gl-sync auto) renders once untimed, then --reps times: the median frame (wall time of render())
// and the median of each pass, timed by GL_TIME_ELAPSED where the driver's timer queries are usable
// and by the host clock otherwise (gl_pass_timer.hpp; column pass_timer says which). Agreement, as
// the GlNative ctest checks it: the fraction of pixels whose n(p) is equal (each engine's count
// pass, once per scene), bytes_used of both, the mean LDR-FLIP of the GL image against the CPU
// engine's and the largest per-channel difference (linear RGB). Status: ok (n(p) equal on >= 99.9%
// of the pixels, bytes_used equal (vkb, dkb: within 0.1% and the budget), mean FLIP <= 2e-3, or the
// bound of an arrival-order-dependent rule: flipBound),
// refused (both engines refused the budget with the same message), differs (an agreement figure out
// of bounds), error (one engine failed; the message in the error column), skipped (--time-limit
// reached, or the Dish absent). Exit status: 0 when every row is ok, refused or skipped; 1 when one
// differs or failed; 2 a bad command line; 3 no GL 4.5 context.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "gl_pass_timer.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/gl/gl_render_engine.hpp"
#include "mfr/gl/gl_technique.hpp"
#include "mfr/method/aoit.hpp"
#include "mfr/method/mboit.hpp"
#include "mfr/metrics/flip.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{
    .name = "gpu_check",
    .csv = "gpu-check.csv",
    .quick = "scenes layers and bottles, ",
    .options = " [--scenes LIST] [--presets LIST] [--dish PATH] [--budget M] [--time-limit S]",
    .optionsHelp =
        "  --scenes LIST   comma-separated, of layers,bottles,dish,hairball (default all;\n"
        "                  --quick: layers,bottles)\n"
        "  --presets LIST  comma-separated preset names, +occupancy forms included (default every\n"
        "                  preset and its +occupancy form)\n"
        "  --dish PATH     the IridescentDishWithOlives glTF (default under ../shared/scenes)\n"
        "  --budget M      memory budget of the bounded presets, e.g. 20MB (default 64 bytes\n"
        "                  per pixel: 64 MiB at 1024x1024)\n"
        "  --time-limit S  no new case after S seconds: the rest are rows with status skipped\n"
        "                  (default 450; 0: no limit)\n"};

constexpr uint64_t kBudgetAt1024 = 64ull << 20;  // 64 bytes per pixel
constexpr double kMinEqualCounts = 0.999;        // the GlNative ctest's bounds
constexpr double kMaxFlipMean = 2e-3;

// The rules whose image depends on the order fragments reach a pixel, which the GL engine's lock
// does not fix (the GlNative ctest's bounds, measured there): the 16-bit moments re-round per
// fragment (2e-2), AOIT's removals beyond N + 1 fragments (1e-1); a linked list whose pool
// overflowed admits other fragments (its counts are checked instead, no FLIP bound). The noise
// methods (stochastic, stochastic-strat, hashed-alpha) dither differently on the native raster
// (their hashes read the fragments' bits): their FLIP is reported, not bounded; the GlNative ctest
// compares their error against the truth instead.
std::optional<double> flipBound(const MethodDesc& m, uint64_t cpuLost) {
  if (m.store == StoreChoice::LinkedList && cpuLost > 0) return std::nullopt;
  if (m.compositing == Compositing::Stochastic8 || m.compositing == Compositing::StochasticStrat8 ||
      m.compositing == Compositing::HashedAlpha)
    return std::nullopt;
  if (mboitQuantized(m.compositing)) return 2e-2;
  if (aoitNodeCount(m.compositing) > 0) return 1e-1;
  return kMaxFlipMean;
}
constexpr double kImportanceBytesApart = 1e-3;

const char* const kHeader =
    "preset,scene,status,width,height,budget_bytes,pass_timer,gl_frame_ms,gl_passes_ms,gl_pass_ms,"
    "cpu_frame_ms,gl_over_cpu,fragments,np_equal_fraction,bytes_used_gl,bytes_used_cpu,flip_mean,"
    "max_abs_diff,renderer,sync,error";

// Pulls "NAME VALUE" out of argv (before parseArgs, which knows only the common options).
std::optional<std::string> takeOption(int& argc, char** argv, const std::string& name) {
  std::optional<std::string> value;
  for (int i = 1; i < argc; ++i) {
    if (argv[i] != name) continue;
    if (i + 1 >= argc) {
      printError(kProgram, name + " needs a value");
      std::exit(2);
    }
    value = argv[i + 1];
    for (int j = i; j + 2 <= argc; ++j) argv[j] = argv[j + 2];
    argc -= 2;
    --i;
  }
  return value;
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  size_t at = 0;
  while (at <= text.size()) {
    const size_t comma = std::min(text.find(',', at), text.size());
    if (comma > at) out.push_back(text.substr(at, comma - at));
    at = comma + 1;
  }
  return out;
}

bool contains(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

// every preset the GL engine runs and the +occupancy form of each that has one
// (test_gl_native.cpp's list; the CPU engine's stochastic presets are not in the GL engine)
std::vector<std::string> allPresets() {
  std::vector<std::string> out;
  for (const std::string& base : presetNames())
    for (const std::string& name : {base, base + "+occupancy"})
      if (auto m = methodPreset(name); m && gl::classifyGl(m.value()).ok()) out.push_back(name);
  return out;
}

struct Settings {
  Args args;
  std::vector<std::string> scenes, presets;
  std::string dish;
  uint64_t budget = 0;
  double timeLimitS = 450.0;
};

Settings parseSettings(int argc, char** argv) {
  Settings s;
  const auto scenes = takeOption(argc, argv, "--scenes");
  const auto presets = takeOption(argc, argv, "--presets");
  const auto dish = takeOption(argc, argv, "--dish");
  const auto limit = takeOption(argc, argv, "--time-limit");
  std::optional<uint64_t> budget;
  if (!takeBudget(kProgram, argc, argv, budget)) std::exit(2);
  s.args = parseArgs(argc, argv, kProgram);
  if (s.args.out == "bench-results") s.args.out = "gpu-check-results";
  s.scenes =
      splitList(scenes.value_or(s.args.quick ? "layers,bottles" : "layers,bottles,dish,hairball"));
  for (const std::string& name : s.scenes)
    if (!contains({"layers", "bottles", "dish", "hairball"}, name)) {
      printError(kProgram, "--scenes: unknown scene '" + name +
                               "' (expected layers, bottles, dish, hairball)");
      std::exit(2);
    }
  const std::vector<std::string> known = allPresets();
  s.presets = presets ? splitList(*presets) : known;
  for (const std::string& name : s.presets)
    if (!contains(known, name)) {
      printError(kProgram, "--presets: unknown preset '" + name + "' (mfr presets lists them)");
      std::exit(2);
    }
  s.dish = dish.value_or(std::string(MFR_SCENES_DIR) +
                         "/khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf");
  const double pixelScale = static_cast<double>(s.args.size) * s.args.size / (1024.0 * 1024.0);
  s.budget =
      budget.value_or(static_cast<uint64_t>(static_cast<double>(kBudgetAt1024) * pixelScale));
  if (limit) {
    char* end = nullptr;
    s.timeLimitS = std::strtod(limit->c_str(), &end);
    if (end == limit->c_str() || *end != '\0' || !(s.timeLimitS >= 0.0)) {
      printError(kProgram, "--time-limit needs seconds >= 0");
      std::exit(2);
    }
  }
  return s;
}

// The pass times of the GL engine's timed renders: per pass (in the frame's order) its samples
// and timer.
struct PassSamples {
  std::string name;
  PassTimer timer = PassTimer::Wall;
  std::vector<double> ms;
};

void addPasses(std::vector<PassSamples>& passes, const std::vector<TimedPass>& frame) {
  for (const TimedPass& p : frame) {
    auto it = std::find_if(passes.begin(), passes.end(),
                           [&](const PassSamples& s) { return s.name == p.name; });
    if (it == passes.end()) it = passes.insert(passes.end(), {p.name, p.timer, {}});
    it->ms.push_back(p.ms);
  }
}

struct SceneSetup {
  std::string label;
  std::unique_ptr<PreparedView> gl, cpu;
};

struct Row {
  std::string status, error;
  double glFrame = NAN, glPassSum = NAN, cpuFrame = NAN, flip = NAN, maxDiff = NAN;
  std::string passList;
  uint64_t fragments = 0, bytesGl = 0, bytesCpu = 0;
  bool ran = false;  // both engines rendered
};

class Checker {
 public:
  Checker(const Settings& settings, Engine& gl, Engine& cpu, Csv& csv)
      : s_(settings), gl_(gl), cpu_(cpu), csv_(csv) {
    const auto d = gl.describe();
    renderer_ = d.at("renderer");
    sync_ = d.at("sync");
    timer_ = glPassTimer(renderer_);
  }

  PassTimer timer() const { return timer_; }
  bool failed() const { return failed_; }
  const std::map<std::string, int>& statusCounts() const { return counts_; }
  double worstFlip() const { return worstFlip_; }
  const std::string& worstFlipCase() const { return worstFlipCase_; }

  void scene(const std::string& name) {
    SceneSetup sc;
    equal_ = NAN;
    std::string source = name == "layers"    ? "procedural:layers?k=8&r=2&pd=0.55"
                         : name == "bottles" ? "procedural:bottles"
                         : name == "dish"    ? s_.dish
                                             : "procedural:hairball";
    sc.label = name == "dish" ? "Dish" : name;
    if (name == "dish" && !std::filesystem::exists(source)) {
      std::printf("skipping Dish: %s not found (--dish PATH)\n", source.c_str());
      Row r;
      r.status = "skipped";
      r.error = source + " not found";
      write("-", sc.label, r);
      return;
    }
    auto loaded = loadScene(source);
    if (!loaded) return sceneError(sc.label, loaded.error().message);
    Scene& scene = loaded.value();
    Camera camera = sceneCamera(scene);
    if (name == "dish") {  // the evaluation's framing of the real scenes (bench_engines')
      scene.alphaOverride = 0.5f;
      camera.eye = camera.target + (camera.eye - camera.target) / 1.6f;
    }
    const View view{&scene, camera, s_.args.size, s_.args.size};
    auto gv = gl_.prepare(view);
    if (!gv) return sceneError(sc.label, "GL engine: " + gv.error().message);
    auto cv = cpu_.prepare(view);
    if (!cv) return sceneError(sc.label, "CPU engine: " + cv.error().message);
    sc.gl = std::move(gv.value());
    sc.cpu = std::move(cv.value());
    auto gn = gl_.countFragments(*sc.gl);
    if (!gn) return sceneError(sc.label, "GL engine: " + gn.error().message);
    auto cn = cpu_.countFragments(*sc.cpu);
    if (!cn) return sceneError(sc.label, "CPU engine: " + cn.error().message);
    size_t equal = 0;
    for (size_t p = 0; p < std::min(gn->size(), cn->size()); ++p) equal += (*gn)[p] == (*cn)[p];
    equal_ = gn->size() == cn->size() && !cn->empty()
                 ? static_cast<double>(equal) / static_cast<double>(cn->size())
                 : 0.0;
    std::printf("== %s (%s), %dx%d: n(p) equal at %.4f%% of the pixels\n", sc.label.c_str(),
                source.c_str(), s_.args.size, s_.args.size, 100.0 * equal_);
    std::fflush(stdout);
    for (const std::string& preset : s_.presets) write(preset, sc.label, check(sc, preset));
  }

 private:
  void sceneError(const std::string& label, const std::string& message) {
    printError(kProgram, label + ": " + message);
    Row r;
    r.status = "error";
    r.error = message;
    write("-", label, r);
  }

  Row check(const SceneSetup& sc, const std::string& preset) {
    Row r;
    if (s_.timeLimitS > 0.0 && msSince(start_) > 1e3 * s_.timeLimitS) {
      r.status = "skipped";
      r.error = "--time-limit " + fixed(s_.timeLimitS, 0) + " s reached";
      return r;
    }
    const MethodDesc method = methodPreset(preset).value();
    RenderOptions options;
    if (method.allocation != AllocationPolicy::Unbounded) options.budgetBytes = s_.budget;
    options.background = glm::vec3(0.2f, 0.4f, 0.6f);
    RenderOptions cpuOptions = options;  // the GL k-buffers lock per pixel (test_gl_seam)
    if (method.allocation != AllocationPolicy::Unbounded && method.store != StoreChoice::MultiLayer)
      cpuOptions.capture = CaptureMode::FragmentParallel;

    Clock::time_point t0 = Clock::now();
    auto c = cpu_.render(*sc.cpu, method, cpuOptions);
    r.cpuFrame = msSince(t0);
    auto g = gl_.render(*sc.gl, method, options);  // untimed: first use of the method's programs
    std::vector<double> frames;
    std::vector<PassSamples> passes;
    for (int rep = 0; rep < s_.args.reps && g; ++rep) {
      t0 = Clock::now();
      g = gl_.render(*sc.gl, method, options);
      if (!g) break;
      frames.push_back(msSince(t0));
      addPasses(passes, glPassTimes(g->stats, timer_));
    }
    if (!c || !g) {
      const std::string ce = c ? "" : c.error().message, ge = g ? "" : g.error().message;
      r.status = !c && !g && ce == ge ? "refused" : "error";
      r.cpuFrame = NAN;  // no frame to compare
      r.error = ce == ge ? ce
                         : (c ? "" : "CPU engine: " + ce) + (!c && !g ? "; " : "") +
                               (g ? "" : "GL engine: " + ge);
      return r;
    }
    r.ran = true;
    r.glFrame = median(frames);
    r.glPassSum = 0.0;
    std::vector<TimedPass> medians;
    for (const PassSamples& p : passes) {
      medians.push_back({p.name, median(p.ms), p.timer});
      r.glPassSum += medians.back().ms;
    }
    r.passList = passList(medians, timer_ == PassTimer::Gpu);
    r.fragments = c->stats.fragmentsGenerated;
    r.bytesGl = g->stats.bytesUsed;
    r.bytesCpu = c->stats.bytesUsed;
    r.maxDiff = maxAbsDiff(c->image, g->image);
    auto flip = computeFlip(encodeSrgb(c->image), encodeSrgb(g->image));
    if (!flip) {
      r.status = "error";
      r.error = "FLIP: " + flip.error().message;
      return r;
    }
    r.flip = flip->mean;
    std::vector<std::string> out;  // the bounds a figure is outside of
    if (equal_ < kMinEqualCounts) out.push_back("n(p) equal below 99.9%");
    const bool importance = method.allocation == AllocationPolicy::Importance;
    const double apart =
        std::fabs(static_cast<double>(r.bytesGl) - static_cast<double>(r.bytesCpu));
    if (importance ? apart > kImportanceBytesApart * static_cast<double>(r.bytesCpu) ||
                         (options.budgetBytes && r.bytesGl > *options.budgetBytes)
                   : r.bytesGl != r.bytesCpu)
      out.push_back(importance ? "bytes_used more than 0.1% apart" : "bytes_used differ");
    const std::optional<double> bound = flipBound(method, c->stats.lost);
    if (bound && !(r.flip <= *bound)) out.push_back("mean FLIP above " + std::to_string(*bound));
    if (!bound && method.store == StoreChoice::LinkedList &&
        (g->stats.captured != g->stats.fragmentSlots ||
         c->stats.captured != c->stats.fragmentSlots))
      out.push_back("a full pool's captured fragments are not its size");
    r.status = out.empty() ? "ok" : "differs";
    for (const std::string& why : out) r.error += (r.error.empty() ? "" : "; ") + why;
    return r;
  }

  void write(const std::string& preset, const std::string& scene, const Row& r) {
    ++counts_[r.status];
    if (r.status == "differs" || r.status == "error") failed_ = true;
    if (r.ran && r.flip >= worstFlip_) {
      worstFlip_ = r.flip;
      worstFlipCase_ = preset + " on " + scene;
    }
    const auto opt = [&](double v, int decimals) {
      return std::isfinite(v) ? fixed(v, decimals) : std::string();
    };
    const bool bounded =
        preset != "-" && methodPreset(preset).value().allocation != AllocationPolicy::Unbounded;
    const std::string side = std::to_string(s_.args.size);
    std::vector<std::string> cells = {preset,
                                      scene,
                                      r.status,
                                      side,
                                      side,
                                      bounded ? num(s_.budget) : "",
                                      toString(timer_),
                                      opt(r.glFrame, 3),
                                      opt(r.glPassSum, 3),
                                      r.passList};
    cells.insert(cells.end(), {opt(r.cpuFrame, 3),
                               r.ran && r.cpuFrame > 0.0 ? fixed(r.glFrame / r.cpuFrame, 3) : "",
                               r.ran ? num(r.fragments) : "", r.ran ? fixed(equal_, 6) : "",
                               r.ran ? num(r.bytesGl) : "", r.ran ? num(r.bytesCpu) : "",
                               opt(r.flip, 7), opt(r.maxDiff, 6), renderer_, sync_, r.error});
    csv_.row(cells);
    if (r.ran)
      std::printf("  %-24s %-7s GL %9.2f ms (passes %9.2f %s)  CPU %9.2f ms  bytes %s  FLIP %.6f\n",
                  preset.c_str(), r.status.c_str(), r.glFrame, r.glPassSum, toString(timer_),
                  r.cpuFrame, r.bytesGl == r.bytesCpu ? "equal" : "apart", r.flip);
    else
      std::printf("  %-24s %-7s %s\n", preset.c_str(), r.status.c_str(), r.error.c_str());
    std::fflush(stdout);
  }

  const Settings& s_;
  Engine& gl_;
  Engine& cpu_;
  Csv& csv_;
  std::string renderer_, sync_;
  PassTimer timer_ = PassTimer::Wall;
  const Clock::time_point start_ = Clock::now();
  std::map<std::string, int> counts_;
  bool failed_ = false;
  double worstFlip_ = 0.0;
  std::string worstFlipCase_;
  double equal_ = NAN;  // the scene's fraction of pixels whose n(p) is equal
};

}  // namespace

int main(int argc, char** argv) {
  const Settings settings = parseSettings(argc, argv);
  const Args& args = settings.args;

  auto gl = gl::makeGlEngine("auto", "native");
  if (!gl) {
    printError(kProgram, gl.error().message);
    return 3;
  }
  std::printf("gpu_check: %zu preset(s) on GL native against the CPU engine, %s\n",
              settings.presets.size(), runDescription(args, resolveThreads(args.threads)).c_str());
  const auto d = (*gl)->describe();
  for (const char* key : {"renderer", "version", "vendor", "egl_platform", "raster", "sync",
                          "fixed_k_capture", "GL_ARB_fragment_shader_interlock",
                          "GL_NV_fragment_shader_interlock", "GL_INTEL_fragment_shader_ordering",
                          "GL_ARB_gpu_shader_int64", "GL_NV_shader_atomic_int64"})
    std::printf("  %-34s %s\n", key, d.count(key) ? d.at(key).c_str() : "?");
  const PassTimer timer = glPassTimer(d.at("renderer"));
  std::printf("  %-34s %s\n", "pass timer",
              timer == PassTimer::Gpu ? "gpu (GL_TIME_ELAPSED queries)"
                                      : "wall (host clock with glFinish: a software rasterizer's "
                                        "timer queries are not usable)");
  std::printf("  budget of the bounded presets: %s (%llu bytes)\n\n",
              formatBytes(settings.budget).c_str(),
              static_cast<unsigned long long>(settings.budget));

  Csv csv = openCsv(kProgram, args, kHeader);
  CpuEngine cpu(EngineOptions{args.threads, 32});
  Checker checker(settings, **gl, cpu, csv);
  for (const std::string& scene : settings.scenes) checker.scene(scene);

  std::printf("\nrows:");
  for (const auto& [status, n] : checker.statusCounts()) std::printf(" %s %d", status.c_str(), n);
  std::printf("; worst mean FLIP %.6f (%s)\nCSV: %s\n", checker.worstFlip(),
              checker.worstFlipCase().c_str(), csv.path().string().c_str());
  return checker.failed() ? 1 : 0;
}
