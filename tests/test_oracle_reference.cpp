// The optimal oracle's fast paths against the straightforward implementations they replace: the
// tile-local pre-pass against a whole-frame A-buffer, and the hull allocator (bucketed, chunked
// order) against sorting every hull segment, on scenes, random curves and awkward ties.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "mfr/cpu/optimal_oracle.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

// --- the straightforward references -------------------------------------------------------------

/// Every pixel's curve from a whole-frame A-buffer (its kept nodes, sorted).
std::vector<std::vector<double>> abufferCurves(const RasterFrame& frame, glm::vec3 background,
                                               Compositing rule, uint32_t firstK = 1) {
  RenderOptions exact;
  exact.keepStores = true;
  exact.background = background;
  const RenderOutput truth = render(frame, methodPreset("abuffer").value(), exact).value();
  std::vector<std::vector<double>> curves(frame.pixelCount());
  for (size_t p = 0; p < curves.size(); ++p) {
    std::vector<FragmentNode> px(
        truth.nodes.begin() + static_cast<std::ptrdiff_t>(truth.offsets[p]),
        truth.nodes.begin() + static_cast<std::ptrdiff_t>(truth.offsets[p] + truth.counts[p]));
    std::sort(px.begin(), px.end());
    curves[p] = errorCurve(px.data(), static_cast<uint32_t>(px.size()), background, rule, firstK);
  }
  return curves;
}

struct ReferenceHull {
  std::vector<uint32_t> k;
  double lambda = 0.0;
};

/// The hull allocator as first written: every hull segment in one stable sort by drop per slot.
/// Curves start at k = firstK (index k - firstK): every covered pixel starts there.
ReferenceHull referenceHull(const std::vector<std::vector<double>>& curves, uint64_t slots,
                            uint32_t firstK = 1) {
  ReferenceHull out;
  out.k.assign(curves.size(), 0);
  uint64_t used = 0;
  struct Segment {
    double drop;
    uint32_t pixel, from, to;
  };
  std::vector<Segment> segments;
  for (size_t p = 0; p < curves.size(); ++p) {
    const std::vector<double>& c = curves[p];
    if (c.empty()) continue;
    const auto e = [&](uint32_t k) { return c[k - firstK]; };
    out.k[p] = firstK;
    used += firstK;
    std::vector<uint32_t> hull;
    for (uint32_t x = firstK; x < firstK + c.size(); ++x) {
      while (hull.size() >= 2) {
        const uint32_t a = hull[hull.size() - 2], b = hull.back();
        if ((e(b) - e(a)) * (x - a) - (e(x) - e(a)) * (b - a) >= 0.0)
          hull.pop_back();
        else
          break;
      }
      hull.push_back(x);
    }
    for (size_t i = 1; i < hull.size(); ++i)
      segments.push_back({(e(hull[i - 1]) - e(hull[i])) / (hull[i] - hull[i - 1]),
                          static_cast<uint32_t>(p), hull[i - 1], hull[i]});
  }
  std::stable_sort(segments.begin(), segments.end(),
                   [](const Segment& a, const Segment& b) { return a.drop > b.drop; });
  bool critical = false;
  for (const Segment& s : segments) {
    if (out.k[s.pixel] != s.from) continue;
    if (used + (s.to - s.from) <= slots) {
      out.k[s.pixel] = s.to;
      used += s.to - s.from;
      continue;
    }
    if (!critical) {
      critical = true;
      out.lambda = std::max(0.0, s.drop);
    }
    if (used >= slots) break;
    uint32_t best = s.from;
    for (uint32_t x = s.from + 1; x <= s.from + (slots - used); ++x)
      if (curves[s.pixel][x - firstK] < curves[s.pixel][best - firstK]) best = x;
    used += best - s.from;
    out.k[s.pixel] = best;
  }
  return out;
}

/// The Lagrangian bound at the reference multiplier, as allocateOptimal reports it.
double referenceBound(const std::vector<std::vector<double>>& curves, uint64_t slots,
                      const ReferenceHull& hull, uint32_t firstK = 1) {
  double bound = -hull.lambda * static_cast<double>(slots);
  for (const std::vector<double>& e : curves) {
    if (e.empty()) continue;
    double m = std::numeric_limits<double>::infinity();
    for (uint32_t x = firstK; x < firstK + e.size(); ++x)
      m = std::min(m, e[x - firstK] + hull.lambda * x);
    bound += m;
  }
  return std::max(0.0, std::min(bound, allocationError(curves, hull.k, firstK)));
}

