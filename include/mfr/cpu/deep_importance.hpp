// The deep k-buffer's importance pass (Tsopouridis, Vasilakis, Fudos, "Deep hybrid
// order-independent transparency", sec. 3.2, Fig. 5): a feature pass and the network's
// prediction I(p) per covered pixel, which the importance allocation turns into
// k(p) = floor(F(M) I(p) / sum I) (Eq. 3).
//
// The CPU engine fuses feature extraction and inference per 16x16 tile: a worker accumulates the
// features of its tile in a 256-pixel scratch (the analogue of GPU shared memory, independent of
// the image size), predicts the importance of the tile's covered pixels as one batch (so the
// result does not depend on the thread count), and writes I(p) into the pixel's offset word
// (where the allocation then computes k(p) and the prefix sum in place). So no full-screen
// feature buffer exists and the method's per-pixel memory is that of the variable k-buffer
// without the previous-frame normal. The image-level features (sum n, depth range) come from the
// count pass before it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/method/dkb_features.hpp"
#include "mfr/method/dkb_model.hpp"

namespace mfr {

namespace learn {
struct Model;
}

/// The count pass of the deep k-buffer: n(p), and the image statistics (sum n, covered pixels,
/// depth range) in `image`.
std::vector<uint32_t> countWithDepthRange(const RasterFrame& frame, ImageFeatureStats& image);

/// I(p) for every pixel (0 where n(p) = 0); `slots` = F(M). `featureMs` and `inferenceMs` receive
/// the time spent in each part, summed over workers (CPU time): the statistics split the fused
/// pass's wall time between "features" and "inference" in proportion to them. The network runs
/// on activeIsa()'s path (learn/mlp.hpp).
std::vector<float> predictImportance(const RasterFrame& frame, const learn::Model& model,
                                     const ImageFeatureStats& image, uint64_t slots,
                                     double* featureMs = nullptr, double* inferenceMs = nullptr);

/// The whole-frame feature pass (tile-parallel, deterministic): one accumulator per pixel, with
/// dkb-curve's hybrid inputs (FeatureAccumulator::addWithCurveInputs).
std::vector<FeatureAccumulator> accumulateFeatures(const RasterFrame& frame);

}  // namespace mfr
