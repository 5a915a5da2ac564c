// Variable k-buffer: importance factors against the paper's equations on hand-checked pixels,
// the allocation's budget guarantees, determinism, and the unlimited-budget limit.
#include <gtest/gtest.h>

#include <cmath>

#include "mfr/cpu/render.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

ImportanceParams onlyFactor(bool depth, bool periphery, bool fresnel, bool noise) {
  ImportanceParams p;
  p.useDepth = depth;
  p.usePeriphery = periphery;
  p.useFresnel = fresnel;
  p.useNoise = noise;
  return p;
}

TEST(Importance, DepthTermFollowsEquation3) {
  const std::vector<uint32_t> n = {0, 1, 10, 20, 100};
  const ImportanceMaps m = computeImportance(5, 1, n, {}, onlyFactor(true, false, false, false));
  EXPECT_EQ(m.importance[0], 0.0f);  // no fragments, no importance
  EXPECT_NEAR(m.importance[1], 0.375 + 0.625 * (1.0 / 20.0), 1e-6);
  EXPECT_NEAR(m.importance[2], 0.6875, 1e-6);
  EXPECT_NEAR(m.importance[3], 1.0, 1e-6);
  EXPECT_NEAR(m.importance[4], 1.0, 1e-6);  // saturates at N_limit
}

TEST(Importance, PeripheryTermFollowsEquation4) {
  const int w = 100, h = 100;
  const std::vector<uint32_t> n(w * h, 1);
  const ImportanceMaps m = computeImportance(w, h, n, {}, onlyFactor(false, true, false, false));
  // corner pixel (0, 0): centre (0.5, 0.5), distance to (50, 50) = 49.5 * sqrt(2)
  const double r = 2.0 * 49.5 * std::sqrt(2.0) / (1.1 * std::sqrt(2.0 * 100 * 100));
  EXPECT_NEAR(m.importance[0], 1.0 - r * r * r, 1e-5);
  EXPECT_NEAR(m.importance[50 * w + 50], 1.0, 1e-5);
  // a fovea elsewhere moves the peak
  ImportanceParams p = onlyFactor(false, true, false, false);
  p.fovea = glm::vec2(10.5f, 20.5f);
  p.peripheryExponent = 10.0f;
  const ImportanceMaps f = computeImportance(w, h, n, {}, p);
  EXPECT_NEAR(f.importance[20 * w + 10], 1.0, 1e-6);
  EXPECT_LT(f.importance[80 * w + 90], f.importance[20 * w + 12]);
}

TEST(Importance, FresnelTermFollowsEquation5) {
  const std::vector<uint32_t> n = {1, 1, 1};
  const std::vector<float> cosine = {1.0f, 0.5f, 0.0f};
  const ImportanceMaps m =
      computeImportance(3, 1, n, cosine, onlyFactor(false, false, true, false));
  EXPECT_NEAR(m.importance[0], 1.0, 1e-6);
  EXPECT_NEAR(m.importance[1], 1.0 - std::pow(0.5, 5) / 2.0, 1e-6);
  EXPECT_NEAR(m.importance[2], 0.5, 1e-6);
}

TEST(Importance, NoiseIsBoundedAndSeeded) {
  const std::vector<uint32_t> n(64 * 64, 1);
  ImportanceParams p = onlyFactor(false, false, false, true);
  const ImportanceMaps a = computeImportance(64, 64, n, {}, p);
  const ImportanceMaps b = computeImportance(64, 64, n, {}, p);
  p.seed = 2;
  const ImportanceMaps c = computeImportance(64, 64, n, {}, p);
  EXPECT_EQ(a.importance, b.importance);
  EXPECT_NE(a.importance, c.importance);
  double mean = 0.0;
  for (float v : a.noise) {
    EXPECT_GE(v, -0.05f);
    EXPECT_LT(v, 0.05f);
    mean += v;
  }
  EXPECT_NEAR(mean / a.noise.size(), 0.0, 0.005);  // xi is uniform: lambda * (xi - 0.5) averages 0
}

TEST(Importance, ProductOfFactorsPlusNoiseClampedAtZero) {
  const std::vector<uint32_t> n = {10};
  const std::vector<float> cosine = {0.0f};
  ImportanceParams p;
  p.noise = 0.0f;
  const ImportanceMaps m = computeImportance(1, 1, n, cosine, p);
  EXPECT_NEAR(m.importance[0], m.depth[0] * m.periphery[0] * m.fresnel[0], 1e-7);
  EXPECT_NEAR(m.importance[0], 0.6875 * 1.0 * 0.5, 1e-5);
}

