// The seam between the method descriptions and the machines that run them. An Engine turns a
// scene seen from a camera at a size into a PreparedView (the CPU engine: transformed, clipped
// and binned triangles; a GPU engine: uploaded geometry and its framebuffer) and renders any
// number of methods on it. Both engines take the same MethodDesc and RenderOptions and fill the
// same RenderOutput (mfr/method/render_output.hpp); what only one engine measures goes into
// RenderStats::engineCounters, not into the shared fields.
//
//   scene, camera, size --prepare--> PreparedView --render(method, options)--> RenderOutput
#pragma once

#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/core/samples.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/render_output.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

/// One frame to render: the scene (it must outlive the PreparedView: the CPU engine's triangles
/// point at its textures), the camera, the image size and the samples per pixel (core/samples.hpp:
/// 1, 2, 4 or 8 at the standard positions; RenderOptions::sampleStorage says how a method stores
/// them).
struct View {
  const Scene* scene = nullptr;
  Camera camera;
  int width = 512;
  int height = 512;
  int samples = 1;
};

/// Engine settings. `threads` (0 = all cores) and `tileSize` are the CPU engine's.
struct EngineOptions {
  int threads = 0;
  int tileSize = 16;
  /// GL engine only: the k-buffer capture's synchronisation, "auto" (the fragment shader interlock
  /// when the driver offers it, else the spin-lock), "lock" or "interlock" (--gl-sync).
  std::string glSync = "auto";
  /// GL engine only: how the geometry passes make fragments, "native" (GL's own pipeline) or
  /// "exact" (the CPU engine's raster emulated, bit-identical to it) (--gl-raster,
  /// mfr::gl::GlRaster).
  std::string glRaster = "native";
};

/// A view set up by one engine for any number of renders. Owned by the caller; render() takes it
/// back from the engine that made it (another engine's view is an error).
class PreparedView {
 public:
  virtual ~PreparedView() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  /// Samples per pixel (View::samples).
  virtual int samples() const { return 1; }
  size_t pixelCount() const { return static_cast<size_t>(width()) * static_cast<size_t>(height()); }
  /// The pixels a method's per-pixel words are kept for: the image's, times the samples under
  /// per-sample storage (what a memory model's per-pixel bytes are charged on).
  uint64_t storagePixels(SampleStorage storage) const {
    return pixelCount() * (storage == SampleStorage::Sample ? static_cast<uint64_t>(samples()) : 1);
  }
};

class Engine {
 public:
  virtual ~Engine() = default;
  /// "cpu" or "gl".
  virtual std::string_view name() const = 0;
  /// What the engine runs on, as key/value lines for `mfr info` and the report's set-up table.
  virtual std::map<std::string, std::string> describe() const = 0;
  /// The memory pre-flight that the size alone decides, checked before prepare() so that a run
  /// that cannot fit fails before the scene is set up (the CPU engine: checkPixelBuffers; default:
  /// nothing to check). render() checks it again.
  virtual Result<void> preflight(int width, int height, const MethodDesc& method,
                                 const RenderOptions& options) const;
  /// The memory this engine charges a method (DHOIT Eq. 1 as it lays the buffers out): what a
  /// relative budget adds its share to. The CPU engine charges a lock word per pixel only in
  /// fragment-parallel capture; the GL engine's k-buffers always take the per-pixel lock.
  virtual MemoryModel memoryModel(const MethodDesc& method, const RenderOptions& options) const;
  /// Sets up a view. Errors (one line): the size, the scene or the camera (see RasterFrame::build).
  virtual Result<std::unique_ptr<PreparedView>> prepare(const View& view) = 0;
  /// Renders one method on a prepared view (the passes of the method's description).
  virtual Result<RenderOutput> render(const PreparedView& view, const MethodDesc& method,
                                      const RenderOptions& options) = 0;
  /// n(p) of every pixel (a coverage count pass), rows top to bottom.
  virtual Result<std::vector<uint32_t>> countFragments(const PreparedView& view) = 0;
  /// n(p) of every storage pixel of `storage` (core/samples.hpp): what the allocation of a method
  /// that stores a multisampled view that way reads (per pixel: one count per fragment whatever
  /// its coverage; per sample: W*S x H counts). With one sample it is countFragments(). Default:
  /// countFragments() with one sample, else an error naming the engine (scene_budgets.hpp reports
  /// it instead of a budget).
  virtual Result<std::vector<uint32_t>> storageFragmentCounts(const PreparedView& view,
                                                              SampleStorage storage);
  /// |n.v| of each pixel's nearest fragment (0 where none), quantised to 8 bits: the previous
  /// frame's input of the importance allocation (RenderOptions::previousNearestCosine).
  virtual Result<std::vector<float>> nearestCosine(const PreparedView& view) = 0;

  /// prepare + render, for a single method.
  Result<RenderOutput> render(const View& view, const MethodDesc& method,
                              const RenderOptions& options);
};

/// Makes an engine; its errors are one line (e.g. no device).
using EngineFactory = Result<std::unique_ptr<Engine>> (*)(const EngineOptions& options);

/// Makes `name` known to makeEngine (libmfr_gl: mfr::gl::registerGlEngine() adds "gl"). A name
/// registered again keeps its first factory. Not thread-safe: register before making engines.
void registerEngine(const std::string& name, EngineFactory factory);

/// The names makeEngine accepts, in order ("cpu" first, then the registered ones).
std::vector<std::string> engineNames();

/// An engine by name. Errors (one line): an unknown name, listing the known ones; an engine that
/// cannot start on this machine.
Result<std::unique_ptr<Engine>> makeEngine(std::string_view name,
                                           const EngineOptions& options = {});

}  // namespace mfr
