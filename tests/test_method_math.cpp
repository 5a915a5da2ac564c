// method_math.h, the methods' maths shared by the CPU engine and the GL engine's shaders: each
// function against values computed by hand (exact in float where the inputs allow), and the
// constants against the values the papers and the engines used before they were shared.
// (GlShaders.MethodConstantsOnlyInMethodMath checks that no shader repeats a constant.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "mfr/method/compositing.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/method/method_math.h"

namespace mfr::method_math {
namespace {

void expectVec(glm::vec3 v, float r, float g, float b) {
  EXPECT_EQ(v.r, r);
  EXPECT_EQ(v.g, g);
  EXPECT_EQ(v.b, b);
}

TEST(MethodMath, ConstantsAreThePapersAndTheEnginesValues) {
  EXPECT_EQ(kWboitMinWeight, 0.01f);  // McGuire and Bavoil, Eq. 10
  EXPECT_EQ(kWboitMaxWeight, 3000.0f);
  EXPECT_EQ(kWboitMinDenominator, 0.0001f);
  EXPECT_EQ(kWboitMaxDenominator, 50000.0f);
  EXPECT_EQ(kMboitBias, 5e-7f);  // Muenstermann et al., 4 power moments in float32
  EXPECT_EQ(kMboitOverestimation, 0.25f);
  EXPECT_EQ(kMboitTiny, 1e-12);  // the integer quotient is the literal's double
  EXPECT_EQ(kGuardBand, 8.0f);
  EXPECT_EQ(kGuardBandMaxNdc, 8.0f * 1.001);
  EXPECT_EQ(kImportanceNoiseUnit, std::ldexp(1.0f, -24));
  // SplitMix64's constants from their 32-bit words
  EXPECT_EQ(words64(kSplitMixGammaLo, kSplitMixGammaHi), 0x9E3779B97F4A7C15ull);
  EXPECT_EQ(words64(kSplitMixOffsetLo, kSplitMixOffsetHi), 0x632BE59BD9B4E019ull);
  EXPECT_EQ(words64(kSplitMixMul1Lo, kSplitMixMul1Hi), 0xBF58476D1CE4E5B9ull);
  EXPECT_EQ(words64(kSplitMixMul2Lo, kSplitMixMul2Hi), 0x94D049BB133111EBull);
}

TEST(MethodMath, OverStepIsFrontToBackOver) {
  float r = 0.0f, g = 0.0f, b = 0.0f, T = 1.0f;
  overStep(r, g, b, T, 0.5f, 1.0f, 0.5f, 0.25f);  // w = 0.5
  EXPECT_EQ(r, 0.5f);
  EXPECT_EQ(g, 0.25f);
  EXPECT_EQ(b, 0.125f);
  EXPECT_EQ(T, 0.5f);
  overStep(r, g, b, T, 0.5f, 0.0f, 1.0f, 0.0f);  // w = 0.25
  EXPECT_EQ(r, 0.5f);
  EXPECT_EQ(g, 0.5f);
  EXPECT_EQ(b, 0.125f);
  EXPECT_EQ(T, 0.25f);
  expectVec(overBackground(glm::vec3(r, g, b), T, glm::vec3(1.0f, 0.0f, 2.0f)), 0.75f, 0.5f,
            0.625f);
}

TEST(MethodMath, HybridTailSumsAndWeighsByItsOpacity) {
  float r = 0.0f, g = 0.0f, b = 0.0f, alpha = 0.0f;
  uint count = 0;
  hybridTailAdd(r, g, b, alpha, count, 0.5f, 1.0f, 0.0f, 0.0f);
  hybridTailAdd(r, g, b, alpha, count, 0.5f, 1.0f, 0.0f, 0.5f);
  EXPECT_EQ(r, 1.0f);
  EXPECT_EQ(b, 0.25f);
  EXPECT_EQ(alpha, 1.0f);
  EXPECT_EQ(count, 2u);
  // C_tail = (1, 0, 0.25), a_avg = 0.5, alpha_tail = 1 - 0.5^2 = 0.75
  const glm::vec3 background(0.0f, 0.0f, 1.0f);
  expectVec(hybridBehind(glm::vec3(r, g, b), alpha, count, background), 0.75f, 0.0f, 0.4375f);
  expectVec(hybridBehind(glm::vec3(r, g, b), alpha, 0u, background), 0.0f, 0.0f, 1.0f);
  // a tail of no alpha holds additive nodes only: their emission over the background, unweighted
  expectVec(hybridBehind(glm::vec3(r, g, b), 0.0f, count, background), 1.0f, 0.0f, 1.25f);
  // the CPU engine's HybridTail::add is this step on the unpacked colour word
  HybridTail tail;
  tail.add(0xff0000ffu);  // red, alpha 1
  EXPECT_FLOAT_EQ(tail.r, 1.0f);
  EXPECT_EQ(tail.g, 0.0f);
  EXPECT_FLOAT_EQ(tail.alpha, 1.0f);
  EXPECT_EQ(tail.count, 1u);
}

TEST(MethodMath, WboitWeightFollowsEquation10) {
  EXPECT_EQ(wboitWeight(0.0f, 1.0f), 3000.0f);
  EXPECT_EQ(wboitWeight(0.5f, 0.5f), 0.5f * 375.0f);  // 3e3 * 0.5^3
  EXPECT_EQ(wboitWeight(1.0f, 1.0f), 0.01f);          // the lower clamp
  EXPECT_EQ(wboitWeight(-3.0f, 1.0f), 3000.0f);       // depth clamped to [0, 1]
  EXPECT_EQ(wboitWeight(2.0f, 0.5f), 0.5f * 0.01f);
}

TEST(MethodMath, WboitAccumulatesAndComposites) {
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f, revealage = 1.0f;
  wboitAccumulate(r, g, b, a, revealage, glm::vec3(1.0f, 0.5f, 0.0f), 0.5f, 4.0f);
  EXPECT_EQ(r, 2.0f);  // c a w
  EXPECT_EQ(g, 1.0f);
  EXPECT_EQ(b, 0.0f);
  EXPECT_EQ(a, 2.0f);  // a w
  EXPECT_EQ(revealage, 0.5f);
  // (1, 0.5, 0) * (1 - 0.5) + 0.5 * (1, 1, 1)
  expectVec(wboitComposite(glm::vec3(r, g, b), a, revealage, glm::vec3(1.0f)), 1.0f, 0.75f, 0.5f);
  expectVec(wboitComposite(glm::vec3(1.0f), 0.0f, 0.5f, glm::vec3(0.25f)), 0.25f, 0.25f, 0.25f);
  // the denominator's clamps: [1e-4, 5e4]
  EXPECT_EQ(wboitComposite(glm::vec3(1.0f), 1e-9f, 0.0f, glm::vec3(0.0f)).r, 1.0f / 1e-4f);
  EXPECT_EQ(wboitComposite(glm::vec3(1e5f), 1e9f, 0.0f, glm::vec3(0.0f)).r, 1e5f / 5e4f);
}

TEST(MethodMath, MlabMergesAndCompositesByOver) {
  const glm::vec3 c = mlabPremultiplied(glm::vec3(1.0f, 0.5f, 0.25f), 0.5f);
  expectVec(c, 0.5f, 0.25f, 0.125f);
  EXPECT_EQ(mlabTransmittance(0.25f), 0.75f);
  float r = 0.5f, g = 0.0f, b = 0.0f, T = 0.5f;
  mlabMergeBehind(r, g, b, T, glm::vec3(0.0f, 0.5f, 1.0f), 0.5f);
  EXPECT_EQ(r, 0.5f);
  EXPECT_EQ(g, 0.25f);
  EXPECT_EQ(b, 0.5f);
  EXPECT_EQ(T, 0.25f);
  glm::vec3 color(0.0f);
  float t = 1.0f;
  mlabCompositeStep(color, t, glm::vec3(0.5f, 0.0f, 0.0f), 0.5f);
  mlabCompositeStep(color, t, glm::vec3(0.0f, 0.5f, 0.0f), 0.5f);
  expectVec(color, 0.5f, 0.25f, 0.0f);
  EXPECT_EQ(t, 0.25f);
}

TEST(MethodMath, MboitMomentsAndComposite) {
  EXPECT_EQ(mboitWarpDepth(0.0f), -1.0f);
  EXPECT_EQ(mboitWarpDepth(0.5f), 0.0f);
  EXPECT_EQ(mboitWarpDepth(1.0f), 1.0f);
  EXPECT_EQ(mboitWarpDepth(7.0f), 1.0f);
  EXPECT_NEAR(mboitAbsorbance(0.5f), std::log(2.0), 1e-6);
  EXPECT_NEAR(mboitAbsorbance(1.0f), -std::log(1.0 - 0.99999), 1e-2);  // finite: alpha capped
  float b0 = 0.0f, b1 = 0.0f, b2 = 0.0f, b3 = 0.0f, b4 = 0.0f;
  mboitAddMoments(b0, b1, b2, b3, b4, 2.0f, 0.5f);
  EXPECT_EQ(b0, 2.0f);
  EXPECT_EQ(b1, 1.0f);
  EXPECT_EQ(b2, 0.5f);
  EXPECT_EQ(b3, 0.25f);
  EXPECT_EQ(b4, 0.125f);
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;
  mboitAddColor(r, g, b, a, glm::vec3(1.0f, 0.5f, 0.0f), 0.5f);
  EXPECT_EQ(r, 0.5f);
  EXPECT_EQ(g, 0.25f);
  EXPECT_EQ(a, 0.5f);
  // T_total = exp(-ln 2) = 0.5: 0.5 * (1, 0.5, 0) + 0.5 * background
  const glm::vec3 out = mboitComposite(std::log(2.0f), glm::vec3(r, g, b), a, glm::vec3(1.0f));
  EXPECT_NEAR(out.r, 1.0f, 1e-6f);
  EXPECT_NEAR(out.g, 0.75f, 1e-6f);
  EXPECT_NEAR(out.b, 0.5f, 1e-6f);
  expectVec(mboitComposite(0.0f, glm::vec3(1.0f), 1.0f, glm::vec3(0.25f)), 0.25f, 0.25f, 0.25f);
}

TEST(MethodMath, MboitTransmittanceOfOneFragment) {
  // one fragment of absorbance A at warped depth 0: in front of it T = 1, behind it exp(-A), at
  // it exp(-overestimation A)
  const float A = std::log(4.0f);
  float b0 = 0.0f, b1 = 0.0f, b2 = 0.0f, b3 = 0.0f, b4 = 0.0f;
  mboitAddMoments(b0, b1, b2, b3, b4, A, 0.0f);
  EXPECT_EQ(mboitTransmittance(0.0f, b1, b2, b3, b4, 0.0f, kMboitBias, kMboitOverestimation), 1.0f);
  EXPECT_NEAR(mboitTransmittance(b0, b1, b2, b3, b4, -0.5f, kMboitBias, kMboitOverestimation), 1.0f,
              1e-3f);
  EXPECT_NEAR(mboitTransmittance(b0, b1, b2, b3, b4, 0.5f, kMboitBias, kMboitOverestimation), 0.25f,
              1e-3f);
  EXPECT_NEAR(mboitTransmittance(b0, b1, b2, b3, b4, 0.0f, kMboitBias, kMboitOverestimation),
              std::exp(-0.25f * A), 1e-3f);
}

TEST(MethodMath, ImportanceTermsFollowEquations3To6) {
  EXPECT_EQ(importanceDepth(0.375f, 0.625f, 10u, 20.0f), 0.6875f);
  EXPECT_EQ(importanceDepth(0.375f, 0.625f, 40u, 20.0f), 1.0f);  // saturates at N_limit
  EXPECT_EQ(importanceDiagonal(3.0f, 4.0f), 1.1f * 5.0f);
  // pixel (3, 4), centre (3.5, 4.5), fovea (0.5, 0.5): distance 5; diagonal 10: base 1
  EXPECT_EQ(importancePeriphery(3u, 4u, glm::vec2(0.5f), 10.0f, 3.0f, 3), 0.0f);
  EXPECT_EQ(importancePeriphery(0u, 0u, glm::vec2(0.5f), 10.0f, 3.0f, 3), 1.0f);
  // distance 2.5 of diagonal 10: 1 - 0.5^3
  EXPECT_EQ(importancePeriphery(2u, 0u, glm::vec2(0.0f, 0.5f), 10.0f, 3.0f, 3), 0.875f);
  EXPECT_EQ(importanceFresnel(1.0f), 1.0f);
  EXPECT_EQ(importanceFresnel(0.0f), 0.5f);
  EXPECT_EQ(importanceFresnel(0.5f), 1.0f - 0.03125f * 0.5f);
  EXPECT_EQ(importanceNoiseTerm(0.1f, 0.5f), 0.0f);
  EXPECT_EQ(importanceNoiseTerm(0.5f, 1.0f), 0.25f);
  EXPECT_EQ(importanceCombine(0.5f, 0.5f, 1.0f, 0.25f), 0.5f);
  EXPECT_EQ(importanceCombine(0.5f, 0.5f, 1.0f, -0.5f), 0.0f);
  EXPECT_EQ(importanceCombine(std::numeric_limits<float>::quiet_NaN(), 1.0f, 1.0f, 0.0f), 0.0f);
}

TEST(MethodMath, ImportanceNoiseIsSplitMix64) {
  // SplitMix64's finaliser written out with its published constants
  const auto reference = [](uint64_t seed, uint64_t pixel) {
    uint64_t z = seed * 0x9E3779B97F4A7C15ull + pixel + 0x632BE59BD9B4E019ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<float>(z >> 40) / 16777216.0f;
  };
  for (uint64_t seed : {0ull, 1ull, 12345ull})
    for (uint64_t pixel : {0ull, 1ull, 999ull, 1ull << 40})
      EXPECT_EQ(importanceNoise(seed, pixel), reference(seed, pixel)) << seed << " " << pixel;
}

}  // namespace
}  // namespace mfr::method_math