RenderOutput renderVkb(const std::string& preset, uint64_t budget, int size = 96,
                       const std::string& scene = "procedural:hairball?strands=300",
                       int threads = 2) {
  auto s = loadScene(scene);
  EXPECT_TRUE(s.ok());
  RasterOptions ro{size, size, 32, threads};
  auto frame = RasterFrame::build(*s, *s->defaultCamera, ro);
  RenderOptions o;
  o.budgetBytes = budget;
  auto out = render(*frame, methodPreset(preset).value(), o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return std::move(out.value());
}

TEST(VariableKBuffer, SumOfKNeverExceedsTheSlotsTheBudgetBuys) {
  for (const char* preset : {"vkb", "vkb-fill"})
    for (uint64_t budget : {200000ull, 400000ull, 1000000ull}) {
      const RenderOutput out = renderVkb(preset, budget);
      const MemoryModel model = MemoryModel::of(methodPreset(preset).value());
      const uint64_t slots = model.fragmentSlots(budget, 96 * 96);
      ASSERT_EQ(out.kMap.size(), 96u * 96u);
      ASSERT_EQ(out.depthComplexity.size(), 96u * 96u);
      uint64_t sumK = 0;
      for (uint32_t k : out.kMap) sumK += k;
      EXPECT_GT(sumK, 0u) << preset << " " << budget;
      EXPECT_LE(sumK, slots) << preset << " " << budget;
      EXPECT_LE(out.stats.bytesUsed, budget);
      EXPECT_EQ(out.stats.bytesUsed, 96u * 96u * 13u + sumK * 8u) << "counter, offset, lock, n.v";
      if (std::string(preset) == "vkb-fill") {
        // the fill variant uses the budget up to the demand
        uint64_t demand = 0;
        for (uint32_t n : out.depthComplexity) demand += n;
        EXPECT_EQ(sumK, std::min(slots, demand)) << budget;
        for (size_t p = 0; p < out.kMap.size(); ++p) {
          EXPECT_LE(out.kMap[p], out.depthComplexity[p]);
          if (out.depthComplexity[p] > 0) {
            EXPECT_GE(out.kMap[p], 1u) << "every covered pixel keeps one";
          }
        }
      }
    }
}

TEST(VariableKBuffer, FillCapturesAtLeastAsManyFragmentsAsThePaperRule) {
  const RenderOutput exact = renderVkb("vkb", 400000);
  const RenderOutput fill = renderVkb("vkb-fill", 400000);
  EXPECT_GE(fill.stats.captured, exact.stats.captured);
  EXPECT_GT(fill.stats.captured, 0u);
}

TEST(VariableKBuffer, MoreImportantPixelsGetMoreSlots) {
  const RenderOutput out = renderVkb("vkb", 1000000);
  // among pixels with the same n(p), k(p) must not decrease with importance
  int compared = 0;
  for (size_t a = 0; a < out.kMap.size(); a += 7)
    for (size_t b = a + 1; b < out.kMap.size(); b += 331)
      if (out.depthComplexity[a] == out.depthComplexity[b] &&
          out.importance.importance[a] > out.importance.importance[b]) {
        EXPECT_GE(out.kMap[a], out.kMap[b]);
        ++compared;
      }
  EXPECT_GT(compared, 100) << "too few pixel pairs with equal n(p) to test anything";
}

TEST(VariableKBuffer, DeterministicForAFixedSeed) {
  const RenderOutput a = renderVkb("vkb", 400000), b = renderVkb("vkb", 400000);
  EXPECT_EQ(a.kMap, b.kMap);
  EXPECT_EQ(encodeSrgb(a.image).rgba, encodeSrgb(b.image).rgba);
}

TEST(VariableKBuffer, IdenticalForAnyThreadCount) {
  // the importance map (noise included), the allocation and the image do not depend on how many
  // workers rasterize and capture: 1 thread against 2 and 7
  int compared = 0;
  for (const char* preset : {"vkb", "vkb-fill"}) {
    const RenderOutput one =
        renderVkb(preset, 400000, 96, "procedural:hairball?strands=300", /*threads=*/1);
    ASSERT_FALSE(one.kMap.empty());
    ASSERT_FALSE(one.importance.importance.empty());
    ASSERT_GT(one.stats.lost, 0u) << preset << ": the budget must bind for k(p) to matter";
    for (const int threads : {2, 7}) {
      const RenderOutput many =
          renderVkb(preset, 400000, 96, "procedural:hairball?strands=300", threads);
      EXPECT_EQ(many.importance.importance, one.importance.importance) << preset << " " << threads;
      EXPECT_EQ(many.importance.noise, one.importance.noise) << preset << " " << threads;
      EXPECT_EQ(many.nearestCosine, one.nearestCosine) << preset << " " << threads;
      EXPECT_EQ(many.kMap, one.kMap) << preset << " " << threads;
      EXPECT_EQ(many.stats.captured, one.stats.captured) << preset << " " << threads;
      EXPECT_EQ(encodeSrgb(many.image).rgba, encodeSrgb(one.image).rgba)
          << preset << " " << threads;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 4);
}

TEST(VariableKBuffer, UnlimitedBudgetEqualsTheABuffer) {
  for (const char* preset : {"vkb", "vkb-fill"}) {
    const RenderOutput v = renderVkb(preset, 1ull << 32);
    auto s = loadScene("procedural:hairball?strands=300");
    RasterOptions ro{96, 96, 32, 2};
    auto frame = RasterFrame::build(*s, *s->defaultCamera, ro);
    const RenderOutput a = *render(*frame, methodPreset("abuffer").value(), {});
    EXPECT_EQ(v.stats.lost, 0u) << preset;
    EXPECT_EQ(encodeSrgb(v.image).rgba, encodeSrgb(a.image).rgba) << preset;
  }
}

TEST(VariableKBuffer, BudgetBelowOneFragmentPerCoveredPixelIsAnError) {
  auto s = loadScene("procedural:hairball?strands=300");
  RasterOptions ro{96, 96, 32, 2};
  auto frame = RasterFrame::build(*s, *s->defaultCamera, ro);
  RenderOptions o;
  o.budgetBytes = 96 * 96 * 13 + 100;
  auto out = render(*frame, methodPreset("vkb").value(), o);
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.error().message.find("covered pixel"), std::string::npos) << out.error().message;
}

}  // namespace
}  // namespace mfr
