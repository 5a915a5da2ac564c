// dkb-curve's hybrid model (issue 28 item 2, mfr/method/dkb_curve.hpp): curves from k = 0 (the
// tail alone) on an absolute log scale, rebuilt with err(n - 1) = 0 (a tail of one fragment is
// exact; tested with any prediction in test_dkb_curve.cpp), from its own inputs
// (curvePixelFeatures, mfr/method/dkb_features.hpp). Expectations are computed here: the log scale
// from its definition, the tail-only error of two fragments from the formula of hybrid transparency
// (Maule et al. 2013) on the sRGB decode of IEC 61966-2-1.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/cpu/optimal_oracle.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/dkb_curve.hpp"
#include "mfr/method/dkb_features.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "scene/procedural_internal.hpp"

namespace mfr {
namespace {

double srgbToLinear(uint8_t v) {
  const double c = v / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

uint32_t rgba(uint8_t r, uint8_t g, uint8_t b, uint8_t a) {
  return r | (g << 8) | (b << 16) | (static_cast<uint32_t>(a) << 24);
}

TEST(DkbCurveHybrid, LogScaleSpansSixteenDecadesBelowThree) {
  EXPECT_FLOAT_EQ(curveLogUnit(3.0), 1.0f);
  EXPECT_FLOAT_EQ(curveLogUnit(30.0), 1.0f) << "clamped";
  EXPECT_NEAR(curveLogUnit(3e-8), 0.5f, 1e-6f);
  EXPECT_NEAR(curveLogUnit(3e-4), 0.75f, 1e-6f);
  EXPECT_FLOAT_EQ(curveLogUnit(3e-16), 0.0f);
  EXPECT_FLOAT_EQ(curveLogUnit(1e-20), 0.0f);
  EXPECT_FLOAT_EQ(curveLogUnit(0.0), 0.0f);
  EXPECT_FLOAT_EQ(curveLogUnit(-1.0), 0.0f);
  EXPECT_FLOAT_EQ(curveLogUnit(std::nan("")), 0.0f);
  // the definition datasets and models record names this scale
  const std::string scale = "1 + log10(v / " + std::to_string(static_cast<int>(kCurveLogTop)) +
                            ") / " + std::to_string(static_cast<int>(kCurveLogDecades)) + " ";
  EXPECT_EQ(std::string(kDkbCurveTailOnlyTargetScaling).rfind(scale, 0), 0u)
      << kDkbCurveTailOnlyTargetScaling;
}

/// A hybrid curve err(k), k = 0..n: err(n - 1) = err(n) = 0, drops of 1e-9..1 before, and beyond
/// k = 8 the linear tail the representation holds.
std::vector<double> randomHybridCurve(procedural::Rng& rng, uint32_t n) {
  std::vector<double> err(n + 1, 0.0);
  if (n <= 1) return err;
  const uint32_t last = n - 1;  // err(last) = 0
  const double tail = last > kCurveDrops ? std::pow(10.0, rng.uniform(-9.0f, 0.0f)) : 0.0;
  for (uint32_t k = kCurveDrops; k < last; ++k)
    err[k] = tail * (last - k) / static_cast<double>(last - kCurveDrops);
  double above = last > kCurveDrops ? tail : 0.0;
  for (uint32_t k = std::min<uint32_t>(kCurveDrops, last); k-- > 0;) {
    above += std::pow(10.0, rng.uniform(-9.0f, 0.0f));
    err[k] = above;
  }
  return err;
}

TEST(DkbCurveHybrid, CurvesFromTheTailAloneRoundTrip) {
  procedural::Rng rng(28);
  for (uint32_t n : {1u, 2u, 3u, 5u, 9u, 10u, 17u, 40u}) {
    for (int trial = 0; trial < 5; ++trial) {
      SCOPED_TRACE(testing::Message() << "n " << n << " trial " << trial);
      const std::vector<double> curve = randomHybridCurve(rng, n);
      const CurveTargets t = curveTargets(curve, 1.0, 0);
      for (float v : t) {
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(v, 1.0f);
      }
      const std::vector<double> rebuilt = curveFromPrediction(t.data(), n, 0);
      ASSERT_EQ(rebuilt.size(), n + 1);
      for (uint32_t k = 0; k <= n; ++k)  // float targets: about 1e-6 relative on this scale
        EXPECT_NEAR(rebuilt[k], curve[k], 2e-5 * curve[k]) << "k " << k;
    }
  }
}

/// err(0) of two fragments (front first) by hybrid transparency's tail (Maule et al.: colour
/// sum a c / sum a, opacity 1 - (1 - mean a)^2) against the exact composite, background's share
/// left out (feature 9's definition).
double twoFragmentTailOnlyError(const double a[2], const double c[2][3]) {
  double err = 0.0;
  const double opacity = 1.0 - std::pow(1.0 - (a[0] + a[1]) / 2, 2.0);
  for (int i = 0; i < 3; ++i) {
    const double exact = a[0] * c[0][i] + (1.0 - a[0]) * a[1] * c[1][i];
    const double tail = (a[0] * c[0][i] + a[1] * c[1][i]) / (a[0] + a[1]) * opacity;
    err += (exact - tail) * (exact - tail);
  }
  return err;
}

TEST(DkbCurveHybrid, InputsOfATwoFragmentPixel) {
  const float farDepth = 0.75f, nearDepth = 0.25f;
  const uint32_t back = rgba(40, 200, 90, 102), front = rgba(230, 30, 60, 179);  // a 0.4, 0.7
  FeatureAccumulator pixel;
  pixel.addWithCurveInputs(farDepth,
                           back);  // arrival order does not matter: the nearest is found by depth
  pixel.addWithCurveInputs(nearDepth, front);
  const double a[2] = {179 / 255.0, 102 / 255.0};
  const double c[2][3] = {{srgbToLinear(230), srgbToLinear(30), srgbToLinear(60)},
                          {srgbToLinear(40), srgbToLinear(200), srgbToLinear(90)}};
  const PixelFeatures f = curvePixelFeatures(pixel);
  EXPECT_FLOAT_EQ(f[0], 0.25f) << "log2(2) / 4";
  EXPECT_NEAR(f[1], a[0], 1e-6);
  EXPECT_NEAR(f[2], (a[0] + a[1]) / 2, 1e-6);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(f[3 + i], a[0] * c[0][i], 1e-6) << i;
    EXPECT_NEAR(f[6 + i], (a[0] * c[0][i] + a[1] * c[1][i]) / 2, 1e-6) << i;
  }
  const double err0 = twoFragmentTailOnlyError(a, c);
  ASSERT_GT(err0, 1e-3);
  EXPECT_NEAR(f[9], curveLogUnit(err0), 1e-5);
  // err(1) of two fragments is 0 (a tail of one fragment is exact), up to float rounding
  EXPECT_LE(f[10], curveLogUnit(1e-12));
  // one fragment behind the nearest has no spread (up to float cancellation under the root)
  EXPECT_NEAR(f[11], 0.0f, 1e-3f);
  EXPECT_EQ(curvePixelFeatures(FeatureAccumulator{}), PixelFeatures{}) << "uncovered";
}

TEST(DkbCurveHybrid, EstimatesAreTheOraclesForThreeFragmentsOfOneOpacity) {
  const uint32_t colours[3] = {rgba(230, 30, 60, 128), rgba(40, 200, 90, 128),
                               rgba(250, 240, 20, 128)};
  const float depths[3] = {0.3f, 0.6f, 0.8f};
  for (int order : {0, 1, 2}) {  // arrival order does not matter
    SCOPED_TRACE(order);
    FeatureAccumulator pixel;
    for (int i = 0; i < 3; ++i)
      pixel.addWithCurveInputs(depths[(i + order) % 3], colours[(i + order) % 3]);
    // the oracle's curve from the tail alone over a background (its share cancels here)
    FragmentNode sorted[3];
    for (int i = 0; i < 3; ++i) sorted[i] = makeNode(depths[i], colours[i]);
    const std::vector<double> curve =
        errorCurve(sorted, 3, glm::vec3(0.2f, 0.5f, 0.9f), Compositing::Hybrid, 0);
    ASSERT_EQ(curve.size(), 4u);
    ASSERT_GT(curve[1], 1e-4);
    const PixelFeatures f = curvePixelFeatures(pixel);
    EXPECT_NEAR(f[9], curveLogUnit(curve[0]), 1e-5);
    EXPECT_NEAR(f[10], curveLogUnit(curve[1]), 1e-5);
  }
  // two fragments: err(0) by the formula, written out independently
  FeatureAccumulator two;
  two.addWithCurveInputs(0.3f, colours[0]);
  two.addWithCurveInputs(0.6f, colours[1]);
  const double a[2] = {128 / 255.0, 128 / 255.0};
  const double c[2][3] = {{srgbToLinear(230), srgbToLinear(30), srgbToLinear(60)},
                          {srgbToLinear(40), srgbToLinear(200), srgbToLinear(90)}};
  EXPECT_NEAR(curvePixelFeatures(two)[9], curveLogUnit(twoFragmentTailOnlyError(a, c)), 1e-5);
}

TEST(DkbCurveHybrid, SpreadBehindTheNearestOfThreeFragments) {
  FeatureAccumulator pixel;
  pixel.addWithCurveInputs(0.2f, rgba(255, 255, 255, 255 / 2));
  pixel.addWithCurveInputs(0.5f,
                           rgba(255, 0, 0, 255));  // behind: premultiplied (1, 0, 0) and (0, 0, 1)
  pixel.addWithCurveInputs(0.6f, rgba(0, 0, 255, 255));
  const PixelFeatures f = curvePixelFeatures(pixel);
  // two colours (1, 0, 0) and (0, 0, 1): mean (0.5, 0, 0.5), mean |c|^2 = 1, spread sqrt(0.5)
  EXPECT_NEAR(f[11], std::sqrt(0.5f), 1e-6f);
  EXPECT_NEAR(f[0], std::log2(3.0f) / 4.0f, 1e-6f);
  EXPECT_NEAR(f[2], (127 / 255.0f + 2.0f) / 3.0f, 1e-6f);
}

TEST(DkbCurveHybrid, CurveInputsLeaveTheDeepKBuffersInputsAsTheyAre) {
  // the paper's feature pass adds without the curve inputs: the same accumulator otherwise
  procedural::Rng rng(30);
  FeatureAccumulator plain, withCurve;
  for (int i = 0; i < 50; ++i) {
    const float depth = rng.uniform();
    const uint32_t colour =
        rgba(static_cast<uint8_t>(rng.below(256)), static_cast<uint8_t>(rng.below(256)),
             static_cast<uint8_t>(rng.below(256)), static_cast<uint8_t>(2 + rng.below(254)));
    plain.add(depth, colour);
    withCurve.addWithCurveInputs(depth, colour);
  }
  EXPECT_EQ(plain.n, withCurve.n);
  EXPECT_EQ(plain.nearest, withCurve.nearest);
  EXPECT_EQ(plain.farthest, withCurve.farthest);
  EXPECT_EQ(plain.premultipliedSum, withCurve.premultipliedSum);
  EXPECT_EQ(plain.second, kFarNode) << "kept by addWithCurveInputs only";
  EXPECT_LT(withCurve.nearest, withCurve.second);
}

TEST(DkbCurveHybrid, HybridModelsDeclareTheTailOnlyDefinition) {
  const learn::Model builtin = *builtinDkbCurveModel(Compositing::Hybrid).value();
  const auto meta = nlohmann::json::parse(builtin.metadata);
  EXPECT_EQ(meta.at("features"), kDkbCurveFeatureSet);
  EXPECT_EQ(meta.at("target"), kDkbCurveTailOnlyTargetScaling);
  const learn::Model kbuffer = *builtinDkbCurveModel(Compositing::KBuffer).value();
  EXPECT_EQ(nlohmann::json::parse(kbuffer.metadata).at("features"), kDkbFeatureSet);
  // a hybrid curve model of the earlier definition (from k = 1, the deep k-buffer's inputs) is
  // refused with the reason; the same metadata is a kbuffer model's
  learn::Model old = builtin;
  old.metadata = nlohmann::json{
      {"features", kDkbFeatureSet},
      {"target", kDkbCurveTargetScaling},
      {"composite",
       "hybrid"}}.dump();
  auto refused = checkDkbCurveModel(old, "old.mfrnn");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("retrain it"), std::string::npos)
      << refused.error().message;
  EXPECT_NE(refused.error().message.find(kDkbCurveFeatureSet), std::string::npos)
      << refused.error().message;
  old.metadata = nlohmann::json{
      {"features", kDkbFeatureSet},
      {"target", kDkbCurveTargetScaling},
      {"composite",
       "kbuffer"}}.dump();
  EXPECT_TRUE(checkDkbCurveModel(old, "old.mfrnn"));
}

TEST(DkbCurveHybrid, AllocationFollowsThePredictedTailOnlyErrors) {
  // three pixels of two fragments: predicted err(0) 1e-2, 1e-6 and 1e-4 (err(1) = 0): the slots go
  // to the largest first, and a pixel of one fragment never takes one
  std::vector<float> predictions(4 * kCurveOutputs, 0.0f);
  predictions[0] = curveLogUnit(1e-2);
  predictions[kCurveOutputs] = curveLogUnit(1e-6);
  predictions[2 * kCurveOutputs] = curveLogUnit(1e-4);
  predictions[3 * kCurveOutputs] = 1.0f;  // ignored: n = 1
  const std::vector<uint32_t> n = {2, 2, 2, 1};
  EXPECT_EQ(allocateByPredictedCurves(predictions, n, 1, 0), (std::vector<uint32_t>{1, 0, 0, 0}));
  EXPECT_EQ(allocateByPredictedCurves(predictions, n, 2, 0), (std::vector<uint32_t>{1, 0, 1, 0}));
  EXPECT_EQ(allocateByPredictedCurves(predictions, n, 3, 0), (std::vector<uint32_t>{1, 1, 1, 0}))
      << "one slot makes a two-fragment pixel exact";
}

}  // namespace
}  // namespace mfr
