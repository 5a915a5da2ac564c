// Issue 28 item 1: under hybrid compositing a pixel without a slot, k(p) = 0, is composited from
// its order-independent tail alone, so every allocating preset takes budgets down to its
// per-pixel words; under kbuffer compositing one node per covered pixel stays the floor, and the
// message says why. Expectations are computed here, independently of the library: the tail-only
// colours from the formula of hybrid transparency (Maule et al. 2013, DHOIT sec. 3.3) over the
// shaded, quantised fragments of three known quads; the allocators' minima by exhaustive search.
#include <gtest/gtest.h>

#include <functional>
#include <random>

#include "mfr/core/color.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/dkb_curve.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "reference_shading.hpp"
#include "test_util.hpp"

namespace mfr {
namespace {

constexpr int kSize = 32;

// the presets that allocate per pixel from a count pass (issue 28: kplus-dynamic, vkb*, dkb*,
// optimal*; kplus-sb's counted k too)
const char* const kAllocating[] = {"kplus-sb", "kplus-dynamic", "vkb",     "vkb-fill",      "dkb",
                                   "dkb-fill", "dkb-curve",     "optimal", "optimal-greedy"};

struct Quad {
  double x0, y0, x1, y1;  // pixel rectangle (edges on whole pixels: no centre on an edge)
  float z;
  glm::vec4 color;
};

// red nearest, green, blue farthest; overlaps give pixels with 1, 2 and 3 fragments
const Quad kQuads[] = {
    {2, 2, 20, 20, 0.0f, {1.0f, 0.1f, 0.1f, 0.5f}},
    {10, 6, 28, 24, -0.2f, {0.1f, 1.0f, 0.2f, 0.6f}},
    {6, 14, 26, 30, -0.4f, {0.2f, 0.3f, 1.0f, 0.4f}},
};

Scene quadScene() {
  std::vector<test::TestTriangle> triangles;
  for (const Quad& q : kQuads)
    for (const test::TestTriangle& t :
         test::screenRect(q.x0, q.y0, q.x1, q.y1, kSize, q.z, q.color))
      triangles.push_back(t);
  return test::makeScene(triangles);
}

const RasterFrame& quadFrame() {
  static const Scene scene = quadScene();
  static const RasterFrame frame =
      RasterFrame::build(scene, test::screenCamera(), RasterOptions{kSize, kSize, 16, 2}).value();
  return frame;
}

// a quad's fragment at pixel (x, y) as the raster shades and stores it: base x (0.2 + 0.8 |n.v|)
// to sRGB8, alpha to 8 bits; linear colour and alpha
struct Layer {
  glm::dvec3 color;
  double alpha;
};
Layer shadedLayer(const Quad& q, int x, int y) {
  const double light = 0.2 + 0.8 * test::refHeadlightCosine(x, y, kSize, kSize, 90.0);
  Layer l;
  for (int c = 0; c < 3; ++c)
    l.color[c] =
        test::refSrgbDecode(std::round(test::refSrgbEncode(q.color[c] * light) * 255.0) / 255.0);
  l.alpha = std::round(q.color.a * 255.0) / 255.0;
  return l;
}

// the quads covering pixel (x, y), nearest first (kQuads is in depth order)
std::vector<Layer> layersAt(int x, int y) {
  std::vector<Layer> layers;
  for (const Quad& q : kQuads)
    if (x + 0.5 > q.x0 && x + 0.5 < q.x1 && y + 0.5 > q.y0 && y + 0.5 < q.y1)
      layers.push_back(shadedLayer(q, x, y));
  return layers;
}

// hybrid transparency with no core: C_tail = sum(a c) / sum(a), a_tail = 1 - (1 - sum(a) / t)^t
glm::dvec3 tailOnly(const std::vector<Layer>& layers, glm::dvec3 bg) {
  if (layers.empty()) return bg;
  glm::dvec3 sum(0.0);
  double alphaSum = 0.0;
  for (const Layer& l : layers) {
    sum += l.color * l.alpha;
    alphaSum += l.alpha;
  }
  const double t = static_cast<double>(layers.size());
  const double alphaTail = 1.0 - std::pow(1.0 - alphaSum / t, t);
  return alphaTail * (sum / alphaSum) + (1.0 - alphaTail) * bg;
}

// every layer composited front to back (the exact image)
glm::dvec3 exact(const std::vector<Layer>& layers, glm::dvec3 bg) {
  glm::dvec3 c(0.0);
  double T = 1.0;
  for (const Layer& l : layers) {
    c += T * l.alpha * l.color;
    T *= 1.0 - l.alpha;
  }
  return c + T * bg;
}

MethodDesc hybridPreset(const std::string& name, Compositing rule = Compositing::Hybrid) {
  MethodDesc m = methodPreset(name).value();
  m.compositing = rule;
  return m;
}

uint64_t overhead(const MethodDesc& m) {
  return MemoryModel::of(m).overhead(static_cast<uint64_t>(kSize) * kSize);
}

TEST(TailOnly, TheQuadSceneHasPixelsWithOneTwoAndThreeFragments) {
  const std::vector<uint32_t> n = countFragments(quadFrame());
  int seen[4] = {0, 0, 0, 0};
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const size_t layers = layersAt(x, y).size();
      ASSERT_EQ(n[static_cast<size_t>(y) * kSize + x], layers) << x << "," << y;
      ++seen[layers];
    }
  for (int count : seen) EXPECT_GT(count, 0);
}

TEST(TailOnly, EveryAllocatingPresetRunsAtItsPerPixelWordsWithEveryPixelFromItsTail) {
  const glm::dvec3 bg(1.0);
  for (const char* name : kAllocating) {
    const MethodDesc m = hybridPreset(name);
    RenderOptions o;
    o.background = glm::vec3(bg);
    o.budgetBytes = overhead(m);  // the floor: no node at all
    auto out = render(quadFrame(), m, o);
    ASSERT_TRUE(out.ok()) << name << ": " << out.error().message;
    EXPECT_LE(out->stats.bytesUsed, *o.budgetBytes) << name;
    EXPECT_EQ(out->stats.fragmentSlots, 0u) << name;
    EXPECT_EQ(out->stats.captured, 0u) << name;
    double largestGap = 0.0;  // how far tail-only is from the exact image (the test can fail)
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const size_t p = static_cast<size_t>(y) * kSize + x;
        EXPECT_EQ(out->kMap[p], 0u) << name << " " << x << "," << y;
        const std::vector<Layer> layers = layersAt(x, y);
        const glm::dvec3 want = tailOnly(layers, bg);
        const glm::vec3 got = out->image.pixels[p];
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(got[c], want[c], 2e-5) << name << " pixel " << x << "," << y << " c" << c;
        largestGap = std::max(largestGap, glm::length(exact(layers, bg) - want));
      }
    EXPECT_GT(largestGap, 0.05) << "tail-only should differ from the exact image somewhere";
  }
}

