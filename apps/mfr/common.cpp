#include "common.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "mfr/core/memory_limit.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/method/make_method.hpp"

namespace mfr::cli {
namespace {

/// CLI11's check that an index option (--view, --scene, --orbit-view) is not negative: -1 is the
/// options' "not given", which a typed -1 must not silently mean.
CLI::Validator nonNegativeIndex(const std::string& what) {
  return CLI::Validator(
      [what](std::string& text) -> std::string {
        const char* begin = text.c_str();
        while (*begin == ' ' || *begin == '\t') ++begin;
        if (*begin != '-') return {};
        char* end = nullptr;
        const long long value = std::strtoll(begin, &end, 0);
        if (end == begin || value == 0) return {};  // not a number: CLI11 says so; -0 is 0
        return "must be 0 or more (" + what + ", 0-based), got " + quoteInput(text, 40);
      },
      "");
}

}  // namespace

void SceneOptions::add(CLI::App& app, bool sceneArgument, bool engineOption) {
  if (sceneArgument)
    app.add_option("scene", source,
                   "Scene file (.gltf .glb .obj .ply .json) or procedural:NAME[?k=v&...]")
        ->required();
  app.add_option("--width", width, "Image width in pixels (1-16384)");
  app.add_option("--height", height, "Image height in pixels (1-16384)");
  app.add_option("--camera", camera,
                 "EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ[,FOV]]: eye, target, up, fov (deg)");
  app.add_option("--view", view, "Use the scene file's camera number N (0-based)")
      ->check(nonNegativeIndex("a camera of the scene file"));
  app.add_option("--scene", gltfScene,
                 "Which of a glTF file's scenes to load, N (0-based; default: the file's own)")
      ->check(nonNegativeIndex("a scene of the glTF file"));
  app.add_option("--orbit", orbit, "Render N views on a circle around the scene");
  app.add_option("--orbit-view", orbitView, "With --orbit N: only view I of the N (0-based)")
      ->check(nonNegativeIndex("a view of the orbit"));
  app.add_option("--zoom", zoom,
                 "Move the camera Z times closer to its target (default 1; 2 = half the distance)");
  app.add_option("--threads", threads,
                 "Worker threads, 0-" + std::to_string(kMaxThreads) + " (default 0: all cores)");
  app.add_option("--seed", seed, "Seed for procedural scenes and noise (default 1)");
  app.add_option("--shuffle-draw-order", shuffleDrawOrder,
                 "Submit the scene's triangles in the random order of this seed");
  app.add_option("--alpha", alpha,
                 "Override every material's alpha (render the whole scene transparent)");
  app.add_option("--background", background, "Background R,G,B (linear, 0-1)")
      ->delimiter(',')
      ->expected(3);
  app.add_option(
      "--transmission-floor", transmissionFloor,
      "Alpha floor for KHR_materials_transmission glass (alpha = max(floor, 1 - transmission))");
  app.add_option("--cull", cull,
                 "Back faces culled: auto (as the file says: glTF materials with doubleSided "
                 "false; OBJ, PLY, JSON and procedural scenes are double-sided), none or back "
                 "(every back face; front = counter-clockwise) (default auto)");
  app.add_option("--blend", blend,
                 "Blend mode of every material (MODE) or of the materials named MATERIAL "
                 "(MATERIAL=MODE); repeatable, applied in order. MODE: over (default), "
                 "premultiplied, additive or multiply (docs/METHODS.md, blend modes)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_option("--samples", samples,
                 "Samples per pixel: 1, 2, 4 or 8 at the standard Direct3D / Vulkan positions "
                 "(antialiasing; both engines, GL on its native raster) (default 1)");
  app.add_option("--sample-storage", sampleStorage,
                 "With --samples > 1, how a method stores a pixel's samples: pixel (one node per "
                 "fragment with its coverage mask, composited per sample) or sample (nodes per "
                 "sample) (default pixel; the ground truth is always per sample)");
  app.add_flag("--quiet,-q", quiet, "No progress or summary on the terminal");
  app.add_flag("--json", json, "Print machine-readable JSON on stdout");
  app.add_flag("--allow-outside-references", allowOutsideReferences,
               "Let files named inside a scene file (glTF buffers and images, OBJ mtllib and "
               "map_Kd, a JSON scene's mesh) lie outside its folder (never FIFOs or devices)");
  app.add_option("--memory-limit", memoryLimit,
                 "Refuse to allocate buffers larger than this, e.g. 8GB (default: " +
                     std::to_string(static_cast<int>(kDefaultMemoryShare * 100)) +
                     "% of the physical memory, of the address-space limit (ulimit -v) or of the "
                     "cgroup's memory limit, whichever is least: " +
                     formatBytes(defaultMemoryLimit()) + ")");
  if (engineOption) {
    std::string names;
    for (const std::string& n : engineNames()) names += (names.empty() ? "" : "|") + n;
    app.add_option("--engine", engine,
                   "Engine that renders: " + names + " (default " + engine + ")");
    app.add_option("--gl-sync", glSync,
                   "GL engine's k-buffer capture: auto (the fragment shader interlock when the "
                   "driver offers it, else the spin-lock), lock or interlock (default auto)");
    app.add_option("--gl-raster", glRaster,
                   "GL engine's geometry passes: native (GL's own clipper, rasterizer and "
                   "interpolation in single precision: what a GPU engine runs) or exact (the CPU "
                   "engine's raster emulated in a geometry shader, partly in double: "
                   "bit-identical to --engine cpu, a cross-check) (default native)");
  }
}

Result<std::unique_ptr<Engine>> makeSceneEngine(const SceneOptions& o) {
  EngineOptions eo;
  eo.threads = o.threads;
  eo.glSync = o.glSync;
  eo.glRaster = o.glRaster;
  return makeEngine(o.engine, eo);
}

View sceneView(const PreparedScene& prepared, const SceneOptions& o, const Camera& camera) {
  View v;
  v.scene = &prepared.scene;
  v.camera = camera;
  v.width = o.width;
  v.height = o.height;
  v.samples = o.sampleCount();
  return v;
}

Result<uint64_t> SceneOptions::memoryLimitBytes() const {
  if (memoryLimit.empty()) return defaultMemoryLimit();
  return parseMemoryLimitOption(memoryLimit);
}

SceneRequest SceneOptions::request() const {
  SceneRequest r;
  r.width = width;
  r.height = height;
  r.camera = camera;
  r.view = view;
  r.orbit = orbit;
  r.orbitView = orbitView;
  r.zoom = zoom;
  r.shuffleDrawOrder = shuffleDrawOrder;
  r.alpha = alpha;
  r.background = background;
  r.transmissionFloor = transmissionFloor;
  r.cull = cull;
  r.blend = blend;
  if (gltfScene != -1) r.gltfScene = gltfScene;
  return r;
}

Result<PreparedScene> prepareScene(const SceneOptions& o) {
  const SceneRequest request = o.request();
  MFR_TRY(checkSceneRequest(request));
  MFR_TRY(checkThreads(o.threads, "--threads"));
  if (auto s = parseSamples(o.samples, "--samples"); !s) return s.error();
  if (auto s = parseSampleStorage(o.sampleStorage, "--sample-storage"); !s) return s.error();
  auto memoryLimit = o.memoryLimitBytes();
  if (!memoryLimit) return memoryLimit.error();

  LoadOptions load;
  load.seed = o.seed;
  load.transmissionAlphaFloor = static_cast<float>(o.transmissionFloor);
  load.allowOutsideReferences = o.allowOutsideReferences;
  load.memoryLimitBytes = memoryLimit.value();
  load.sceneIndex = request.gltfScene;
  auto loaded = loadScene(o.source, load);
  if (!loaded) return loaded.error();
  PreparedScene prepared{std::move(loaded.value()), {}, {}};
  MFR_TRY(applyToScene(request, prepared.scene));
  auto views = sceneViews(prepared.scene, o.source, request);
  if (!views) return views.error();
  prepared.cameras = std::move(views->cameras);
  prepared.previousCamera = views->previousCamera;
  return prepared;
}

std::string viewPath(const std::string& path, int view, int views) {
  if (views <= 1 || path.empty()) return path;
  std::filesystem::path p(path);
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, "_v%03d", view);
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

Progress::Progress(bool enabled) : enabled_(enabled), terminal_(isatty(STDERR_FILENO) != 0) {
  // MFR_PROGRESS_SECONDS: the seconds between lines in a log (a number in [0.1, 3600])
  if (const char* text = std::getenv("MFR_PROGRESS_SECONDS")) {
    char* end = nullptr;
    const double seconds = std::strtod(text, &end);
    if (end != text && *end == '\0' && seconds >= 0.1 && seconds <= 3600.0) logSeconds_ = seconds;
  }
  if (enabled_) thread_ = std::thread([this] { loop(); });
}

Progress::~Progress() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (printed_) std::fprintf(stderr, "\r\033[K");
}

