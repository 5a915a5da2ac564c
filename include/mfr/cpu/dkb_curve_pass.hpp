// dkb-curve's passes over a frame (issue 14 sec. 4, mfr/method/dkb_curve.hpp): the deep
// k-buffer's feature pass (DHOIT sec. 3.2), the curve network over the covered pixels (one batch
// per fixed-size chunk: the result does not depend on the thread count) and the hull allocation
// over the predicted curves. A CPU pass, like the optimal oracle: the GL engine runs it on its
// view's CPU frame and renders with the k(p) it returns.
#pragma once

#include <cstdint>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

struct CurveChoice {
  std::vector<uint32_t> n, k;   // n(p) and the allocation, sum k <= slots
  uint64_t bytesAllocated = 0;  // features, predictions and curves held at once
};

/// n(p) and k(p) of dkb-curve for `slots` = F(M), with the method's model (dkbModelFor). Errors:
/// the model's (missing, stale, other rule), or fewer slots than covered pixels (no k then; the
/// allocation reports it: k is empty).
Result<CurveChoice> predictedCurveK(const RasterFrame& frame, const MethodDesc& method,
                                    uint64_t slots);

}  // namespace mfr
