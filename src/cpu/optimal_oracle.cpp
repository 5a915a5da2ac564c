// The optimal k-buffer's pre-pass (DHOIT sec. 3.1.2): every pixel's fragments, sorted, and their
// error curves.
//
// The curves are built tile by tile, without a count pass: each worker rasterizes one tile with
// full shading (shaded_fragments.hpp: on 8 lanes with AVX2) into its scratch (local pixel, node) in
// arrival order, counts per pixel, groups the nodes by pixel (a counting sort, which keeps each
// pixel's arrival order), sorts each pixel's nodes and writes its curve and n(p). The nodes are
// exactly the A-buffer's (every fragment, the same shading, makeNode) and their sorted order does
// not depend on the arrival order, so the curves are those of a whole-frame A-buffer without its 8
// bytes per fragment (twice, with the kept copy) ever existing at once: the pre-pass holds n(p),
// the curves and one tile's nodes per worker.
//
// Memory: n(p) and the curves (8 bytes per fragment, a vector per pixel) are checked against the
// limit as the tiles add their fragments, before each tile's curves are allocated. Once the sum
// exceeds it, the remaining tiles only count their fragments (coverage), so the error names the
// frame's whole fragment count, as a count pass up front would (and costs no more than one).
#include "mfr/cpu/optimal_oracle.hpp"

#include <algorithm>
#include <atomic>
#include <string>

#include <tbb/task_arena.h>

#include "mfr/core/memory_limit.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/fragment.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "shaded_fragments.hpp"

namespace mfr {

Result<FrameErrorCurves> frameErrorCurves(const RasterFrame& frame, glm::vec3 background,
                                          Compositing compositing,
                                          std::optional<uint64_t> memoryLimitBytes,
                                          uint32_t firstK) {
  const uint64_t limit = memoryLimitBytes.value_or(defaultMemoryLimit());
  const uint64_t pixels = frame.pixelCount();
  // n(p) and the curves of `fragments` fragments (8 bytes each, a vector per pixel, and err(0)
  // per pixel when the curves start at k = 0)
  const uint64_t perPixel =
      sizeof(std::vector<double>) + sizeof(uint32_t) + (firstK == 0 ? sizeof(double) : 0);
  const auto needed = [&](uint64_t fragments) {
    // beside the scene's bytes, as the render's own pre-flight counts them
    return saturatingAdd(
        saturatingAdd(saturatingMul(fragments, sizeof(double)), saturatingMul(pixels, perPixel)),
        frame.sceneBytes());
  };
  const auto check = [&](uint64_t fragments) {
    return checkMemory(needed(fragments), limit,
                       "the error curves of " + std::to_string(fragments) + " fragments at " +
                           std::to_string(frame.width()) + " x " + std::to_string(frame.height()) +
                           " pixels and the scene's " + formatBytes(frame.sceneBytes()));
  };
  // fragments per tile; kUncounted until a tile is rasterized or counted
  constexpr uint64_t kUncounted = UINT64_MAX;
  std::vector<uint64_t> tileFragments(static_cast<size_t>(frame.tileCount()), kUncounted);
  // the error, with the frame's whole fragment count (coverage-only for the uncounted tiles)
  const auto overLimit = [&] {
    frame.forEachTile([&](int tile) {
      if (tileFragments[tile] != kUncounted) return;
      uint64_t count = 0;
      frame.rasterizeTile<ShadeMode::Coverage>(tile,
                                               CoverageAll{[&](uint32_t, float) { ++count; }});
      tileFragments[tile] = count;
    });
    uint64_t total = 0;
    for (uint64_t c : tileFragments) total += c;
    return check(total).error();
  };
  if (needed(0) > limit) return overLimit();

  FrameErrorCurves out;
  out.firstK = firstK;
  out.n.assign(pixels, 0);
  out.curves.resize(pixels);
  std::atomic<uint64_t> fragments{0};
  std::atomic<bool> over{false};
  const double inverseWidth = 1.0 / frame.width();
  frame.forEachTile([&](int tile) {
    if (over.load(std::memory_order_relaxed)) return;
    const TileRect r = frame.tileRect(tile);
    const int w = r.x1 - r.x0 + 1, h = r.y1 - r.y0 + 1;
    const uint32_t origin = static_cast<uint32_t>(r.y0) * frame.width() + r.x0;
    // the tile's fragments in arrival order (local pixel, node), then grouped by pixel in
    // `nodes` (the worker's scratch, reused from tile to tile)
    thread_local std::vector<uint32_t> local, first;
    thread_local std::vector<FragmentNode> arrived, nodes;
    local.clear();
    arrived.clear();
    detail::forEachShadedFragment(frame, tile, [&](const Fragment& f) {
      // row and column in the tile without an integer division: (d + 0.5) / width is exact
      // enough
      const uint32_t d = f.pixel - origin;
      const uint32_t y = static_cast<uint32_t>((d + 0.5) * inverseWidth);
      local.push_back(y * w + (d - y * frame.width()));
      arrived.push_back(makeNode(f));
    });
    tileFragments[tile] = arrived.size();
    const uint64_t sum = fragments.fetch_add(arrived.size()) + arrived.size();
    if (needed(sum) > limit) {
      over.store(true);
      return;
    }
    // counting sort: first[i] = the start of pixel i's nodes, then, after the scatter, their end
    first.assign(static_cast<size_t>(w) * h + 1, 0);
    for (uint32_t i : local) ++first[i + 1];
    for (size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
    nodes.resize(arrived.size());
    for (size_t j = 0; j < arrived.size(); ++j) nodes[first[local[j]]++] = arrived[j];
    for (int y = r.y0, i = 0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x, ++i) {
        const size_t p = static_cast<size_t>(y) * frame.width() + x;
        const uint32_t begin = i == 0 ? 0 : first[i - 1], n = first[i] - begin;
        FragmentNode* px = nodes.data() + begin;
        std::sort(px, px + n);
        out.n[p] = n;
        out.curves[p] = errorCurve(px, n, background, compositing, firstK);
      }
  });
  if (over) {
    out = FrameErrorCurves{};  // free the curves before counting the rest
    return overLimit();
  }
  for (uint32_t c : out.n) {
    out.coveredPixels += c > 0;
    out.fragments += c;
  }
  out.bytesAllocated =
      out.n.capacity() * sizeof(uint32_t) + out.curves.capacity() * sizeof(std::vector<double>);
  for (const std::vector<double>& c : out.curves)
    out.bytesAllocated += c.capacity() * sizeof(double);
  return out;
}

Result<OracleChoice> optimalK(const RasterFrame& frame, const MethodDesc& method,
                              const RenderOptions& options, uint64_t slots) {
  // under hybrid compositing a pixel may keep no slot: the curves start at its tail alone
  const uint32_t firstK = allowsTailOnlyPixels(method) ? 0 : 1;
  auto oracle = frameErrorCurves(frame, options.background, method.compositing,
                                 options.memoryLimitBytes, firstK);
  if (!oracle) return makeError(method.name + ": the oracle's pre-pass: " + oracle.error().message);
  OracleChoice out;
  out.bytesAllocated = oracle->bytesAllocated;
  if (firstK == 1 && slots < oracle->coveredPixels) {
    out.n = std::move(oracle->n);
    return out;
  }
  OracleOptions oo;
  oo.publishedGreedy = method.publishedGreedy;
  oo.firstK = firstK;
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