/// k and the multiplier (through the bound) of the fast allocator equal the reference's.
/// With firstK = 0 (curves from k = 0, hybrid's tail alone) the reference starts every pixel at
/// k = 0 itself, while the library shifts the problem to k + 1: the bound's sums then round
/// differently.
void expectSameAllocation(const std::vector<std::vector<double>>& curves, uint64_t slots,
                          uint64_t chunk, const std::string& what, uint32_t firstK = 1) {
  OracleOptions options;
  options.hullChunkSegments = chunk;
  options.firstK = firstK;
  const ReferenceHull ref = referenceHull(curves, slots, firstK);
  ASSERT_EQ(allocateOptimalHull(curves, slots, options), ref.k) << what;
  uint64_t values = 0, covered = 0;
  for (const auto& e : curves) {
    values += e.size();
    covered += !e.empty();
  }
  if (values - (firstK == 0 ? covered : 0) <= slots) return;  // all-fit: no multiplier
  const OracleAllocation a = allocateOptimal(curves, slots, options);
  const double bound = referenceBound(curves, slots, ref, firstK);
  if (firstK == 1) {
    EXPECT_EQ(a.lagrangianBound, bound) << what;
  } else {
    EXPECT_NEAR(a.lagrangianBound, bound, 1e-9 * std::fabs(bound) + 1e-300) << what;
  }
}

// --- tests --------------------------------------------------------------------------------------

TEST(OracleReference, TileLocalCurvesEqualTheWholeFrameABuffersForBothRules) {
  for (const char* source : {"procedural:hairball?strands=300", "procedural:layers?k=4&r=2"}) {
    auto scene = loadScene(source);
    ASSERT_TRUE(scene.ok()) << source;
    auto frame = RasterFrame::build(*scene, *scene->defaultCamera, RasterOptions{80, 64, 16, 2});
    ASSERT_TRUE(frame.ok()) << source;
    for (Compositing rule : {Compositing::Hybrid, Compositing::KBuffer}) {
      const glm::vec3 bg(0.2f, 0.3f, 0.4f);
      const auto fast = frameErrorCurves(*frame, bg, rule);
      ASSERT_TRUE(fast.ok()) << source;
      const auto ref = abufferCurves(*frame, bg, rule);
      EXPECT_EQ(fast->curves, ref) << source << " " << toString(rule);  // bit for bit
      uint64_t fragments = 0;
      for (const auto& e : ref) fragments += e.size();
      EXPECT_EQ(fast->fragments, fragments);
      EXPECT_GT(fragments, 1000u) << source;
    }
  }
}

/// A procedural:hairball view's error curves under `rule`, with their covered pixels and
/// fragments.
struct SceneCurves {
  std::vector<std::vector<double>> curves;
  uint64_t covered = 0, fragments = 0;
};
SceneCurves hairballCurves(int strands, int size, Compositing rule) {
  const Scene scene = loadScene("procedural:hairball?strands=" + std::to_string(strands)).value();
  const RasterFrame frame =
      RasterFrame::build(scene, *scene.defaultCamera, RasterOptions{size, size, 16, 2}).value();
  SceneCurves out;
  out.curves = frameErrorCurves(frame, glm::vec3(1.0f), rule).value().curves;
  for (const auto& e : out.curves) {
    out.covered += !e.empty();
    out.fragments += e.size();
  }
  return out;
}

TEST(OracleReference, HullAllocationEqualsSortingEverySegmentOnSceneCurves) {
  for (Compositing rule : {Compositing::Hybrid, Compositing::KBuffer}) {
    const auto [curves, covered, fragments] = hairballCurves(300, 96, rule);
    for (double share : {0.0, 0.05, 0.3, 0.7, 0.99, 1.0})
      for (uint64_t chunk : {uint64_t{1}, uint64_t{64}, uint64_t{1} << 20}) {
        const uint64_t slots = covered + static_cast<uint64_t>(share * (fragments - covered));
        expectSameAllocation(curves, slots, chunk,
                             std::string(toString(rule)) + " slots " + std::to_string(slots) +
                                 " chunk " + std::to_string(chunk));
      }
  }
}

// The allocators' per-pixel passes run on the caller's task arena (workers fold ranges of pixels
// and their states combine in any order): one worker and four give the same bits.
TEST(OracleReference, AllocationIsTheSameOnOneWorkerAndOnFour) {
  const tbb::global_control four(tbb::global_control::max_allowed_parallelism, 4);
  for (Compositing rule : {Compositing::Hybrid, Compositing::KBuffer}) {
    const auto [curves, covered, fragments] = hairballCurves(600, 256, rule);
    // 16 tasks of 4096 pixels (the allocator's grain), most of them covered
    ASSERT_EQ(curves.size(), 16u * 4096u);
    ASSERT_GT(covered, curves.size() / 3);
    for (double share : {0.1, 0.5}) {
      const uint64_t slots = covered + static_cast<uint64_t>(share * (fragments - covered));
      OracleAllocation one, many;
      std::vector<uint32_t> hullOne, hullMany;
      tbb::task_arena(1).execute([&] {
        one = allocateOptimal(curves, slots);
        hullOne = allocateOptimalHull(curves, slots);
      });
      tbb::task_arena(4).execute([&] {
        many = allocateOptimal(curves, slots);
        hullMany = allocateOptimalHull(curves, slots);
      });
      const std::string what = std::string(toString(rule)) + " share " + std::to_string(share);
      EXPECT_EQ(one.k, many.k) << what;
      EXPECT_EQ(hullOne, hullMany) << what;
      EXPECT_EQ(one.error, many.error) << what;  // bit for bit
      EXPECT_EQ(one.lowerBound, many.lowerBound) << what;
      EXPECT_EQ(one.lagrangianBound, many.lagrangianBound) << what;
      EXPECT_EQ(one.nonconvexPixels, many.nonconvexPixels) << what;
      EXPECT_EQ(one.corePixels, many.corePixels) << what;
      EXPECT_STREQ(one.solver, many.solver) << what;
      expectSameAllocation(curves, slots, 64, what);  // and the reference's
    }
  }
}

