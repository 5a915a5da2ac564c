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

double fromCurveLogUnit(float v) {
  if (!(v > 0.0f)) return 0.0;  // (NaN too)
  const double x = std::min(static_cast<double>(v), 1.0);
  return kCurveLogTop * std::pow(10.0, kCurveLogDecades * (x - 1.0));
}

}  // namespace

float curveLogUnit(double value) {
  if (!(value > 0.0)) return 0.0f;
  return static_cast<float>(
      std::clamp(1.0 + std::log10(value / kCurveLogTop) / kCurveLogDecades, 0.0, 1.0));
}

CurveTargets curveTargets(const std::vector<double>& curve, double scale, uint32_t firstK) {
  MFR_CHECK_GT(scale, 0.0);
  MFR_CHECK_LE(firstK, 1u);
  const auto unit = [&](double value) {
    return firstK == 0 ? curveLogUnit(value) : unitRoot(value, scale);
  };
  CurveTargets t{};
  const size_t n = curve.size();
  for (size_t j = 1; j <= kCurveDrops; ++j)
    if (j < n) t[j - 1] = unit(curve[j - 1] - curve[j]);
  if (n > kCurveOutputs) t[kCurveDrops] = unit(curve[kCurveOutputs - 1]);
  return t;
}

double curveScale(const std::vector<std::vector<double>>& curves) {
  double scale = 0.0;
  for (const std::vector<double>& c : curves)
    if (!c.empty()) scale = std::max(scale, c.front());
  return scale > 0.0 ? scale : 1.0;
}

std::vector<double> curveFromPrediction(const float* prediction, uint32_t n, uint32_t firstK) {
  MFR_CHECK_LE(firstK, 1u);
  if (n == 0) return {};
  // from k = 0 (hybrid compositing) a tail of one fragment is exact: err(n - 1) = err(n) = 0, so
  // the drops end at k = n - 1
  const uint32_t last = firstK == 0 ? n - 1 : n;
  const uint32_t m = last + 1 - firstK;  // values err(firstK..last), the last 0
  std::vector<double> err(m, 0.0);
  const auto value = [&](float v) { return firstK == 0 ? fromCurveLogUnit(v) : squared(v); };
  // the tail: err(firstK + 8) spread linearly down to err(last) = 0
  const double tail = m > kCurveOutputs ? value(prediction[kCurveDrops]) : 0.0;
  for (uint32_t i = kCurveDrops; i + 1 < m; ++i)
    err[i] = tail * static_cast<double>(m - 1 - i) / static_cast<double>(m - 1 - kCurveDrops);
  // the drops, from index min(7, m - 2) down to 0
  double above = m > kCurveOutputs ? tail : 0.0;  // err at the index after the last drop
  for (uint32_t i = std::min<uint32_t>(kCurveDrops, m - 1); i-- > 0;) {
    above += value(prediction[i]);
    err[i] = above;
  }
  if (last < n) err.push_back(0.0);  // err(n)
  return err;
}

std::vector<uint32_t> allocateByPredictedCurves(const std::vector<float>& predictions,
                                                const std::vector<uint32_t>& n, uint64_t slots,
                                                uint32_t firstK) {
  MFR_CHECK(predictions.size() == n.size() * kCurveOutputs);
  MFR_CHECK_LE(firstK, 1u);
  std::vector<std::vector<double>> curves(n.size());
  for (size_t p = 0; p < n.size(); ++p)
    curves[p] = curveFromPrediction(predictions.data() + p * kCurveOutputs, n[p], firstK);
  OracleOptions options;
  options.firstK = firstK;
  return allocateOptimalHull(curves, slots, options);
}

}  // namespace mfr
