// dkb-curve: a learned allocation beyond the paper (issue 14 sec. 4). The deep k-buffer's network
// (DHOIT sec. 3.1.3) predicts one number per pixel, an importance; the optimal k-buffer
// (DHOIT sec. 3.1.2, optimal_allocation.hpp) instead allocates by each pixel's error-vs-k curve
// err_p(k) through the lower convex hull. Here the same 12 features (dkb_features.hpp) predict
// the curve itself and the hull allocator runs over the predicted curves.
//
// The curve's representation, 9 numbers in [0, 1] (the network's sigmoid outputs), over the
// curve from its first k, k0: 1 under kbuffer compositing, where every covered pixel keeps a slot,
// and 0 under hybrid compositing, where err(0) is the pixel's tail alone (issue 28):
//   t_j, j = 0..7, the marginal error reductions d_j = err(k0 + j) - err(k0 + j + 1) (0 where
//         k0 + j >= n(p): no fragment left to add; negative drops read as 0);
//   t_8, the tail: err(k0 + 8), the error left with k0 + 8 core fragments (0 when
//         n(p) <= k0 + 8), spread linearly down to the curve's last drop when rebuilt.
// The scale of a value v:
//   k0 = 1: t = sqrt(v / S), S a per-view scale, max_p err_p(1), so that t stays in [0, 1]: the
//         hull allocation only compares drops between pixels of one image, so any per-image factor
//         is free, as for the importance; the square root spreads the small drops.
//   k0 = 0: t = 1 + log10(v / 3) / 16 clamped to [0, 1] (0 for v <= 0): absolute, 16 decades below
//         the largest squared linear-RGB error, 3. A per-view S is a statistic of the whole image
//         the network cannot see (one bright pixel rescales every target), and the allocation at
//         a large budget ranks drops many decades below the largest, which a square root squeezes
//         into the sigmoid's first percent (measured in issue 28's note).
// Rebuilt (curveFromPrediction), from k0 to the last k whose error is not 0 by construction, kl:
// kl = n under kbuffer compositing (err(n) = 0), and kl = n - 1 under hybrid compositing (a tail
// of one fragment is exact, so err(n - 1) = err(n) = 0 and the last drop is never predicted).
// With m = k0 + 8: err(k) = sum_{j=k-k0}^{min(7, kl-1-k0)} d_j + tail(k), tail(k) = e_m for
// k <= m and e_m (kl - k) / (kl - m) beyond, when kl > m. A pixel whose n(p) <= 9 is represented
// exactly.
//
// The hybrid model (models/dkb-curve.mfrnn) also has its own inputs (curvePixelFeatures,
// dkb_features.hpp); the kbuffer model keeps the deep k-buffer's. The two definitions are two
// target strings and two feature sets (dkbCurveTarget, dkbCurveFeatureSet), checked in datasets
// and models like kDkbTargetScaling.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mfr/method/dkb_features.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

inline constexpr int kCurveDrops = 8;
inline constexpr int kCurveOutputs = kCurveDrops + 1;

/// The network of dkb-curve: the paper's hidden layers, 9 outputs.
inline const std::vector<int> kDkbCurveLayers = {12, 128, 64, kCurveOutputs};

/// The target definitions of dkb-curve's datasets and models (checked like kDkbTargetScaling):
/// curves from k = 1 (kbuffer compositing) and from k = 0, the tail alone (hybrid compositing).
inline constexpr const char* kDkbCurveTargetScaling =
    "sqrt(err(j) - err(j+1)) j=1..8, sqrt(err(9)), over max_p err_p(1) per view "
    "(include/mfr/method/dkb_curve.hpp)";
inline constexpr const char* kDkbCurveTailOnlyTargetScaling =
    "1 + log10(v / 3) / 16 of v = err(j) - err(j+1) j=0..7 and err(8), err(0) the tail alone, "
    "err(n-1) = 0 (include/mfr/method/dkb_curve.hpp)";

/// The log scale of curves from k = 0: values from 3 (the largest squared linear-RGB error) down
/// 16 decades map to [1, 0]. kDkbCurveTailOnlyTargetScaling names both numbers: change it with
/// them.
inline constexpr double kCurveLogTop = 3.0;
inline constexpr double kCurveLogDecades = 16.0;

/// A value v >= 0 on that scale: 1 + log10(v / 3) / decades, clamped to [0, 1] (0 for v <= 0).
float curveLogUnit(double value);

/// The first k of `rule`'s curves: 0 under hybrid compositing (a pixel may keep no slot), else 1.
constexpr uint32_t curveFirstK(Compositing rule) {
  return rule == Compositing::Hybrid ? 0 : 1;
}

/// The target definition of `rule`'s curve datasets and models.
constexpr const char* dkbCurveTarget(Compositing rule) {
  return curveFirstK(rule) == 0 ? kDkbCurveTailOnlyTargetScaling : kDkbCurveTargetScaling;
}

/// The feature set of `rule`'s curve datasets and models (dkb_features.hpp).
constexpr const char* dkbCurveFeatureSet(Compositing rule) {
  return curveFirstK(rule) == 0 ? kDkbCurveFeatureSet : kDkbFeatureSet;
}

using CurveTargets = std::array<float, kCurveOutputs>;

/// The 9 targets of one pixel's curve, its values from k0 = `firstK` (curve[i] = err(k0 + i), the
/// last err(n) = 0), for the view's scale S > 0 (used from k0 = 1); values in [0, 1].
CurveTargets curveTargets(const std::vector<double>& curve, double scale, uint32_t firstK = 1);

/// The per-view scale S of curves from k = 1: max_p err_p(1) over non-empty curves, or 1 when
/// every one is 0.
double curveScale(const std::vector<std::vector<double>>& curves);

/// err(k), k = firstK..n (index k - firstK), rebuilt from 9 predicted values (NaN or negative
/// read as 0, above 1 as 1); empty for n = 0.
std::vector<double> curveFromPrediction(const float* prediction, uint32_t n, uint32_t firstK = 1);

/// k(p) for `slots` = F(M): the hull allocator (allocateOptimalHull) over the curves rebuilt from
/// `predictions` (9 per pixel, pixel-major, curves from k = firstK) and n(p). 0 where n(p) = 0;
/// firstK <= k(p) <= n(p) elsewhere; sum k <= slots. `firstK` 1 needs slots >= the covered
/// pixels; 0 (hybrid compositing, a pixel may keep no slot) takes any slots.
std::vector<uint32_t> allocateByPredictedCurves(const std::vector<float>& predictions,
                                                const std::vector<uint32_t>& n, uint64_t slots,
                                                uint32_t firstK = 1);

}  // namespace mfr
