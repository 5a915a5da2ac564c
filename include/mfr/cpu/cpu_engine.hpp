// The CPU engine behind the Engine seam: prepare() builds a RasterFrame (mfr/cpu/raster_frame.hpp),
// render() runs the CPU passes (mfr/cpu/render.hpp) on it. The exact reference of every method.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "mfr/cpu/frame_buffers.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/engine/engine.hpp"

namespace mfr {

/// A view prepared by the CPU engine: the frame the tile passes run on. A multisampled view
/// (View::samples > 1) holds the per-pixel storage frame and builds its per-sample storage frame
/// (RasterOptions::storage) on first use, from the scene the view refers to.
class CpuView final : public PreparedView {
 public:
  explicit CpuView(RasterFrame frame) : frame_(std::move(frame)) {}
  CpuView(RasterFrame frame, const Scene& scene, const RasterOptions& options)
      : frame_(std::move(frame)), scene_(&scene), options_(options) {}
  int width() const override { return frame_.imageWidth(); }
  int height() const override { return frame_.height(); }
  int samples() const override { return frame_.samples(); }
  /// The per-pixel storage frame (the only one with one sample).
  const RasterFrame& frame() const { return frame_; }
  /// The frame of a storage discipline (built once, on first use).
  Result<const RasterFrame*> frame(SampleStorage storage) const;
  /// Multisampled views: 1 where an edge crosses the image pixel (some fragment covers part of
  /// its samples), else 0 (built once, on first use).
  const std::vector<uint8_t>& edgePixels() const;
  /// n(p) of each storage pixel of `frame` (this view's frame of that discipline), counted once:
  /// a multisampled render's edge statistics and every countFragments of the view read it.
  const std::vector<uint32_t>& fragmentCounts(const RasterFrame& frame) const;

 private:
  RasterFrame frame_;
  const Scene* scene_ = nullptr;
  RasterOptions options_;
  mutable std::mutex mutex_;
  mutable std::unique_ptr<RasterFrame> sampleFrame_;
  mutable std::vector<uint8_t> edges_;
  mutable std::vector<uint32_t> pixelCounts_, sampleCounts_;  // fragmentCounts, per discipline
};

class CpuEngine final : public Engine {
 public:
  explicit CpuEngine(const EngineOptions& options = {}) : options_(options) {}
  std::string_view name() const override { return "cpu"; }
  std::map<std::string, std::string> describe() const override;
  Result<void> preflight(int width, int height, const MethodDesc& method,
                         const RenderOptions& options) const override;
  Result<std::unique_ptr<PreparedView>> prepare(const View& view) override;
  using Engine::render;
  Result<RenderOutput> render(const PreparedView& view, const MethodDesc& method,
                              const RenderOptions& options) override;
  Result<std::vector<uint32_t>> countFragments(const PreparedView& view) override;
  Result<std::vector<uint32_t>> storageFragmentCounts(const PreparedView& view,
                                                      SampleStorage storage) override;
  Result<std::vector<float>> nearestCosine(const PreparedView& view) override;
  /// Frees the buffers kept from the last render (frame_buffers.hpp: its node pool and per-pixel
  /// stores, held until the next render or the engine's end).
  void releaseBuffers() { buffers_->release(); }

 private:
  EngineOptions options_;
  /// Kept from one render to the next (frame_buffers.hpp), unless the caller passes its own.
  std::unique_ptr<FrameBuffers> buffers_ = std::make_unique<FrameBuffers>();
};

/// The CPU frame of a view prepared by the CPU engine; an error naming the engine otherwise.
Result<const RasterFrame*> cpuFrame(const PreparedView& view);

}  // namespace mfr
