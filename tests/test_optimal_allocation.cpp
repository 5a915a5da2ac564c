// The optimal k-buffer allocators (DHOIT Algorithm 1) against exhaustive search on tiny images.
#include <gtest/gtest.h>

#include <functional>
#include <random>

#include "mfr/core/color.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/compositing.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/optimal_allocation.hpp"
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

TEST(OptimalAllocation, HullIsExactOnConvexCurves) {
  std::mt19937 rng(11);
  int convexCases = 0, compared = 0;
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
    if (!allConvex) continue;
    ++convexCases;
    for (uint64_t slots = curves.size(); slots <= total; ++slots) {
      const double best = exhaustiveMinimum(curves, slots);
      EXPECT_NEAR(allocationError(curves, allocateOptimalHull(curves, slots)), best, 1e-12)
          << "trial " << trial << " slots " << slots;
      ++compared;
    }
  }
  EXPECT_GT(convexCases, 20);
  EXPECT_GT(compared, 100);
}

// Random curves with err(n) = 0 and otherwise arbitrary values: most are not convex.
std::vector<std::vector<double>> randomCurves(std::mt19937& rng, int pixels, uint32_t maxN) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::vector<double>> curves;
  for (int p = 0; p < pixels; ++p) {
    const uint32_t n = 1 + rng() % maxN;
    std::vector<double> e(n, 0.0);
    for (uint32_t i = 0; i + 1 < n; ++i) e[i] = u(rng);
    curves.push_back(e);
  }
  return curves;
}

// The claim of the optimal oracle: lower bound <= true minimum <= returned <= published greedy,
// and returned == minimum whenever the reported gap is 0.
void checkOracleClaims(const std::vector<std::vector<double>>& curves, uint64_t slots,
                       const OracleOptions& options, int& exactCases, int& hullSuboptimal,
                       const std::string& what) {
  const double best = exhaustiveMinimum(curves, slots);
  const double greedy = allocationError(curves, allocateOptimalGreedy(curves, slots));
  const double hull = allocationError(curves, allocateOptimalHull(curves, slots));
  const OracleAllocation a = allocateOptimal(curves, slots, options);
  expectValid(curves, a.k, slots);
  EXPECT_NEAR(a.error, allocationError(curves, a.k), 1e-12) << what;
  EXPECT_LE(a.lagrangianBound, best + 1e-12) << what;
  EXPECT_LE(a.lowerBound, best + 1e-12) << what;
  EXPECT_GE(a.error, best - 1e-12) << what;
  EXPECT_LE(a.error, greedy + 1e-12) << what;
  EXPECT_LE(a.error, hull + 1e-12) << what;
  EXPECT_GE(a.gap(), 0.0) << what;
  if (a.exact) {
    EXPECT_EQ(a.gap(), 0.0) << what;
    EXPECT_NEAR(a.error, best, 1e-12) << what;
    ++exactCases;
  }
  if (a.gap() == 0.0) {
    EXPECT_NEAR(a.error, best, 1e-12) << what;
  }
  hullSuboptimal += hull > best + 1e-9;
}

TEST(OptimalOracle, ExactOnRandomNonConvexCurves) {
  std::mt19937 rng(2024);
  int cases = 0, exact = 0, hullSuboptimal = 0, nonconvex = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const auto curves = randomCurves(rng, 2 + trial % 3, 5);
    uint64_t total = 0;
    for (const auto& e : curves) {
      total += e.size();
      nonconvex += !errorCurveIsConvex(e);
    }
    for (uint64_t slots = curves.size(); slots <= total; ++slots, ++cases)
      checkOracleClaims(curves, slots, {}, exact, hullSuboptimal,
                        "trial " + std::to_string(trial) + " slots " + std::to_string(slots));
  }
  EXPECT_GT(cases, 1000);
  EXPECT_GT(nonconvex, 500);
  EXPECT_GT(hullSuboptimal, 50);  // the hull alone is not optimal here ...
  EXPECT_EQ(exact, cases);        // ... the exact step always is, within its cell limit
}

