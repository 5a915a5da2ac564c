// dkb-curve: a learned allocation beyond the paper (issue 14 sec. 4). The deep k-buffer's network
// (DHOIT sec. 3.1.3) predicts one number per pixel, an importance; the optimal k-buffer
// (DHOIT sec. 3.1.2, optimal_allocation.hpp) instead allocates by each pixel's error-vs-k curve
// err_p(k) through the lower convex hull. Here the same 12 features (dkb_features.hpp) predict
// the curve itself and the hull allocator runs over the predicted curves.
//
// The curve's representation, 9 numbers in [0, 1] (the network's sigmoid outputs):
//   t_j = sqrt(d_j / S), j = 1..8, the marginal error reductions d_j = err(j) - err(j + 1)
//         (0 where j >= n(p): no fragment left to add);
//   t_9 = sqrt(err(9) / S), the tail: the error left with 8 core fragments (0 when n(p) <= 9),
//         spread linearly over k = 9..n(p) when the curve is rebuilt.
// S is a per-view scale, max_p err_p(1), so that t stays in [0, 1]: the hull allocation only
// compares drops between pixels of one image, so any per-image factor is free, as for the
// importance. The square root spreads the many small drops over the sigmoid's range.
// Rebuilt (curveFromPrediction): err(k) = sum_{j=k}^{min(8, n-1)} d_j + tail(k),
//   tail(k) = e9 for k <= 9 and e9 (n - k) / (n - 9) beyond, when n > 9; err(n) = 0.
// A pixel whose n(p) <= 9 is represented exactly.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace mfr {

inline constexpr int kCurveDrops = 8;
inline constexpr int kCurveOutputs = kCurveDrops + 1;

/// The network of dkb-curve: the paper's hidden layers, 9 outputs.
inline const std::vector<int> kDkbCurveLayers = {12, 128, 64, kCurveOutputs};

/// The target definition of dkb-curve's datasets and models (checked like kDkbTargetScaling).
inline constexpr const char* kDkbCurveTargetScaling =
    "sqrt(err(j) - err(j+1)) j=1..8, sqrt(err(9)), over max_p err_p(1) per view "
    "(include/mfr/method/dkb_curve.hpp)";

using CurveTargets = std::array<float, kCurveOutputs>;

/// The 9 targets of one pixel's curve err(k), k = 1..n (index k - 1; err(n) = 0), for the view's
/// scale S > 0; values clamped to [0, 1].
CurveTargets curveTargets(const std::vector<double>& curve, double scale);

/// The per-view scale S: max_p err_p(1) over non-empty curves, or 1 when every one is 0.
double curveScale(const std::vector<std::vector<double>>& curves);

/// err(k), k = 1..n, rebuilt from 9 predicted values (NaN or negative read as 0, above 1 as 1);
/// empty for n = 0.
std::vector<double> curveFromPrediction(const float* prediction, uint32_t n);

/// k(p) for `slots` = F(M) >= the covered pixels: the hull allocator (allocateOptimalHull) over
/// the curves rebuilt from `predictions` (9 per pixel, pixel-major) and n(p). 0 where n(p) = 0;
/// firstK <= k(p) <= n(p) elsewhere; sum k <= slots. `firstK` 0 (hybrid compositing, a pixel may
/// keep no slot; any slots then): the network predicts no err(0), so the curve is extended by its
/// first drop, err(0) = err(1) + (err(1) - err(2)) (0 drop when n(p) = 1, where the tail alone is
/// exact), a stand-in until a model predicts it.
std::vector<uint32_t> allocateByPredictedCurves(const std::vector<float>& predictions,
                                                const std::vector<uint32_t>& n, uint64_t slots,
                                                uint32_t firstK = 1);

}  // namespace mfr
