// Every shaded fragment of one tile, for the passes that take them all (the deep k-buffer's
// feature pass, the optimal oracle's A-buffer pre-pass, the previous-frame cosines): on the
// capture's 8-lane kernel (raster_span_avx2.hpp) where activeIsa() has AVX2, else the scalar
// rasterizeTile<ShadeMode::Full>. Both give the same fragments bit for bit and each pixel's
// fragments in the same (primitive) order; only the interleaving of different pixels of the tile
// differs, so a pass that keeps per-pixel state gets the same result on either path.
#pragma once

#include <cstdint>
#include <vector>

#include "mfr/core/isa.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "raster_span_avx2.hpp"

namespace mfr::detail {

#if MFR_HAS_AVX2_KERNELS
/// The lane protocol of rasterizeTileAvx2 for a pass without early tests: every cull depth is
/// INT32_MAX (every depth passes), every fragment goes to fn.
template <class Fn>
struct LaneEmitAll {
  static constexpr bool kCullsInLanes = false;
  Fn& fn;
  std::vector<int32_t>& noCull;  // one row of INT32_MAX, shared by every row

  void beginTile(const TileRect&, int tileSize) { noCull.assign(tileSize, INT32_MAX); }
  int32_t* cullDepthRow(int) { return noCull.data(); }
  void countEarly(uint32_t, uint32_t) {}
  [[gnu::always_inline]] void emitLane(const Fragment& f, int32_t*) { fn(f); }
  bool accept(uint32_t, float) const { return true; }
  void emit(const Fragment& f) { fn(f); }
};
#endif

/// fn(fragment) for every fragment of `tile`, shaded (see the file comment).
template <class Fn>
void forEachShadedFragment(const RasterFrame& frame, int tile, Fn&& fn) {
#if MFR_HAS_AVX2_KERNELS
  if (activeIsa() >= Isa::Avx2 && frame.samples() == 1) {  // the lanes test pixel centres only
    if (frame.tileBegin(tile) == frame.tileEnd(tile)) return;
    thread_local std::vector<int32_t> noCull;  // reused by the worker's tiles
    LaneEmitAll<Fn> sink{fn, noCull};
    rasterizeTileAvx2(frame, frame.shadingInputs(), tile, sink);
    return;
  }
#endif
  frame.rasterizeTile<ShadeMode::Full>(tile, EmitAll{fn});
}

}  // namespace mfr::detail
