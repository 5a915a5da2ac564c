// The CPU engine behind the Engine seam (mfr/cpu/cpu_engine.hpp).
#include "mfr/cpu/cpu_engine.hpp"

#include <algorithm>
#include <thread>

#include "mfr/cpu/render.hpp"
#include "mfr/method/pass_plan.hpp"

namespace mfr {

Result<const RasterFrame*> CpuView::frame(SampleStorage storage) const {
  if (frame_.samples() == 1 || storage == SampleStorage::Pixel) return &frame_;
  const std::lock_guard lock(mutex_);
  if (!sampleFrame_) {
    RasterOptions o = options_;
    o.storage = SampleStorage::Sample;
    auto built = RasterFrame::build(*scene_, frame_.camera(), o);
    if (!built) return built.error();
    sampleFrame_ = std::make_unique<RasterFrame>(std::move(built.value()));
  }
  return sampleFrame_.get();
}

const std::vector<uint8_t>& CpuView::edgePixels() const {
  const std::lock_guard lock(mutex_);
  if (edges_.empty()) {
    edges_.assign(frame_.pixelCount(), 0);
    const int samples = frame_.samples();
    const uint32_t full = (1u << samples) - 1u;
    frame_.forEachTile([&](int tile) {  // a tile's pixels are its worker's
      frame_.rasterizeTile<ShadeMode::Coverage>(tile, CoverageAll{[&](uint32_t p, float depth) {
                                                  if (coverageOf(depth, samples) != full)
                                                    edges_[p] = 1;
                                                }});
    });
  }
  return edges_;
}

const std::vector<uint32_t>& CpuView::fragmentCounts(const RasterFrame& frame) const {
  const std::lock_guard lock(mutex_);
  std::vector<uint32_t>& counts = &frame == &frame_ ? pixelCounts_ : sampleCounts_;
  if (counts.empty()) counts = countFragments(frame);
  return counts;
}

namespace {

// The view a CPU engine's call receives, or the error naming the engine.
Result<const CpuView*> cpuView(const PreparedView& view) {
  const auto* cpu = dynamic_cast<const CpuView*>(&view);
  if (!cpu) return makeError("engine cpu: the view was prepared by another engine");
  return cpu;
}

// Multisampled renders: edgeStatistics from n(p) and the nodes per storage pixel
// (RenderOutput::counts, which render() leaves for a multisampled frame).
void edgeStatistics(const CpuView& view, const RasterFrame& frame, RenderOutput& out) {
  const std::vector<uint32_t>& n = out.depthComplexity.size() == frame.pixelCount()
                                       ? out.depthComplexity
                                       : view.fragmentCounts(frame);
  mfr::edgeStatistics(n, out.counts, view.edgePixels(), frame.storagePerPixel(), out);
}

}  // namespace

Result<const RasterFrame*> cpuFrame(const PreparedView& view) {
  auto cpu = cpuView(view);
  if (!cpu) return cpu.error();
  return &(*cpu)->frame();
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
  ro.samples = view.samples;
  auto frame = RasterFrame::build(*view.scene, view.camera, ro);
  if (!frame) return frame.error();
  return std::unique_ptr<PreparedView>(
      std::make_unique<CpuView>(std::move(frame.value()), *view.scene, ro));
}

Result<RenderOutput> CpuEngine::render(const PreparedView& view, const MethodDesc& method,
                                       const RenderOptions& options) {
  auto viewed = cpuView(view);
  if (!viewed) return viewed.error();
  const CpuView* cpu = *viewed;
  const int samples = cpu->samples();
  auto frame = cpu->frame(sampleStorageOf(method, options));
  if (!frame) return frame.error();
  const int per = (*frame)->storagePerPixel();
  RenderOptions reusing = options;
  if (!reusing.reuse) reusing.reuse = buffers_.get();
  std::vector<float> cosine;  // per-sample storage: the previous frame's |n.v| for each sample
  if (per > 1 && options.previousNearestCosine) {
    cosine.reserve(options.previousNearestCosine->size() * per);
    for (float c : *options.previousNearestCosine) cosine.insert(cosine.end(), per, c);
    reusing.previousNearestCosine = &cosine;
  }
  auto out = mfr::render(**frame, method, reusing);
  if (out) {
    out->stats.engine = "cpu";
    out->stats.engineCounters["threads"] = (*frame)->threads();
    out->stats.engineCounters["tile_workers"] = (*frame)->arenaThreads();
    if (samples > 1) {
      edgeStatistics(*cpu, **frame, *out);
      if (!options.keepStores) out->counts.clear();
    }
    if (per > 1) toImagePixels(*out, per);
  }
  return out;
}

Result<std::vector<uint32_t>> CpuEngine::countFragments(const PreparedView& view) {
  auto cpu = cpuView(view);
  if (!cpu) return cpu.error();
  if ((*cpu)->samples() == 1) return mfr::countFragments((*cpu)->frame());
  // multisampled: the fragments of the pixel's samples (the per-sample A-buffer's nodes)
  auto frame = (*cpu)->frame(SampleStorage::Sample);
  if (!frame) return frame.error();
  RenderOutput counted;
  counted.depthComplexity = (*cpu)->fragmentCounts(**frame);
  toImagePixels(counted, (*cpu)->samples());
  return std::move(counted.depthComplexity);
}

Result<std::vector<uint32_t>> CpuEngine::storageFragmentCounts(const PreparedView& view,
                                                               SampleStorage storage) {
  auto cpu = cpuView(view);
  if (!cpu) return cpu.error();
  auto frame = (*cpu)->frame(storage);
  if (!frame) return frame.error();
  return (*cpu)->fragmentCounts(**frame);
}

Result<std::vector<float>> CpuEngine::nearestCosine(const PreparedView& view) {
  auto frame = cpuFrame(view);
  if (!frame) return frame.error();
  return mfr::nearestCosine(**frame);
}

}  // namespace mfr