TEST(OracleReference, HullAllocationEqualsSortingEverySegmentOnTiesAndDeadEnds) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<std::vector<double>> curves;
    for (int p = 0; p < 300; ++p) {
      const uint32_t n = static_cast<uint32_t>(rng() % 9);  // empty pixels too
      std::vector<double> e(n, 0.0);
      switch (trial % 4) {
        case 0:  // random, mostly non-convex
          for (uint32_t i = 0; i + 1 < n; ++i) e[i] = u(rng) * std::pow(10.0, -6.0 * u(rng));
          break;
        case 1:  // few distinct values: many equal drops across pixels
          for (uint32_t i = 0; i + 1 < n; ++i)
            e[i] = static_cast<double>((n - 1 - i) * (rng() % 3));
          break;
        case 2:  // flat then 0: one segment costing n - 1, partial buys that gain nothing
          for (uint32_t i = 0; i + 1 < n; ++i) e[i] = 0.5 + (rng() % 4);
          break;
        default:  // zero curves (opaque nearest fragment): drops of 0
          break;
      }
      curves.push_back(e);
    }
    uint64_t covered = 0, fragments = 0;
    for (const auto& e : curves) {
      covered += !e.empty();
      fragments += e.size();
    }
    for (uint64_t slots = covered; slots <= fragments + 2; slots += 1 + (fragments - covered) / 23)
      for (uint64_t chunk : {uint64_t{1}, uint64_t{7}, uint64_t{1} << 20})
        expectSameAllocation(curves, slots, chunk,
                             "trial " + std::to_string(trial) + " slots " + std::to_string(slots) +
                                 " chunk " + std::to_string(chunk));
    // the same curves read from k = 0 (issue 28: a pixel may keep no slot), from no slot up
    for (uint64_t slots = 0; slots <= fragments + 2; slots += 1 + fragments / 23)
      for (uint64_t chunk : {uint64_t{1}, uint64_t{1} << 20})
        expectSameAllocation(curves, slots, chunk,
                             "from k = 0, trial " + std::to_string(trial) + " slots " +
                                 std::to_string(slots) + " chunk " + std::to_string(chunk),
                             0);
  }
}

TEST(OracleReference, OptimalPresetKeepsItsAllocationOnScenes) {
  // the render's k(p) is the allocation of the reference curves and hull, through the same
  // reduced-cost step: compared through the error it reaches and the bound it proves
  auto scene = loadScene("procedural:hairball?strands=300");
  ASSERT_TRUE(scene.ok());
  auto frame = RasterFrame::build(*scene, *scene->defaultCamera, RasterOptions{96, 96, 16, 2});
  ASSERT_TRUE(frame.ok());
  for (Compositing rule : {Compositing::Hybrid, Compositing::KBuffer})
    for (uint64_t budget : {400000u, 550000u, 900000u}) {
      MethodDesc m = methodPreset("optimal").value();
      m.compositing = rule;
      RenderOptions o;
      o.budgetBytes = budget;
      auto rendered = render(*frame, m, o);
      ASSERT_TRUE(rendered.ok()) << budget << ": " << rendered.error().message;
      const RenderOutput& out = rendered.value();
      ASSERT_TRUE(out.stats.oracle.has_value());
      // under hybrid compositing the curves start at k = 0 (the tail alone, issue 28)
      const uint32_t firstK = rule == Compositing::Hybrid ? 0 : 1;
      const auto curves = abufferCurves(*frame, o.background, rule, firstK);
      const uint64_t slots = MemoryModel::of(m).fragmentSlots(budget, frame->pixelCount());
      const ReferenceHull ref = referenceHull(curves, slots, firstK);
      const double bound = referenceBound(curves, slots, ref, firstK);
      if (firstK == 1) {
        EXPECT_EQ(out.stats.oracle->lagrangianBound, bound) << budget;
      } else {  // the oracle sums lambda (k + 1) over one more slot per pixel: rounding differs
        EXPECT_NEAR(out.stats.oracle->lagrangianBound, bound, 1e-9 * bound) << budget;
      }
      EXPECT_LE(out.stats.oracle->error, allocationError(curves, ref.k, firstK)) << budget;
      std::vector<uint32_t> k(out.kMap.begin(), out.kMap.end());
      for (size_t p = 0; p < k.size(); ++p) k[p] = std::min(k[p], out.depthComplexity[p]);
      EXPECT_DOUBLE_EQ(allocationError(curves, k, firstK), out.stats.oracle->error) << budget;
    }
}

}  // namespace
}  // namespace mfr
