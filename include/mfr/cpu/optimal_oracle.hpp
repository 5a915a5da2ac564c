// The optimal k-buffer's pre-pass over a frame (DHOIT sec. 3.1.2): an exact A-buffer, each pixel's
// fragments sorted, and its hybrid error curve err_p(k) (optimal_allocation.hpp). The curves do
// not depend on the budget, so one pre-pass serves any number of budgets (mfr dataset).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/result.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

struct FrameErrorCurves {
  std::vector<std::vector<double>> curves;  // per pixel, err(k) for k = 1..n(p)
  std::vector<uint32_t> n;                  // n(p)
  uint64_t coveredPixels = 0;
  uint64_t fragments = 0;  // sum n(p)
  /// Bytes the pre-pass allocated: the A-buffer's buffers, its kept nodes and the curves.
  uint64_t bytesAllocated = 0;
};

/// `compositing`: the rule whose error the curves measure (the optimal k-buffer of DHOIT: hybrid).
/// `memoryLimitBytes` (none: defaultMemoryLimit()): the A-buffer's and the curves' bytes are
/// checked against it before they are allocated (RenderOptions::memoryLimitBytes).
Result<FrameErrorCurves> frameErrorCurves(const RasterFrame& frame, glm::vec3 background,
                                          Compositing compositing = Compositing::Hybrid,
                                          std::optional<uint64_t> memoryLimitBytes = std::nullopt);

}  // namespace mfr
