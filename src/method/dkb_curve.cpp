// dkb-curve's curve representation and allocation (issue 14 sec. 4; the allocation is the optimal
// k-buffer's hull allocator of DHOIT sec. 3.1.2, Algorithm 1's convex variant): see
// mfr/method/dkb_curve.hpp.
#include "mfr/method/dkb_curve.hpp"

#include <algorithm>
#include <cmath>

#include "mfr/core/result.hpp"
#include "mfr/method/optimal_allocation.hpp"

namespace mfr {
namespace {

float unitRoot(double value, double scale) {
  return static_cast<float>(std::clamp(std::sqrt(std::max(value, 0.0) / scale), 0.0, 1.0));
}

double squared(float v) {
  const double x = std::isnan(v) ? 0.0 : std::clamp(static_cast<double>(v), 0.0, 1.0);
  return x * x;
}

}  // namespace

CurveTargets curveTargets(const std::vector<double>& curve, double scale) {
  MFR_CHECK_GT(scale, 0.0);
  CurveTargets t{};
  const size_t n = curve.size();
  for (size_t j = 1; j <= kCurveDrops; ++j)
    if (j < n) t[j - 1] = unitRoot(curve[j - 1] - curve[j], scale);
  if (n > kCurveOutputs) t[kCurveDrops] = unitRoot(curve[kCurveOutputs - 1], scale);
  return t;
}

double curveScale(const std::vector<std::vector<double>>& curves) {
  double scale = 0.0;
  for (const std::vector<double>& c : curves)
    if (!c.empty()) scale = std::max(scale, c.front());
  return scale > 0.0 ? scale : 1.0;
}

std::vector<double> curveFromPrediction(const float* prediction, uint32_t n) {
  std::vector<double> err(n, 0.0);
  if (n == 0) return err;
  // the tail: err(9) spread linearly down to err(n) = 0
  const double tail = n > kCurveOutputs ? squared(prediction[kCurveDrops]) : 0.0;
  for (uint32_t k = kCurveOutputs; k < n; ++k)
    err[k - 1] = tail * static_cast<double>(n - k) / static_cast<double>(n - kCurveOutputs);
  // the drops, from k = min(8, n - 1) down to 1
  const uint32_t last = std::min<uint32_t>(kCurveDrops, n - 1);
  double above = n > kCurveOutputs ? tail : 0.0;  // err(last + 1)
  for (uint32_t k = last; k >= 1; --k) {
    above += squared(prediction[k - 1]);
    err[k - 1] = above;
  }
  return err;
}

std::vector<uint32_t> allocateByPredictedCurves(const std::vector<float>& predictions,
                                                const std::vector<uint32_t>& n, uint64_t slots,
                                                uint32_t firstK) {
  MFR_CHECK(predictions.size() == n.size() * kCurveOutputs);
  MFR_CHECK_LE(firstK, 1u);
  std::vector<std::vector<double>> curves(n.size());
  for (size_t p = 0; p < n.size(); ++p) {
    std::vector<double> c = curveFromPrediction(predictions.data() + p * kCurveOutputs, n[p]);
    if (firstK == 0 && !c.empty()) {  // err(0): the first drop again (see the header)
      const double firstDrop = c.size() > 1 ? c[0] - c[1] : 0.0;
      c.insert(c.begin(), c[0] + firstDrop);
    }
    curves[p] = std::move(c);
  }
  OracleOptions options;
  options.firstK = firstK;
  return allocateOptimalHull(curves, slots, options);
}

}  // namespace mfr
