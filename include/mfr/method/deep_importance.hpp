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
#include "mfr/method/dkb_features.hpp"
#include "mfr/raster/raster_frame.hpp"

namespace mfr {

namespace learn {
struct Model;
}

/// The count pass of the deep k-buffer: n(p), and the image statistics (sum n, covered pixels,
/// depth range) in `image`.
std::vector<uint32_t> countWithDepthRange(const RasterFrame& frame, ImageFeatureStats& image);

/// I(p) for every pixel (0 where n(p) = 0); `slots` = F(M). `featureMs` and `inferenceMs` receive
/// the time spent in each part, summed over workers (CPU time, not wall time).
std::vector<float> predictImportance(const RasterFrame& frame, const learn::Model& model,
                                     const ImageFeatureStats& image, uint64_t slots,
                                     double* featureMs = nullptr, double* inferenceMs = nullptr);

/// Checks that a model fits the deep k-buffer: 12 inputs, 1 output, metadata declaring the feature
/// set kDkbFeatureSet ("features") and, if it declares a target ("target"), the target definition
/// learn::kDkbTargetScaling. `name` names the model in the message.
Result<void> checkDkbModel(const learn::Model& model, const std::string& name);

/// The model shipped in the repository (models/dkb-default.mfrnn, compiled into the library),
/// decoded once. An error when the build had no model file, or when the model does not declare
/// both kDkbFeatureSet and learn::kDkbTargetScaling (stale against the code: retrain it).
Result<std::shared_ptr<const learn::Model>> builtinDkbModel();

}  // namespace mfr