TEST(TailOnly, OneByteBelowThePerPixelWordsIsRefusedNamingThatFloor) {
  for (const char* name : kAllocating) {
    const MethodDesc m = hybridPreset(name);
    const uint64_t floor = overhead(m);
    RenderOptions o;
    o.budgetBytes = floor - 1;
    auto out = render(quadFrame(), m, o);
    ASSERT_FALSE(out.ok()) << name;
    const std::string& message = out.error().message;
    EXPECT_NE(message.find("budget " + std::to_string(floor - 1) + " B"), std::string::npos)
        << message;
    EXPECT_NE(message.find(std::to_string(floor) + " B"), std::string::npos) << message;
    EXPECT_NE(message.find("hybrid"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(TailOnly, KBufferCompositingStillNeedsOneNodePerCoveredPixelAndSaysWhy) {
  const std::vector<uint32_t> n = countFragments(quadFrame());
  uint64_t covered = 0;
  for (uint32_t c : n) covered += c > 0;
  for (const char* name : kAllocating) {
    const MethodDesc m = hybridPreset(name, Compositing::KBuffer);
    const uint64_t needed = overhead(m) + 8 * covered;
    RenderOptions o;
    o.budgetBytes = needed - 1;
    auto refused = render(quadFrame(), m, o);
    ASSERT_FALSE(refused.ok()) << name;
    const std::string& message = refused.error().message;
    EXPECT_NE(message.find("needs " + std::to_string(needed) + " B"), std::string::npos) << message;
    EXPECT_NE(message.find("kbuffer compositing keeps no tail"), std::string::npos) << message;
    EXPECT_NE(message.find("would lose all its fragments"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    // the floor itself runs, every covered pixel with a slot (but under the papers' importance
    // rule, floor(P(p) F(M)), which may give a pixel none)
    o.budgetBytes = needed;
    auto out = render(quadFrame(), m, o);
    ASSERT_TRUE(out.ok()) << name << ": " << out.error().message;
    EXPECT_LE(out->stats.bytesUsed, needed) << name;
    const bool papersImportance =
        m.allocation == AllocationPolicy::Importance && !m.fillUnusedSlots;
    for (size_t p = 0; p < n.size(); ++p)
      if (n[p] > 0 && !papersImportance) {
        EXPECT_GE(out->kMap[p], 1u) << name << " pixel " << p;
      }
  }
}

TEST(TailOnly, RelativeSharesBelowOneNodePerCoveredPixelResolveUnderHybridOnly) {
  const std::vector<uint32_t> n = countFragments(quadFrame());
  const FrameCounts counts = FrameCounts::of(n);
  ASSERT_GT(counts.coveredPixels, counts.fragments / 4) << "the shares below need the floor";
  for (const char* name : kAllocating) {
    const MethodDesc hybrid = hybridPreset(name);
    const MemoryModel memory = MemoryModel::of(hybrid);
    // 10% of the A-buffer's node bytes: fewer nodes than covered pixels
    const uint64_t nodeBytes = 8 * counts.fragments / 10;
    ASSERT_LT(nodeBytes / 8, counts.coveredPixels);
    auto bytes = resolveBudget(BudgetSpec::relative(10.0), hybrid, memory, counts, "32x32");
    ASSERT_TRUE(bytes.ok()) << name << ": " << bytes.error().message;
    EXPECT_EQ(*bytes, overhead(hybrid) + nodeBytes) << name;
    EXPECT_EQ(smallestWorkingPercent(hybrid, memory, counts), 0.0) << name;
    const MethodDesc kbuffer = hybridPreset(name, Compositing::KBuffer);
    auto refused = resolveBudget(BudgetSpec::relative(10.0), kbuffer, MemoryModel::of(kbuffer),
                                 counts, "32x32");
    ASSERT_FALSE(refused.ok()) << name;
    EXPECT_NE(refused.error().message.find("keeps no tail"), std::string::npos)
        << refused.error().message;
    // and the hybrid share renders within its bytes
    RenderOptions o;
    o.budgetBytes = *bytes;
    auto out = render(quadFrame(), hybrid, o);
    ASSERT_TRUE(out.ok()) << name << ": " << out.error().message;
    EXPECT_LE(out->stats.bytesUsed, *bytes) << name;
    EXPECT_LE(out->stats.fragmentSlots, nodeBytes / 8) << name;
  }
}

TEST(TailOnly, OptimalErrorNeverGrowsWithTheBudgetFromThePerPixelWordsUp) {
  const glm::dvec3 bg(1.0);
  const std::vector<uint32_t> n = countFragments(quadFrame());
  uint64_t fragments = 0;
  double tailOnlyError = 0.0;  // sum over pixels of |exact - tail only|^2, by hand
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const std::vector<Layer> layers = layersAt(x, y);
      fragments += layers.size();
      const glm::dvec3 d = exact(layers, bg) - tailOnly(layers, bg);
      tailOnlyError += glm::dot(d, d);
    }
  ASSERT_GT(tailOnlyError, 0.0);
  for (const char* name : {"optimal", "optimal-greedy"}) {
    const MethodDesc m = hybridPreset(name);
    double previous = INFINITY;
    for (uint64_t slots = 0; slots <= fragments; slots += 1 + slots / 3) {
      RenderOptions o;
      o.background = glm::vec3(bg);
      o.budgetBytes = overhead(m) + 8 * slots;
      auto out = render(quadFrame(), m, o);
      ASSERT_TRUE(out.ok()) << name << " " << slots << ": " << out.error().message;
      EXPECT_LE(out->stats.bytesUsed, *o.budgetBytes) << name << " " << slots;
      EXPECT_LE(out->stats.fragmentSlots, slots) << name;
      ASSERT_TRUE(out->stats.oracle.has_value());
      const double error = out->stats.oracle->error;
      EXPECT_LE(error, previous + 1e-12) << name << " slots " << slots;
      if (slots == 0) {
        // (the library's shading differs from the reference's in the last float bits)
        EXPECT_NEAR(error, tailOnlyError, 1e-3 * tailOnlyError) << name;
      }
      previous = error;
    }
    RenderOptions all;
    all.budgetBytes = overhead(m) + 8 * fragments;
    EXPECT_EQ(render(quadFrame(), m, all)->stats.oracle->error, 0.0) << name;
  }
}

// exhaustive minimum of sum err over k(p) in [0, n(p)] (curves from k = 0), sum k <= slots
double exhaustiveFromZero(const std::vector<std::vector<double>>& curves, uint64_t slots) {
  double best = INFINITY;
  std::function<void(size_t, uint64_t, double)> visit = [&](size_t p, uint64_t used, double e) {
    if (used > slots) return;
    if (p == curves.size()) {
      best = std::min(best, e);
      return;
    }
    for (uint32_t k = 0; k < curves[p].size(); ++k) visit(p + 1, used + k, e + curves[p][k]);
  };
  visit(0, 0, 0.0);
  return best;
}

TEST(TailOnly, OracleFromZeroMatchesHandWorkedMinima) {
  // pixel A: err(0..2) = 9, 1, 0; pixel B: 4, 3, 0. By hand: 0 slots 13; 1 slot A = 1: 5;
  // 2 slots 4 (A = 2, or A = B = 1); 3 slots A = 1, B = 2: 1; 4 slots 0
  const std::vector<std::vector<double>> curves = {{9, 1, 0}, {4, 3, 0}, {}};
  OracleOptions options;
  options.firstK = 0;
  const double want[] = {13, 5, 4, 1, 0};
  for (uint64_t slots = 0; slots <= 4; ++slots) {
    const OracleAllocation a = allocateOptimal(curves, slots, options);
    EXPECT_EQ(a.error, want[slots]) << slots;
    EXPECT_EQ(a.k[2], 0u);
    EXPECT_LE(a.k[0] + a.k[1], slots);
    EXPECT_EQ(allocationError(curves, a.k, 0), a.error);
  }
  EXPECT_EQ(allocateOptimal(curves, 0, options).k, (std::vector<uint32_t>{0, 0, 0}));
  EXPECT_EQ(allocateOptimal(curves, 1, options).k, (std::vector<uint32_t>{1, 0, 0}));
  EXPECT_EQ(allocateOptimal(curves, 3, options).k, (std::vector<uint32_t>{1, 2, 0}));
}

TEST(TailOnly, OracleFromZeroEqualsExhaustiveSearchOnRandomHybridCurves) {
  std::mt19937 rng(28);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<std::vector<double>> curves;
    uint64_t fragments = 0;
    for (int p = 0; p < 5; ++p) {
      const uint32_t n = rng() % 5;  // 0..4 fragments
      std::vector<FragmentNode> nodes;
      for (uint32_t i = 0; i < n; ++i)
        nodes.push_back(
            makeNode(u(rng), packFragmentColor({u(rng), u(rng), u(rng)}, 0.1f + 0.8f * u(rng))));
      std::sort(nodes.begin(), nodes.end());
      curves.push_back(errorCurve(nodes.data(), n, glm::vec3(1.0f), Compositing::Hybrid, 0));
      ASSERT_EQ(curves.back().size(), n == 0 ? 0u : n + 1);
      fragments += n;
    }
    OracleOptions options;
    options.firstK = 0;
    for (uint64_t slots = 0; slots <= fragments; ++slots) {
      const OracleAllocation a = allocateOptimal(curves, slots, options);
      const double best = exhaustiveFromZero(curves, slots);
      EXPECT_NEAR(a.error, best, 1e-12 + 1e-9 * best) << "trial " << trial << " slots " << slots;
      uint64_t used = 0;
      for (size_t p = 0; p < curves.size(); ++p) {
        EXPECT_LE(a.k[p] + 1, std::max<size_t>(curves[p].size(), 1));
        used += a.k[p];
      }
      EXPECT_LE(used, slots);
    }
  }
}

TEST(TailOnly, OnePixelOfOneFragmentIsExactFromItsTail) {
  // t = 1: C_tail = c, a_tail = a, so the tail alone is the exact over: err(0) = 0
  const FragmentNode node = makeNode(0.5f, packFragmentColor({0.8f, 0.2f, 0.4f}, 0.7f));
  const std::vector<double> e = errorCurve(&node, 1, glm::vec3(1.0f), Compositing::Hybrid, 0);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NEAR(e[0], 0.0, 1e-15);
  EXPECT_EQ(e[1], 0.0);
}

TEST(TailOnly, AOneFragmentTailIsExactSoTheLastFragmentNeedsNoSlot) {
  // with k = n - 1 the tail holds one fragment: C_tail = c, a_tail = 1 - (1 - a)^1 = a, the over
  // of that fragment: err(n - 1) = 0 on every random pixel (and err(n - 2) > 0 somewhere)
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double largestBefore = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const uint32_t n = 2 + rng() % 6;
    std::vector<FragmentNode> nodes;
    for (uint32_t i = 0; i < n; ++i)
      nodes.push_back(
          makeNode(u(rng), packFragmentColor({u(rng), u(rng), u(rng)}, 0.1f + 0.8f * u(rng))));
    std::sort(nodes.begin(), nodes.end());
    const std::vector<double> e =
        errorCurve(nodes.data(), n, glm::vec3(1.0f), Compositing::Hybrid, 0);
    EXPECT_NEAR(e[n - 1], 0.0, 1e-24) << trial;
    largestBefore = std::max(largestBefore, e[n - 2]);
  }
  EXPECT_GT(largestBefore, 1e-3);
}

TEST(TailOnly, FillVariantsGiveAPixelAtMostNMinusOneSlotsUnderHybrid) {
  const glm::dvec3 bg(1.0);
  const std::vector<uint32_t> n = countFragments(quadFrame());
  uint64_t useful = 0, covered = 0;
  for (uint32_t c : n) {
    useful += c > 0 ? c - 1 : 0;
    covered += c > 0;
  }
  for (const char* name : {"vkb-fill", "dkb-fill"}) {
    const MethodDesc m = hybridPreset(name);
    RenderOptions o;
    o.background = glm::vec3(bg);
    o.budgetBytes = overhead(m) + 8 * useful;  // exactly n(p) - 1 for every pixel
    auto out = render(quadFrame(), m, o);
    ASSERT_TRUE(out.ok()) << name << ": " << out.error().message;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const size_t p = static_cast<size_t>(y) * kSize + x;
        ASSERT_EQ(out->kMap[p], n[p] > 0 ? n[p] - 1 : 0) << name << " " << x << "," << y;
        const glm::dvec3 want = exact(layersAt(x, y), bg);  // a one-fragment tail is exact
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(out->image.pixels[p][c], want[c], 2e-5) << name;
      }
    // under kbuffer compositing the same budget (here below one node per covered pixel: the
    // scene has more pixels of one fragment than extra fragments) is refused
    ASSERT_LT(useful, covered);
    o.budgetBytes = overhead(hybridPreset(name, Compositing::KBuffer)) + 8 * useful;
    EXPECT_FALSE(render(quadFrame(), hybridPreset(name, Compositing::KBuffer), o).ok()) << name;
  }
}

TEST(TailOnly, PredictedCurvesMayLeaveAPixelWithoutASlotUnderHybrid) {
  // two pixels of 3 fragments, curves from k = 0 (the hybrid model's, on its log scale): drops
  // 0.5, 0.1 (pixel 0) and 0.2, 0.1 (pixel 1); err(2) = err(3) = 0
  std::vector<float> predictions(2 * kCurveOutputs, 0.0f);
  predictions[0] = curveLogUnit(0.5);
  predictions[1] = curveLogUnit(0.1);
  predictions[kCurveOutputs] = curveLogUnit(0.2);
  predictions[kCurveOutputs + 1] = curveLogUnit(0.1);
  const std::vector<uint32_t> n = {3, 3};
  EXPECT_EQ(allocateByPredictedCurves(predictions, n, 0, 0), (std::vector<uint32_t>{0, 0}));
  // the tail-only error is predicted: pixel 0 gains 0.5 from its first slot, pixel 1 0.2
  EXPECT_EQ(allocateByPredictedCurves(predictions, n, 1, 0), (std::vector<uint32_t>{1, 0}));
  EXPECT_EQ(allocateByPredictedCurves(predictions, n, 2, 0), (std::vector<uint32_t>{1, 1}));
  // a third fragment's slot gains nothing (a tail of one fragment is exact): 4 slots serve both
  // pixels' gains, and slots beyond them fill up to n(p)
  EXPECT_EQ(allocateByPredictedCurves(predictions, n, 4, 0), (std::vector<uint32_t>{2, 2}));
  EXPECT_EQ(allocateByPredictedCurves(predictions, n, 6, 0), (std::vector<uint32_t>{3, 3}));
}

}  // namespace
}  // namespace mfr
