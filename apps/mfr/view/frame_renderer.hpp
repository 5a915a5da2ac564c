// The viewer's renders, through the Engine interface only: the method's RenderOutput for the
// current settings, the exact A-buffer of the same view (ground truth, FLIP and PSNR), and the
// sRGB image of the current view mode. Renders are cached by their key: changing only the view
// mode or the wiper re-uses them.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "../common.hpp"
#include "engine_context.hpp"
#include "mfr/core/image.hpp"
#include "mfr/engine/engine.hpp"
#include "view_settings.hpp"

namespace mfr::view {

struct Frame {
  Image8 display;     // what the image area shows (maps carry their legend strip below)
  std::string error;  // one line: the engine refused the method, or the mode has no map
  std::optional<RenderStats> stats;
  std::optional<double> flipMean;  // of the method's image against the A-buffer
  std::optional<double> psnr;      // linear, dB
  double renderMs = 0.0;           // wall time of this update (renders, maps, metrics)
  uint64_t truthBytes = 0;         // the exact A-buffer's bytes_used
};

class FrameRenderer {
 public:
  FrameRenderer(Engine& engine, const EngineContext& context, GLFWwindow* window,
                const cli::PreparedScene& scene, const cli::SceneOptions& options);
  ~FrameRenderer();
  /// Renders what changed since the last call and composes the display of settings.mode. Callable
  /// from one thread at a time: on the window's thread, or on a worker while the window's thread
  /// keeps its own context (the engine's context is made current on the calling thread).
  Frame update(const ViewSettings& settings);

 private:
  struct Cached;
  Engine& engine_;
  const EngineContext& context_;
  GLFWwindow* window_;
  std::thread::id windowThread_;  // where the window's context lives (the constructing thread)
  const cli::PreparedScene& scene_;
  cli::SceneOptions options_;
  std::unique_ptr<Cached> cache_;
};

/// The method description of the settings (preset, k, compositing), errors as `mfr render`'s.
Result<MethodDesc> settingsMethod(const ViewSettings& settings);

}  // namespace mfr::view
