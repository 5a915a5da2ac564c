// The optimal k-buffer allocators (DHOIT Algorithm 1) against exhaustive search on tiny images.
#include <gtest/gtest.h>

#include <functional>
#include <random>

#include "mfr/core/color.hpp"
#include "mfr/method/compositing.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "mfr/method/render.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

// exhaustive minimum of sum err over k(p) in [1, n(p)], sum k <= slots
double exhaustiveMinimum(const std::vector<std::vector<double>>& curves, uint64_t slots) {
  double best = 1e300;
  std::vector<uint32_t> k(curves.size(), 1);
  std::function<void(size_t, uint64_t)> visit = [&](size_t p, uint64_t used) {
    if (p == curves.size()) {
      if (used <= slots) best = std::min(best, allocationError(curves, k));
      return;
    }
    for (uint32_t x = 1; x <= curves[p].size(); ++x) {
      k[p] = x;
      visit(p + 1, used + x);
    }
  };
  visit(0, 0);
  return best;
}

std::vector<FragmentNode> randomPixel(std::mt19937& rng, uint32_t n) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<FragmentNode> nodes;
  for (uint32_t i = 0; i < n; ++i)
    nodes.push_back(
        makeNode(u(rng), packFragmentColor({u(rng), u(rng), u(rng)}, 0.1f + 0.8f * u(rng))));
  std::sort(nodes.begin(), nodes.end());
  return nodes;
}

bool convex(const std::vector<double>& e) {
  for (size_t i = 2; i < e.size(); ++i)
    if (e[i - 2] - e[i - 1] < e[i - 1] - e[i] - 1e-15) return false;
  return true;
}

void expectValid(const std::vector<std::vector<double>>& curves, const std::vector<uint32_t>& k,
                 uint64_t slots) {
  uint64_t used = 0;
  for (size_t p = 0; p < curves.size(); ++p) {
    EXPECT_GE(k[p], 1u);
    EXPECT_LE(k[p], curves[p].size());
    used += k[p];
  }
  EXPECT_LE(used, slots);
}

TEST(OptimalAllocation, ErrorCurveMatchesHybridCompositingAndEndsAtZero) {
  std::mt19937 rng(5);
  const glm::vec3 bg(0.9f, 0.8f, 1.0f);
  for (int trial = 0; trial < 50; ++trial) {
    const std::vector<FragmentNode> px = randomPixel(rng, 1 + trial % 7);
    const uint32_t n = static_cast<uint32_t>(px.size());
    const std::vector<double> e = hybridErrorCurve(px.data(), n, bg);
    ASSERT_EQ(e.size(), n);
    EXPECT_EQ(e.back(), 0.0);
    const glm::vec3 exact = compositeKBuffer(px.data(), n, bg);
    for (uint32_t k = 1; k < n; ++k) {
      HybridTail tail;
      for (uint32_t i = k; i < n; ++i) tail.add(nodeColor(px[i]));
      const glm::vec3 d = exact - compositeHybrid(px.data(), k, tail, bg);
      EXPECT_NEAR(e[k - 1], glm::dot(d, d), 1e-5) << "k=" << k;
    }
  }
}

TEST(OptimalAllocation, KBufferErrorCurveDropsTheTail) {
  std::mt19937 rng(9);
  const glm::vec3 bg(0.2f, 0.5f, 1.0f);
  for (int trial = 0; trial < 50; ++trial) {
    const std::vector<FragmentNode> px = randomPixel(rng, 1 + trial % 7);
    const uint32_t n = static_cast<uint32_t>(px.size());
    const std::vector<double> e = errorCurve(px.data(), n, bg, Compositing::KBuffer);
    ASSERT_EQ(e.size(), n);
    EXPECT_EQ(e.back(), 0.0);
    const glm::vec3 exact = compositeKBuffer(px.data(), n, bg);
    for (uint32_t k = 1; k < n; ++k) {
      const glm::vec3 d = exact - compositeKBuffer(px.data(), k, bg);
      EXPECT_NEAR(e[k - 1], glm::dot(d, d), 1e-5) << "k=" << k;
    }
  }
}

TEST(OptimalAllocation, BothAllocatorsRespectTheBudgetAndKeepOneFragmentPerPixel) {
  std::mt19937 rng(9);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<std::vector<double>> curves;
    uint64_t total = 0;
    for (int p = 0; p < 4; ++p) {
      const std::vector<FragmentNode> px = randomPixel(rng, 1 + (trial + p) % 6);
      curves.push_back(
          hybridErrorCurve(px.data(), static_cast<uint32_t>(px.size()), glm::vec3(1.0f)));
      total += px.size();
    }
    for (uint64_t slots = curves.size(); slots <= total; ++slots) {
      expectValid(curves, allocateOptimalGreedy(curves, slots), slots);
      expectValid(curves, allocateOptimalHull(curves, slots), slots);
    }
  }
}