void Progress::set(const std::string& stage, int done, int total) {
  std::lock_guard<std::mutex> lock(mutex_);
  stage_ = stage;
  done_ = done;
  total_ = total;
}

void Progress::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (printed_) std::fprintf(stderr, "\r\033[K");
  printed_ = false;
}

void Progress::loop() {
  const auto start = std::chrono::steady_clock::now();
  static const char spinner[] = "|/-\\";
  int tick = 0;
  double lastLine = 0.0;  // without a terminal: when the last line was printed
  std::string lastStage;
  while (!stop_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed < std::min(1.0, logSeconds_) || stop_) continue;
    std::lock_guard<std::mutex> lock(mutex_);
    if (!terminal_) {  // a log: a plain line every kLogSeconds at most, while the stage changes
      const bool due = elapsed - lastLine >= logSeconds_ &&
                       (stage_ != lastStage || elapsed - lastLine >= 6.0 * logSeconds_);
      if (!due) continue;
      const std::string count =
          total_ > 0 ? std::to_string(done_) + "/" + std::to_string(total_) + " " : std::string();
      std::fprintf(stderr, "progress: %s%s (%.0f s)\n", count.c_str(), stage_.c_str(), elapsed);
      std::fflush(stderr);
      lastLine = elapsed;
      lastStage = stage_;
      continue;
    }
    std::string bar;
    if (total_ > 0) {
      const int width = 24, filled = done_ * width / total_;
      bar = "[" + std::string(filled, '#') + std::string(width - filled, '.') + "] " +
            std::to_string(done_) + "/" + std::to_string(total_) + " ";
    }
    std::fprintf(stderr, "\r\033[K%c %s%s  %.1fs", spinner[tick++ % 4], bar.c_str(), stage_.c_str(),
                 elapsed);
    std::fflush(stderr);
    printed_ = true;
  }
}

