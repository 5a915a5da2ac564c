// The optimal k-buffer's pre-pass (DHOIT sec. 3.1.2): every pixel's fragments, sorted, and their
// error curves.
//
// The curves are built tile by tile: a count pass gives n(p); then each worker rasterizes one tile
// with full shading into a tile-local A-buffer (the tile's n(p) summed, nodes grouped by pixel),
// sorts each pixel's nodes and writes its curve. The nodes are exactly the A-buffer's (every
// fragment, the same shading, makeNode) and their sorted order does not depend on the arrival
// order, so the curves are those of a whole-frame A-buffer without its 8 bytes per fragment
// (twice, with the kept copy) ever existing at once: the pre-pass holds n(p), the curves and one
// tile's nodes per worker.
#include "mfr/cpu/optimal_oracle.hpp"

#include <algorithm>
#include <string>

#include <tbb/task_arena.h>

#include "mfr/core/memory_limit.hpp"
#include "mfr/cpu/fragment.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/optimal_allocation.hpp"

namespace mfr {

Result<FrameErrorCurves> frameErrorCurves(const RasterFrame& frame, glm::vec3 background,
                                          Compositing compositing,
                                          std::optional<uint64_t> memoryLimitBytes) {
  FrameErrorCurves out;
  out.n = countFragments(frame);
  for (uint32_t c : out.n) {
    out.coveredPixels += c > 0;
    out.fragments += c;
  }
  // memory pre-flight: n(p) and the curves (8 bytes per fragment, a vector per pixel)
  const uint64_t curveBytes =
      saturatingAdd(saturatingMul(out.fragments, sizeof(double)),
                    saturatingMul(frame.pixelCount(), sizeof(std::vector<double>)));
  MFR_TRY(checkMemory(saturatingAdd(curveBytes, out.n.capacity() * sizeof(uint32_t)),
                      memoryLimitBytes.value_or(defaultMemoryLimit()),
                      "the error curves of " + std::to_string(out.fragments) + " fragments at " +
                          std::to_string(frame.width()) + " x " + std::to_string(frame.height()) +
                          " pixels"));
  out.curves.resize(frame.pixelCount());
  const double inverseWidth = 1.0 / frame.width();
  frame.forEachTile([&](int tile) {
    const TileRect r = frame.tileRect(tile);
    const int w = r.x1 - r.x0 + 1, h = r.y1 - r.y0 + 1;
    // tile-local A-buffer: pixel i's nodes at first[i] .. first[i] + n
    std::vector<uint32_t> first(static_cast<size_t>(w) * h + 1, 0), filled(first.size() - 1, 0);
    for (int y = r.y0, i = 0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x, ++i)
        first[i + 1] = first[i] + out.n[static_cast<size_t>(y) * frame.width() + x];
    std::vector<FragmentNode> nodes(first.back());
    const uint32_t origin = static_cast<uint32_t>(r.y0) * frame.width() + r.x0;
    frame.rasterizeTile<ShadeMode::Full>(tile, EmitAll{[&](const Fragment& f) {
                                           // row and column in the tile without an integer
                                           // division: (d + 0.5) / width is exact enough
                                           const uint32_t d = f.pixel - origin;
                                           const uint32_t y =
                                               static_cast<uint32_t>((d + 0.5) * inverseWidth);
                                           const uint32_t i = y * w + (d - y * frame.width());
                                           nodes[first[i] + filled[i]++] = makeNode(f);
                                         }});
    for (int y = r.y0, i = 0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x, ++i) {
        const size_t p = static_cast<size_t>(y) * frame.width() + x;
        MFR_CHECK(filled[i] == out.n[p]);  // the count pass and the shaded pass agree
        FragmentNode* begin = nodes.data() + first[i];
        std::sort(begin, begin + filled[i]);
        out.curves[p] = errorCurve(begin, filled[i], background, compositing);
      }
  });
  out.bytesAllocated =
      out.n.capacity() * sizeof(uint32_t) + out.curves.capacity() * sizeof(std::vector<double>);
  for (const std::vector<double>& c : out.curves)
    out.bytesAllocated += c.capacity() * sizeof(double);
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
  // on the frame's workers, like its tile passes (the allocation is the same on any number)
  OracleAllocation a;
  tbb::task_arena(frame.arenaThreads()).execute([&] {
    a = allocateOptimal(oracle->curves, slots, oo);
  });
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