TEST(OptimalOracle, WithoutTheExactStepStillBoundedAndNeverWorseThanGreedy) {
  std::mt19937 rng(77);
  OracleOptions noDp;
  noDp.maxDpCells = 0;
  int cases = 0, exact = 0, hullSuboptimal = 0, withGap = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto curves = randomCurves(rng, 3, 4);
    uint64_t total = 0;
    for (const auto& e : curves) total += e.size();
    for (uint64_t slots = curves.size(); slots <= total; ++slots, ++cases) {
      checkOracleClaims(curves, slots, noDp, exact, hullSuboptimal,
                        "trial " + std::to_string(trial) + " slots " + std::to_string(slots));
      withGap += allocateOptimal(curves, slots, noDp).gap() > 0.0;
    }
  }
  EXPECT_GT(cases, 500);
  EXPECT_GT(withGap, 50);  // the bound is reported, not hidden
}

TEST(OptimalOracle, ExactOnRealHybridAndKBufferCurves) {
  // curves from random pixels composited as the renderer does (8-bit colours, both rules)
  std::mt19937 rng(31);
  int cases = 0, exact = 0, hullSuboptimal = 0, nonconvex = 0;
  for (Compositing rule : {Compositing::Hybrid, Compositing::KBuffer})
    for (int trial = 0; trial < 150; ++trial) {
      std::vector<std::vector<double>> curves;
      uint64_t total = 0;
      for (int p = 0; p < 3; ++p) {
        const std::vector<FragmentNode> px = randomPixel(rng, 1 + (trial + 2 * p) % 6);
        curves.push_back(errorCurve(px.data(), static_cast<uint32_t>(px.size()),
                                    glm::vec3(0.9f, 0.8f, 1.0f), rule));
        nonconvex += !errorCurveIsConvex(curves.back());
        total += px.size();
      }
      for (uint64_t slots = curves.size(); slots <= total; ++slots, ++cases)
        checkOracleClaims(curves, slots, {}, exact, hullSuboptimal,
                          "trial " + std::to_string(trial) + " slots " + std::to_string(slots));
    }
  EXPECT_GT(cases, 500);
  EXPECT_GT(nonconvex, 0);  // real curves are not all convex
  EXPECT_EQ(exact, cases);
}

TEST(OptimalOracle, LargeFramesUseTheCoreAndStayWithinTheBudget) {
  // many pixels: the exhaustive search is out of reach, the bound and the budget are not
  std::mt19937 rng(5);
  const auto curves = randomCurves(rng, 20000, 12);
  uint64_t total = 0;
  for (const auto& e : curves) total += e.size();
  const uint64_t slots = curves.size() + (total - curves.size()) / 3;
  const OracleAllocation a = allocateOptimal(curves, slots);
  expectValid(curves, a.k, slots);
  EXPECT_TRUE(a.exact);
  EXPECT_STREQ(a.solver, "hull+dp");
  EXPECT_GT(a.corePixels, 0u);
  EXPECT_LT(a.corePixels, curves.size() / 2);  // reduced-cost fixing fixes most pixels
  EXPECT_LE(a.lagrangianBound, a.error);
  EXPECT_LE(a.error, allocationError(curves, allocateOptimalHull(curves, slots)) + 1e-9);
  EXPECT_LE(a.error, allocationError(curves, allocateOptimalGreedy(curves, slots)) + 1e-9);
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
    // under hybrid compositing a covered pixel may keep no slot (its tail alone, issue 28)
    EXPECT_LE(optimal.kMap[p], truth.depthComplexity[p]);
  }
  EXPECT_LE(sumK, slots);
  EXPECT_LE(optimal.stats.bytesUsed, 400000u);
  const double eOptimal = linearMse(optimal.image, truth.image);
  EXPECT_GT(eOptimal, 0.0);
  EXPECT_LT(eOptimal, linearMse(dynamic.image, truth.image));
  EXPECT_LT(eOptimal, linearMse(fill.image, truth.image));
  EXPECT_LT(linearMse(greedy.image, truth.image), linearMse(dynamic.image, truth.image));
  // the oracle's report: the proven minimum, never above the published greedy's error
  ASSERT_TRUE(optimal.stats.oracle.has_value());
  ASSERT_TRUE(greedy.stats.oracle.has_value());
  const OracleReport& report = *optimal.stats.oracle;
  EXPECT_TRUE(report.exact);
  EXPECT_EQ(report.gap(), 0.0);
  EXPECT_LE(report.lagrangianBound, report.error);
  EXPECT_LE(report.error, greedy.stats.oracle->error + 1e-12);
  EXPECT_LE(greedy.stats.oracle->lowerBound, report.error + 1e-12);
  EXPECT_GT(report.nonconvexPixels, 0u);  // real hybrid curves are not all convex
  EXPECT_FALSE(dynamic.stats.oracle.has_value());
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
