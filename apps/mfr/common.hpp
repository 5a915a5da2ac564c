// Shared pieces of the mfr command line: scene/camera options, progress display, output helpers.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "mfr/core/result.hpp"
#include "mfr/core/samples.hpp"
#include "mfr/engine/engine.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/scene_request.hpp"

namespace mfr::cli {

/// Options every scene-rendering command shares.
struct SceneOptions {
  std::string source;
  int width = 1024;
  int height = 1024;
  std::string camera;  // "EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ[,FOV]]" (parseCameraSpec)
  int view = -1;       // camera of the file, by index
  int gltfScene = -1;  // --scene: which of a glTF file's scenes (-1: the file's own)
  int orbit = 0;       // N views around the scene
  int orbitView = -1;  // with orbit: only this one of the N views
  double zoom = 1.0;   // camera distance to its target divided by this
  int threads = 0;
  uint64_t seed = 1;
  std::optional<uint64_t> shuffleDrawOrder;  // submit the triangles in this seed's random order
  std::optional<double> alpha;
  std::vector<double> background;
  double transmissionFloor = 0.1;
  std::string cull = "auto";       // --cull auto|none|back
  std::vector<std::string> blend;  // --blend MODE | MATERIAL=MODE, repeatable
  bool quiet = false;
  bool json = false;
  bool allowOutsideReferences = false;  // files named in a scene may lie outside its folder
  std::string memoryLimit;              // --memory-limit (empty: defaultMemoryLimit())
  std::string engine = "cpu";           // --engine (render, compare, info)
  std::string glSync = "auto";          // --gl-sync (the GL engine's k-buffer sync)
  std::string glRaster = "native";      // --gl-raster (the GL engine's geometry passes)
  std::string samples = "1";            // --samples 1|2|4|8 (core/samples.hpp)
  std::string sampleStorage = "pixel";  // --sample-storage pixel|sample

  /// --samples and --sample-storage, parsed (prepareScene checks them first).
  int sampleCount() const {
    auto s = parseSamples(samples, "--samples");
    return s ? s.value() : 1;
  }
  SampleStorage storage() const {
    auto s = parseSampleStorage(sampleStorage, "--sample-storage");
    return s ? s.value() : SampleStorage::Pixel;
  }

  /// Registers the options (and the positional scene unless the command takes several; --engine
  /// for the commands that run on either engine).
  void add(CLI::App& app, bool sceneArgument = true, bool engineOption = false);
  /// --memory-limit in bytes, or the default share of the physical memory.
  Result<uint64_t> memoryLimitBytes() const;
  /// The scene options the library checks and applies (mfr/scene/scene_request.hpp).
  SceneRequest request() const;
};

struct PreparedScene {
  Scene scene;
  std::vector<Camera> cameras;  // one per view to render
  /// With --orbit-view I > 0: view I - 1 of the orbit, the frame before the rendered one (its
  /// nearest |n.v| feeds the variable k-buffer's Fresnel term as in a full orbit).
  std::optional<Camera> previousCamera;
};

/// Loads the scene, applies overrides and resolves the cameras. Errors name the input.
Result<PreparedScene> prepareScene(const SceneOptions& options);

/// The engine named by --engine, running --threads workers.
Result<std::unique_ptr<Engine>> makeSceneEngine(const SceneOptions& options);

/// The view of a prepared scene from one of its cameras at --width x --height.
View sceneView(const PreparedScene& prepared, const SceneOptions& options, const Camera& camera);

/// "out.png" -> "out_v003.png" when rendering several views.
std::string viewPath(const std::string& path, int view, int views);

/// A progress line on a terminal (stderr), shown only for work that lasts more than a second.
/// A command's progress on stderr while it works: on a terminal a line redrawn in place after
/// the first second; otherwise (a log, a pipe) a plain "progress: 3/12 STAGE (12 s)" line at most
/// every 5 s (MFR_PROGRESS_SECONDS) when the stage has changed, every 30 s (six times that) when
/// it has not, and nothing for a command done within the first 5 s.
class Progress {
 public:
  explicit Progress(bool enabled);
  ~Progress();
  void set(const std::string& stage, int done = -1, int total = -1);
  /// Erases the progress line (if one was drawn) so a normal line can be printed.
  void clear();

 private:
  void loop();
  bool enabled_;
  bool terminal_;
  double logSeconds_ = 5.0;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::string stage_;
  int done_ = -1, total_ = -1;
  bool printed_ = false;
  std::thread thread_;
};

/// " (applies to: fkb, kplus-array, ...)" for an option's help text, from the option table.
std::string appliesTo(MethodOption option);

/// "Method: zbuffer, abuffer, ... (each bounded one also NAME+occupancy)" from the preset list.
std::string presetHelp();

/// Prints "mfr: error: <message>" (one line, cut at kMaxErrorMessage characters) and returns the
/// exit code 1.
int fail(const std::string& message);
inline constexpr size_t kMaxErrorMessage = 1000;

/// One file a command writes: the option that names it and its path as given.
struct OutputFile {
  std::string option;
  std::string path;
};

/// Refuses two outputs of one run that are the same file (one would silently replace the other):
/// paths are compared absolute, with `.`, `..` and symbolic links resolved as far as they exist
/// (std::filesystem::weakly_canonical), so `X`, `./X`, `a/../X` and a link to X's folder are one
/// file. Empty paths (an output not asked for) are skipped, and so are existing special files
/// (`/dev/null`, `/dev/stdout`: written in place, nothing is replaced). The error names both
/// options and the paths: "--out 'X' and --stats-json './X' are the same file: ...". An output
/// that is one of the run's `inputs` (a dataset `mfr train` reads, an image `mfr metrics`
/// compares, the scene or model `mfr render` reads) is refused the same way. Every command
/// writing several files calls it before any work.
Result<void> checkDistinctOutputs(const std::vector<OutputFile>& outputs,
                                  const std::vector<OutputFile>& inputs = {});

/// Adds to every integer option of `app` and its subcommands (CLI11 type INT or UINT) a check of
/// the text before CLI11 converts it, which would silently saturate: an unsigned option refuses a
/// negative value (strtoull wraps -1 to 2^64 - 1), and any value beyond 64 bits is refused
/// (strtoull and strtoll saturate). Syntax errors, like the other malformed values.
void guardIntegerOptions(CLI::App& app);

}  // namespace mfr::cli
