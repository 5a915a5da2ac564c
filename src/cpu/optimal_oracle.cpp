// The optimal k-buffer's pre-pass (DHOIT sec. 3.1.2): exact A-buffer, sorted pixels, error curves.
#include "mfr/cpu/optimal_oracle.hpp"

#include <algorithm>
#include <string>

#include "mfr/core/memory_limit.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/optimal_allocation.hpp"

namespace mfr {

Result<FrameErrorCurves> frameErrorCurves(const RasterFrame& frame, glm::vec3 background,
                                          Compositing compositing,
                                          std::optional<uint64_t> memoryLimitBytes) {
  RenderOptions exact;
  exact.keepStores = true;
  exact.background = background;
  exact.memoryLimitBytes = memoryLimitBytes;  // the A-buffer checks its own buffers
  auto truth = render(frame, methodPreset("abuffer").value(), exact);
  if (!truth) return truth.error();
  {  // memory pre-flight of the curves (8 bytes per fragment, a vector per pixel) on top of the
     // A-buffer's output
    uint64_t fragments = 0;
    for (uint32_t c : truth->counts) fragments += c;
    const uint64_t held =
        truth->nodes.capacity() * sizeof(FragmentNode) +
        truth->offsets.capacity() * sizeof(uint64_t) +
        (truth->counts.capacity() + truth->kMap.capacity() + truth->depthComplexity.capacity()) *
            sizeof(uint32_t) +
        truth->image.pixels.capacity() * sizeof(glm::vec3);
    const uint64_t curves = saturatingAdd(saturatingMul(fragments, sizeof(double)),
                                          saturatingMul(frame.pixelCount(), 24 + 16));
    MFR_TRY(checkMemory(
        saturatingAdd(held, curves), memoryLimitBytes.value_or(defaultMemoryLimit()),
        "the error curves of " + std::to_string(fragments) + " fragments at " +
            std::to_string(frame.width()) + " x " + std::to_string(frame.height()) + " pixels"));
  }
  FrameErrorCurves out;
  out.curves.resize(frame.pixelCount());
  frame.forEachTile([&](int tile) {
    const TileRect r = frame.tileRect(tile);
    std::vector<FragmentNode> local;
    for (int y = r.y0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x) {
        const size_t p = static_cast<size_t>(y) * frame.width() + x;
        const FragmentNode* first = truth->nodes.data() + truth->offsets[p];
        local.assign(first, first + truth->counts[p]);
        std::sort(local.begin(), local.end());
        out.curves[p] = errorCurve(local.data(), truth->counts[p], background, compositing);
      }
  });
  out.bytesAllocated =
      truth->stats.bytesAllocated + truth->nodes.capacity() * sizeof(FragmentNode) +
      truth->offsets.capacity() * sizeof(uint64_t) + truth->counts.capacity() * sizeof(uint32_t) +
      out.curves.capacity() * sizeof(std::vector<double>);
  for (const std::vector<double>& c : out.curves)
    out.bytesAllocated += c.capacity() * sizeof(double);
  out.n = std::move(truth->depthComplexity);
  for (uint32_t c : out.n) {
    out.coveredPixels += c > 0;
    out.fragments += c;
  }
  return out;
}

Result<OracleChoice> optimalK(const RasterFrame& frame, const MethodDesc& method,
                              const RenderOptions& options, uint64_t slots) {
  auto oracle =
      frameErrorCurves(frame, options.background, method.compositing, options.memoryLimitBytes);
  if (!oracle) return makeError(method.name + ": the oracle's pre-pass: " + oracle.error().message);
  OracleChoice out;
  out.bytesAllocated = oracle->bytesAllocated;
  if (slots < oracle->coveredPixels) {
    out.n = std::move(oracle->n);
    return out;
  }
  OracleOptions oo;
  oo.publishedGreedy = method.publishedGreedy;
  OracleAllocation a = allocateOptimal(oracle->curves, slots, oo);
  OracleReport& r = out.report.emplace();
  r.error = a.error;
  r.lowerBound = a.lowerBound;
  r.lagrangianBound = a.lagrangianBound;
  r.exact = a.exact;
  r.solver = a.solver;
  r.nonconvexPixels = a.nonconvexPixels;
  r.corePixels = a.corePixels;
  out.n = std::move(oracle->n);
  out.k = std::move(a.k);
  return out;
}

}  // namespace mfr
