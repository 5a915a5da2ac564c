// The CPU engine behind the Engine seam (mfr/cpu/cpu_engine.hpp).
#include "mfr/cpu/cpu_engine.hpp"

#include <thread>

#include "mfr/cpu/render.hpp"

namespace mfr {

Result<const RasterFrame*> cpuFrame(const PreparedView& view) {
  const auto* cpu = dynamic_cast<const CpuView*>(&view);
  if (!cpu) return makeError("engine cpu: the view was prepared by another engine");
  return &cpu->frame();
}

std::map<std::string, std::string> CpuEngine::describe() const {
  return {{"engine", "cpu"},
          {"threads", std::to_string(resolveThreads(options_.threads))},
          {"hardware_threads", std::to_string(std::thread::hardware_concurrency())},
          {"tile_size", std::to_string(options_.tileSize)}};
}

Result<void> CpuEngine::preflight(int width, int height, const MethodDesc& method,
                                  const RenderOptions& options) const {
  return checkPixelBuffers(width, height, method, options);
}

Result<std::unique_ptr<PreparedView>> CpuEngine::prepare(const View& view) {
  if (!view.scene) return makeError("engine cpu: a view without a scene");
  RasterOptions ro;
  ro.width = view.width;
  ro.height = view.height;
  ro.tileSize = options_.tileSize;
  ro.threads = options_.threads;
  auto frame = RasterFrame::build(*view.scene, view.camera, ro);
  if (!frame) return frame.error();
  return std::unique_ptr<PreparedView>(std::make_unique<CpuView>(std::move(frame.value())));
}

Result<RenderOutput> CpuEngine::render(const PreparedView& view, const MethodDesc& method,
                                       const RenderOptions& options) {
  auto frame = cpuFrame(view);
  if (!frame) return frame.error();
  RenderOptions reusing = options;
  if (!reusing.reuse) reusing.reuse = buffers_.get();
  auto out = mfr::render(**frame, method, reusing);
  if (out) {
    out->stats.engine = "cpu";
    out->stats.engineCounters["threads"] = (*frame)->threads();
    out->stats.engineCounters["tile_workers"] = (*frame)->arenaThreads();
  }
  return out;
}

Result<std::vector<uint32_t>> CpuEngine::countFragments(const PreparedView& view) {
  auto frame = cpuFrame(view);
  if (!frame) return frame.error();
  return mfr::countFragments(**frame);
}

Result<std::vector<float>> CpuEngine::nearestCosine(const PreparedView& view) {
  auto frame = cpuFrame(view);
  if (!frame) return frame.error();
  return mfr::nearestCosine(**frame);
}

}  // namespace mfr
