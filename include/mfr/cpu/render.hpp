// The CPU engine's render of one rasterized frame with one method: count -> allocate ->
// [occupancy] -> capture -> resolve, with exact memory accounting and per-pass statistics. The
// options and outputs are the engines' common ones (mfr/method/render_output.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/render_output.hpp"

namespace mfr {

/// Renders one frame with one method: the passes of the method's description (count, importance
/// or oracle, allocate, [occupancy], capture, resolve) on the frame's worker threads. The output is
/// byte-identical for any thread count (tile-owned capture; see docs/ARCHITECTURE.md).
///
/// Errors (one line, the caller adds the scene's name): a bounded method without a budget or k;
/// a budget too small for the method's per-pixel words and one fragment per (covered) pixel, for
/// an explicit k, or (abuffer with a budget) for every fragment; a deep k-buffer model that does
/// not fit (checkDkbModel) or a missing built-in model; an inconsistent hand-made description
/// (e.g. occupancy culling without a bounded k); buffers larger than options.memoryLimitBytes, or
/// an allocation that fails anyway (named by its pass; std::bad_alloc never escapes). A
/// previousNearestCosine of another size than the frame is ignored (as if absent).
///
/// Lifetimes: `frame` (and so its Scene) and `options.previousNearestCosine` are only read during
/// the call; the RenderOutput owns all its data. Neither the frame nor the method is modified, so
/// one frame can be rendered with many methods in turn.
Result<RenderOutput> render(const RasterFrame& frame, const MethodDesc& method,
                            const RenderOptions& options);

/// The memory pre-flight that the image size alone decides: the per-pixel buffers `method` needs
/// at width x height (with options.capture's locks) against options.memoryLimitBytes (default
/// defaultMemoryLimit()). render() checks it before its first pass; callers check it before
/// building the frame (RasterFrame::build takes seconds at 16384 x 16384), so that a run that
/// cannot fit fails at once. A size outside [1, kMaxImageSize] passes (RasterFrame::build names
/// it).
Result<void> checkPixelBuffers(int width, int height, const MethodDesc& method,
                               const RenderOptions& options);

/// Per-pixel fragment counts n(p) (a Coverage count pass), rows top to bottom; what
/// RenderOutput::depthComplexity holds when the method counts.
std::vector<uint32_t> countFragments(const RasterFrame& frame);

/// |n.v| of each pixel's nearest fragment (0 where none), quantised to 8 bits.
std::vector<float> nearestCosine(const RasterFrame& frame);

}  // namespace mfr
