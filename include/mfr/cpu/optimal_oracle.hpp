// The optimal k-buffer's pre-pass over a frame (DHOIT sec. 3.1.2): an exact A-buffer, each pixel's
// fragments sorted, and its hybrid error curve err_p(k) (optimal_allocation.hpp). The A-buffer is
// tile-local (each worker rasterizes one tile's fragments, groups them by pixel and sorts them;
// no count pass), so only n(p) and the curves exist for the whole frame. The curves do not depend
// on the budget, so one pre-pass serves any number of budgets (mfr dataset).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/result.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/render_output.hpp"

namespace mfr {

struct FrameErrorCurves {
  std::vector<std::vector<double>> curves;  // per pixel, err(k) for k = firstK..n(p)
  uint32_t firstK = 1;      // 0: from the tail alone (hybrid compositing, allowsTailOnlyPixels)
  std::vector<uint32_t> n;  // n(p)
  uint64_t coveredPixels = 0;
  uint64_t fragments = 0;  // sum n(p)
  /// Bytes the pre-pass allocated for the whole frame: n(p) and the curves.
  uint64_t bytesAllocated = 0;
};

/// `compositing`: the rule whose error the curves measure (the optimal k-buffer of DHOIT: hybrid).
/// `memoryLimitBytes` (none: defaultMemoryLimit()): the A-buffer's and the curves' bytes are
/// checked against it before they are allocated (RenderOptions::memoryLimitBytes). `firstK`: the
/// curves' first k (errorCurve), 0 for curves from the tail alone.
Result<FrameErrorCurves> frameErrorCurves(const RasterFrame& frame, glm::vec3 background,
                                          Compositing compositing = Compositing::Hybrid,
                                          std::optional<uint64_t> memoryLimitBytes = std::nullopt,
                                          uint32_t firstK = 1);

/// The optimal k-buffer's pre-pass and allocation, as both engines run it: n(p) and the oracle's
/// k(p) with its bound over the error curves of the method's compositing rule, for `slots` = F(M)
/// node slots (no k when the budget cannot give every covered pixel a slot and the rule needs one:
/// allocate() reports that; under hybrid compositing the curves start at k = 0, the tail alone,
/// and any slots work). The GL engine takes its k(p) from here too (the oracle is a CPU pass).
struct OracleChoice {
  std::vector<uint32_t> n, k;
  std::optional<OracleReport> report;
  uint64_t bytesAllocated = 0;  // the pre-pass (A-buffer, error curves)
};

Result<OracleChoice> optimalK(const RasterFrame& frame, const MethodDesc& method,
                              const RenderOptions& options, uint64_t slots);

}  // namespace mfr
