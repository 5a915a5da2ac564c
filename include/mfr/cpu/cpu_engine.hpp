// The CPU engine behind the Engine seam: prepare() builds a RasterFrame (mfr/cpu/raster_frame.hpp),
// render() runs the CPU passes (mfr/cpu/render.hpp) on it. The exact reference of every method.
#pragma once

#include <memory>

#include "mfr/cpu/frame_buffers.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/engine/engine.hpp"

namespace mfr {

/// A view prepared by the CPU engine: the frame the tile passes run on.
class CpuView final : public PreparedView {
 public:
  explicit CpuView(RasterFrame frame) : frame_(std::move(frame)) {}
  int width() const override { return frame_.width(); }
  int height() const override { return frame_.height(); }
  const RasterFrame& frame() const { return frame_; }

 private:
  RasterFrame frame_;
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