TEST(OptimalAllocation, ExactOnConvexCurvesAndNeverBelowTheTrueOptimum) {
  std::mt19937 rng(11);
  int convexCases = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<std::vector<double>> curves;
    uint64_t total = 0;
    bool allConvex = true;
    for (int p = 0; p < 3; ++p) {
      const std::vector<FragmentNode> px = randomPixel(rng, 1 + (trial * 7 + p) % 5);
      curves.push_back(
          hybridErrorCurve(px.data(), static_cast<uint32_t>(px.size()), glm::vec3(1.0f)));
      allConvex = allConvex && convex(curves.back());
      total += px.size();
    }
    convexCases += allConvex;
    for (uint64_t slots = curves.size(); slots <= total; ++slots) {
      const double best = exhaustiveMinimum(curves, slots);
      const double hull = allocationError(curves, allocateOptimalHull(curves, slots));
      const double greedy = allocationError(curves, allocateOptimalGreedy(curves, slots));
      EXPECT_GE(hull, best - 1e-12);
      EXPECT_GE(greedy, best - 1e-12);
      if (allConvex) {
        EXPECT_NEAR(hull, best, 1e-12) << "trial " << trial << " slots " << slots;
      }
    }
  }
  EXPECT_GT(convexCases, 20);
}

TEST(OptimalAllocation, PublishedGreedyIsNotOptimalOnThisCounterexample) {
  // Two convex error curves (k = 1..n): pixel 0 loses 0.1 per removed fragment, pixel 1 has two
  // fragments and loses 0.25 without its second. With 3 slots: k = (1, 2) costs 0.30, k = (2, 1)
  // costs 0.45. Algorithm 1 keys its heap by the pixel's error *after* a removal, so it removes
  // from pixel 0 twice (0.10, then 0.20 < 0.25) and then must take pixel 1's fragment: 0.45.
  // Keying by the increase (or the hull allocator) finds 0.30.
  const std::vector<std::vector<double>> curves = {{0.30, 0.20, 0.10, 0.0}, {0.25, 0.0}};
  const uint64_t slots = 3;
  const double best = exhaustiveMinimum(curves, slots);
  const double greedy = allocationError(curves, allocateOptimalGreedy(curves, slots));
  const double hull = allocationError(curves, allocateOptimalHull(curves, slots));
  EXPECT_NEAR(best, 0.30, 1e-12);
  EXPECT_NEAR(greedy, 0.45, 1e-12);
  EXPECT_NEAR(hull, best, 1e-12);
}

double linearMse(const ImageRGB& a, const ImageRGB& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const glm::vec3 d = a.pixels[i] - b.pixels[i];
    sum += glm::dot(d, d);
  }
  return sum / (3.0 * a.pixels.size());
}

TEST(OptimalPreset, BeatsTheOtherAllocationsWithinTheSameBudget) {
  auto scene = loadScene("procedural:hairball?strands=300");
  ASSERT_TRUE(scene.ok());
  RasterOptions ro{96, 96, 16, 2};
  auto frame = RasterFrame::build(*scene, *scene->defaultCamera, ro);
  const RenderOutput truth = *render(*frame, methodPreset("abuffer").value(), {});
  RenderOptions o;
  o.budgetBytes = 400000;
  auto run = [&](const std::string& name) {
    MethodDesc m = methodPreset(name).value();
    m.compositing = Compositing::Hybrid;
    auto out = render(*frame, m, o);
    EXPECT_TRUE(out.ok()) << name << ": " << (out.ok() ? "" : out.error().message);
    return std::move(out.value());
  };
  const RenderOutput optimal = run("optimal"), greedy = run("optimal-greedy");
  const RenderOutput dynamic = run("kplus-dynamic"), fill = run("vkb-fill");
  const uint64_t slots =
      MemoryModel::of(methodPreset("optimal").value()).fragmentSlots(400000, 96 * 96);
  uint64_t sumK = 0;
  for (size_t p = 0; p < optimal.kMap.size(); ++p) {
    sumK += optimal.kMap[p];
    if (truth.depthComplexity[p] > 0) {
      EXPECT_GE(optimal.kMap[p], 1u);
    }
  }
  EXPECT_LE(sumK, slots);
  EXPECT_LE(optimal.stats.bytesUsed, 400000u);
  const double eOptimal = linearMse(optimal.image, truth.image);
  EXPECT_GT(eOptimal, 0.0);
  EXPECT_LT(eOptimal, linearMse(dynamic.image, truth.image));
  EXPECT_LT(eOptimal, linearMse(fill.image, truth.image));
  EXPECT_LT(linearMse(greedy.image, truth.image), linearMse(dynamic.image, truth.image));
}

TEST(OptimalPreset, WithKBufferCompositingMinimisesTheKBufferError) {
  auto scene = loadScene("procedural:hairball?strands=300");
  ASSERT_TRUE(scene.ok());
  auto frame = RasterFrame::build(*scene, *scene->defaultCamera, RasterOptions{96, 96, 16, 2});
  const RenderOutput truth = *render(*frame, methodPreset("abuffer").value(), {});
  RenderOptions o;
  o.budgetBytes = 300000;
  auto error = [&](const std::string& name) {
    MethodDesc m = methodPreset(name).value();
    m.compositing = Compositing::KBuffer;
    auto out = render(*frame, m, o);
    EXPECT_TRUE(out.ok()) << name;
    return linearMse(out->image, truth.image);
  };
  const double optimal = error("optimal");
  EXPECT_GT(optimal, 0.0);
  for (const char* other : {"kplus-dynamic", "vkb-fill", "kplus-sb"})
    EXPECT_LT(optimal, error(other)) << other;
}

}  // namespace
}  // namespace mfr