std::string appliesTo(MethodOption option) {
  return " (applies to: " + presetsAccepting(option) + ")";
}

std::string presetHelp() {
  std::string list;
  for (const PresetInfo& p : presetTable()) list += "\n  " + p.name + ": " + p.summary;
  return "Method (`mfr presets` lists the papers; each bounded one also NAME+occupancy):" + list;
}

int fail(const std::string& message) {
  std::fprintf(stderr, "mfr: error: %s\n", oneLine(message, kMaxErrorMessage).c_str());
  return 1;
}

namespace {

namespace fs = std::filesystem;

/// What `path` names once `.`, `..` and the symbolic links of its existing part are resolved.
std::string resolvedOutput(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) p = path;
  fs::path resolved = fs::weakly_canonical(p, ec);
  if (ec) resolved = p.lexically_normal();
  std::string key = resolved.string();
  while (key.size() > 1 && key.back() == '/') key.pop_back();  // "DIR/" is "DIR"
  return key;
}

/// An existing device, FIFO or socket: written in place, so two outputs there lose nothing.
bool isSpecialFile(const std::string& resolved) {
  struct stat st {};
  return ::stat(resolved.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

}  // namespace

Result<void> checkDistinctOutputs(const std::vector<OutputFile>& outputs,
                                  const std::vector<OutputFile>& inputs) {
  std::vector<std::pair<const OutputFile*, std::string>> seen;
  for (const OutputFile& output : outputs) {
    if (output.path.empty()) continue;
    const std::string resolved = resolvedOutput(output.path);
    if (isSpecialFile(resolved)) continue;
    for (const auto& [earlier, key] : seen)
      if (key == resolved)
        return makeError(earlier->option + " " + quoteInput(earlier->path, 256) + " and " +
                         output.option + " " + quoteInput(output.path, 256) +
                         " are the same file: one output would replace the other (give each its "
                         "own path)");
    seen.emplace_back(&output, resolved);
  }
  for (const OutputFile& input : inputs) {
    if (input.path.empty()) continue;
    const std::string resolved = resolvedOutput(input.path);
    for (const auto& [output, key] : seen)
      if (key == resolved)
        return makeError(output->option + " " + quoteInput(output->path, 256) + " is the " +
                         input.option + " " + quoteInput(input.path, 256) +
                         " this run reads: writing it would replace that input (give the output "
                         "its own path)");
  }
  return {};
}

namespace {

/// The check guardIntegerOptions adds: "" when `text` converts within 64 bits (and, `isUnsigned`,
/// is not negative); malformed text is left to CLI11's own conversion and its message.
std::string integerRangeProblem(const std::string& text, bool isUnsigned) {
  const char* begin = text.c_str();
  while (*begin == ' ' || *begin == '\t' || *begin == '\n') ++begin;
  char* end = nullptr;
  errno = 0;
  if (isUnsigned) {
    const unsigned long long value = std::strtoull(begin, &end, 0);
    if (end == begin) return {};
    if (errno == ERANGE) return "out of range (more than 64 bits), got " + quoteInput(text, 40);
    if (*begin == '-' && value != 0) return "must be 0 or more, got " + quoteInput(text, 40);
    return {};
  }
  (void)std::strtoll(begin, &end, 0);
  if (end != begin && errno == ERANGE)
    return "out of range (more than 64 bits), got " + quoteInput(text, 40);
  return {};
}

}  // namespace

void guardIntegerOptions(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    const std::string base = type.substr(0, type.find(':'));  // "UINT:..." with a validator
    if (base != "UINT" && base != "INT") continue;
    const bool isUnsigned = base == "UINT";
    option->check(CLI::Validator(
        [isUnsigned](std::string& text) { return integerRangeProblem(text, isUnsigned); }, ""));
  }
  for (CLI::App* sub : app.get_subcommands({})) guardIntegerOptions(*sub);
}

}  // namespace mfr::cli
