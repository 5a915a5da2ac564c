// Per-pixel linked lists with a fixed node pool (`linked-list`; Yang, Hensley, Gruen, Thibieroz,
// EGSR 2010; include/mfr/method/linked_list.hpp) on the CPU engine: without a budget (or with a
// pool that holds every fragment) it is the A-buffer, bit for bit; with a pool of known size on a
// constructed scene it admits the first fragments in primitive order (within the boundary
// triangle in scanline order, hand-computed below) and the captured and lost counts are exact;
// under hybrid compositing the turned-away fragments form the tail (closed form in double); the
// memory is the model's, to the byte, and never above the budget; the lists are the same for any
// number of threads; the image is draw-order independent while the pool holds everything and
// order dependent once it overflows; bad budgets and options are one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/color.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/compositing.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/scene/draw_order.hpp"
#include "mfr/scene/load.hpp"
#include "test_util.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr {
namespace {

constexpr int kSize = 16;
const glm::vec3 kBg(0.2f, 0.4f, 0.6f);

RenderOutput run(const RasterFrame& frame, const std::string& preset,
                 std::optional<uint64_t> budget, Compositing rule = Compositing::KBuffer) {
  MethodDesc m = methodPreset(preset).value();
  if (preset != "abuffer") m.compositing = rule;
  RenderOptions o;
  o.background = kBg;
  o.keepStores = true;
  o.budgetBytes = budget;
  auto out = render(frame, m, o);
  EXPECT_TRUE(out.ok()) << preset << ": " << (out.ok() ? "" : out.error().message);
  return std::move(out.value());
}

uint64_t poolBudget(uint64_t pixels, uint64_t nodes, bool hybrid = false) {
  return pixels * (4 + (hybrid ? 20 : 0)) + 4 + 12 * nodes;
}

// The constructed scene, 16 x 16 pixels, in primitive order:
//   0, 1  layer A: full screen at z = -1 (256 fragments over the two triangles)
//   2     triangle T: (8, 0), (16.25, 0), (8, 8.25) at z = -0.5; no pixel centre on an edge: it
//         covers x = 8 + X, y with X + y <= 7 (36 fragments), row 0 first (X = 0..7), then row 1
//   3, 4  rectangle C: x in [0, 8), y in [8, 16) at z = -0.25 (64 fragments)
// A pool of 256 + 10 nodes admits A whole, T's first 10 fragments in scanline order (row 0:
// x = 8..15; row 1: x = 8, 9) and nothing of C: 266 captured, 26 + 64 = 90 lost.
const glm::vec4 kA(0.9f, 0.2f, 0.1f, 0.5f), kT(0.1f, 0.8f, 0.3f, 0.6f), kC(0.2f, 0.3f, 0.9f, 0.7f);
constexpr uint64_t kAdmitted = 266, kLost = 90;

RasterFrame constructedFrame(int threads = 2) {
  std::vector<test::TestTriangle> tris =
      test::screenRect(-1, -1, kSize + 1, kSize + 1, kSize, -1.0f, kA);
  tris.push_back({test::screenPoint(8, 0, kSize, -0.5f), test::screenPoint(16.25, 0, kSize, -0.5f),
                  test::screenPoint(8, 8.25, kSize, -0.5f), kT});
  for (const test::TestTriangle& t : test::screenRect(0, 8, 8, 16, kSize, -0.25f, kC))
    tris.push_back(t);
  return std::move(
      *test::buildFrame(test::makeScene(tris), test::screenCamera(), kSize, kSize, threads));
}

bool inT(int x, int y) {
  return x >= 8 && (x - 8) + y <= 7;
}
bool inC(int x, int y) {
  return x < 8 && y >= 8;
}
bool tAdmitted(int x, int y) {
  return (y == 0 && x >= 8) || (y == 1 && (x == 8 || x == 9));
}

TEST(LinkedList, UnboundedEqualsTheABuffer) {
  for (const char* spec : {"procedural:hairball?strands=120", "procedural:bottles"}) {
    const Scene scene = loadScene(spec).value();
    const auto frame = test::buildFrame(scene, *scene.defaultCamera, 48, 40, 2);
    ASSERT_TRUE(frame);
    const RenderOutput ab = run(*frame, "abuffer", std::nullopt);
    const uint64_t n = ab.stats.fragmentsGenerated;
    // no budget: the pool is sum n(p); a budget whose pool exceeds it: the same image
    for (std::optional<uint64_t> budget :
         {std::optional<uint64_t>{}, std::optional<uint64_t>{poolBudget(48 * 40, n + 7)}}) {
      const RenderOutput ll = run(*frame, "linked-list", budget);
      EXPECT_EQ(encodeSrgb(ll.image).rgba, encodeSrgb(ab.image).rgba) << spec;
      EXPECT_EQ(ll.image.pixels, ab.image.pixels) << spec << ": linear values differ";
      EXPECT_EQ(test::capturedSets(ll), test::capturedSets(ab)) << spec;
      EXPECT_EQ(ll.stats.captured, n) << spec;
      EXPECT_EQ(ll.stats.lost, 0u) << spec;
      EXPECT_EQ(ll.stats.fragmentSlots, budget ? n + 7 : n) << spec;
      EXPECT_EQ(ll.kMap, ab.depthComplexity) << spec << ": k(p) is each list's length";
    }
  }
}

TEST(LinkedList, FullPoolAdmitsTheFirstFragmentsInPrimitiveOrder) {
  const RasterFrame frame = constructedFrame();
  const uint64_t pixels = kSize * kSize;
  const RenderOutput ab = run(frame, "abuffer", std::nullopt);
  ASSERT_EQ(ab.stats.fragmentsGenerated, 256u + 36u + 64u);
  const RenderOutput ll = run(frame, "linked-list", poolBudget(pixels, kAdmitted));
  EXPECT_EQ(ll.stats.fragmentSlots, kAdmitted);
  EXPECT_EQ(ll.stats.fragmentsGenerated, 356u);
  EXPECT_EQ(ll.stats.captured, kAdmitted);
  EXPECT_EQ(ll.stats.lost, kLost);
  const auto abSets = test::capturedSets(ab), llSets = test::capturedSets(ll);
  const float dA = nodeDepth(abSets[0].back());  // pixel 0: A alone
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const size_t p = static_cast<size_t>(y) * kSize + x;
      ASSERT_EQ(abSets[p].size(), 1u + inT(x, y) + inC(x, y)) << x << "," << y;
      // the A-buffer's nodes less those the pool turned away: all of C, T outside its first 10
      std::vector<FragmentNode> expected;
      for (FragmentNode n : abSets[p]) {
        const bool isA = nodeDepth(n) == dA;
        const bool isC = inC(x, y) && n == abSets[p].front();
        if (isA || (!isC && tAdmitted(x, y))) expected.push_back(n);
      }
      EXPECT_EQ(llSets[p], expected) << x << "," << y;
      EXPECT_EQ(ll.kMap[p], 1u + tAdmitted(x, y)) << x << "," << y;
      EXPECT_EQ(ll.image.pixels[p],
                compositeKBuffer(expected.data(), static_cast<uint32_t>(expected.size()), kBg))
          << x << "," << y;
    }
  // one node fewer: T's tenth fragment, (9, 1), is the one turned away
  const RenderOutput less = run(frame, "linked-list", poolBudget(pixels, kAdmitted - 1));
  EXPECT_EQ(less.stats.captured, kAdmitted - 1);
  EXPECT_EQ(less.kMap[1 * kSize + 9], 1u);
  EXPECT_EQ(less.kMap[1 * kSize + 8], 2u);
  // the 11 bytes short of a node buy nothing
  EXPECT_EQ(run(frame, "linked-list", poolBudget(pixels, kAdmitted) + 11).stats.captured,
            kAdmitted);
}

// Hybrid: the 90 turned-away fragments go to their pixels' tails; closed form in double:
// C = C_core + T_core (alpha_tail C_tail + (1 - alpha_tail) bg), C_tail = sum(a c) / sum(a),
// alpha_tail = 1 - (1 - sum(a) / t)^t.
TEST(LinkedList, HybridTailTakesWhatThePoolTurnsAway) {
  const RasterFrame frame = constructedFrame();
  const uint64_t pixels = kSize * kSize;
  const uint64_t budget = poolBudget(pixels, kAdmitted, true);
  const RenderOutput ll = run(frame, "linked-list", budget, Compositing::Hybrid);
  EXPECT_EQ(ll.stats.captured, kAdmitted);
  EXPECT_EQ(ll.stats.lost, kLost);  // (in the tail, not in a node)
  EXPECT_EQ(ll.stats.bytesUsed, budget);
  // each fragment's shaded colour as its node stores it (sRGB8, alpha8), read off the A-buffer's
  // sorted nodes: C (z = -0.25) before T (z = -0.5) before A (z = -1)
  const auto abSets = test::capturedSets(run(frame, "abuffer", std::nullopt));
  double worst = 0.0;
  int tailPixels = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const auto& nodes = abSets[static_cast<size_t>(y) * kSize + x];
      ASSERT_EQ(nodes.size(), 1u + inT(x, y) + inC(x, y));
      const auto linear = [&](size_t i) {
        return glm::dvec4(unpackFragmentColor(nodeColor(nodes[i])));
      };
      const glm::dvec4 a = linear(nodes.size() - 1), t = inT(x, y) ? linear(inC(x, y)) : a,
                       c = linear(0);
      std::vector<glm::dvec4> core, tail;  // core nearest first: T (z = -0.5) before A
      if (tAdmitted(x, y)) core.push_back(t);
      core.push_back(a);
      if (inT(x, y) && !tAdmitted(x, y)) tail.push_back(t);
      if (inC(x, y)) tail.push_back(c);
      glm::dvec3 color(0.0);
      double T = 1.0;
      for (const glm::dvec4& f : core) {
        color += T * f.a * glm::dvec3(f);
        T *= 1.0 - f.a;
      }
      glm::dvec3 behind(kBg);
      if (!tail.empty()) {
        glm::dvec3 sum(0.0);
        double sumA = 0.0;
        for (const glm::dvec4& f : tail) {
          sum += f.a * glm::dvec3(f);
          sumA += f.a;
        }
        const double n = static_cast<double>(tail.size());
        const double alphaTail = 1.0 - std::pow(1.0 - sumA / n, n);
        behind = alphaTail * (sum / sumA) + (1.0 - alphaTail) * behind;
        ++tailPixels;
      }
      color += T * behind;
      const glm::dvec3 got(ll.image.pixels[static_cast<size_t>(y) * kSize + x]);
      worst = std::max(worst, glm::length(got - color));
    }
  EXPECT_EQ(tailPixels, 26 + 64);
  EXPECT_LT(worst, 2e-6);
}

TEST(LinkedList, MemoryIsTheModelAndNeverAboveTheBudget) {
  const Scene scene = loadScene("procedural:hairball?strands=120").value();
  for (int w : {24, 40}) {
    const auto frame = test::buildFrame(scene, *scene.defaultCamera, w, 32, 2);
    ASSERT_TRUE(frame);
    const uint64_t pixels = static_cast<uint64_t>(w) * 32;
    for (Compositing rule : {Compositing::KBuffer, Compositing::Hybrid}) {
      const bool hybrid = rule == Compositing::Hybrid;
      for (uint64_t budget : {pixels * 40, pixels * 40 + 5, pixels * 64 + 11, uint64_t{1} << 20}) {
        const RenderOutput out = run(*frame, "linked-list", budget, rule);
        const uint64_t perPixel = 4 + (hybrid ? 20 : 0);
        const uint64_t nodes = (budget - pixels * perPixel - 4) / 12;  // F(M), by hand
        EXPECT_EQ(out.stats.fragmentSlots, nodes);
        EXPECT_EQ(out.stats.bytesUsed, pixels * perPixel + 4 + 12 * nodes);
        EXPECT_LE(out.stats.bytesUsed, budget);
        EXPECT_GT(out.stats.bytesUsed + 12, budget);  // the remainder buys no node
        EXPECT_EQ(out.stats.bytesByCategory.at("heads"), pixels * 4);
        EXPECT_EQ(out.stats.bytesByCategory.at("pool_counter"), 4u);
        EXPECT_EQ(out.stats.bytesByCategory.at("nodes"), nodes * 12);
        EXPECT_EQ(out.stats.bytesByCategory.count("tail"), hybrid ? 1u : 0u);
        EXPECT_EQ(out.stats.bytesByCategory.count("counters"), 0u);
        EXPECT_EQ(out.stats.captured, std::min(nodes, out.stats.fragmentsGenerated));
        EXPECT_EQ(out.stats.lost, out.stats.fragmentsGenerated - out.stats.captured);
        // measured: the pool and heads as the model charges them
        EXPECT_EQ(out.stats.bytesAllocatedByCategory.at("nodes"), nodes * 12);
        EXPECT_EQ(out.stats.bytesAllocatedByCategory.at("heads"), pixels * 4);
      }
    }
  }
}

// The lists (each pixel's nodes in list order), the image and the counts for 1, 2, 3 and 8
// workers, with an overflowing pool, both rules.
TEST(LinkedList, SameListsForAnyNumberOfThreads) {
  ::setenv("MFR_MAX_WORKERS", "8", 1);
  const Scene scene = loadScene("procedural:hairball?strands=250").value();
  for (Compositing rule : {Compositing::KBuffer, Compositing::Hybrid}) {
    std::optional<RenderOutput> reference;
    for (int threads : {1, 2, 3, 8}) {
      const auto frame = test::buildFrame(scene, *scene.defaultCamera, 80, 72, threads);
      ASSERT_TRUE(frame);
      const uint64_t budget = poolBudget(80 * 72, 9000, rule == Compositing::Hybrid);
      RenderOutput out = run(*frame, "linked-list", budget, rule);
      ASSERT_EQ(out.stats.captured, 9000u);
      ASSERT_GT(out.stats.lost, 1000u);
      if (!reference) {
        reference = std::move(out);
        continue;
      }
      EXPECT_EQ(out.nodes, reference->nodes) << threads << " threads: list order";
      EXPECT_EQ(out.counts, reference->counts) << threads;
      EXPECT_EQ(out.image.pixels, reference->image.pixels) << threads;
    }
  }
}

// Draw order: a pool that holds every fragment gives the same bits under another submission order
// (the resolve sorts by (depth, colour)); an overflowing pool admits the first fragments of the
// order given, so another order keeps another set (the same count).
TEST(LinkedList, DrawOrderMattersOnlyOnceThePoolOverflows) {
  const Scene scene = loadScene("procedural:hairball?strands=120").value();
  Scene shuffled = scene;
  shuffleDrawOrder(shuffled, 1234);
  const auto a = test::buildFrame(scene, *scene.defaultCamera, 40, 40, 2);
  const auto b = test::buildFrame(shuffled, *scene.defaultCamera, 40, 40, 2);
  ASSERT_TRUE(a && b);
  const RenderOutput ua = run(*a, "linked-list", std::nullopt),
                     ub = run(*b, "linked-list", std::nullopt);
  EXPECT_EQ(encodeSrgb(ua.image).rgba, encodeSrgb(ub.image).rgba);
  EXPECT_EQ(ua.image.pixels, ub.image.pixels);
  EXPECT_EQ(test::capturedSets(ua), test::capturedSets(ub));
  const uint64_t half = ua.stats.fragmentsGenerated / 2;
  const RenderOutput oa = run(*a, "linked-list", poolBudget(1600, half)),
                     ob = run(*b, "linked-list", poolBudget(1600, half));
  EXPECT_EQ(oa.stats.captured, half);
  EXPECT_EQ(ob.stats.captured, half);
  EXPECT_NE(test::capturedSets(oa), test::capturedSets(ob));
  EXPECT_NE(oa.image.pixels, ob.image.pixels);
}

TEST(LinkedList, BadBudgetsAndOptionsAreOneLineErrors) {
  const RasterFrame frame = constructedFrame();
  const uint64_t pixels = kSize * kSize;
  MethodDesc m = methodPreset("linked-list").value();
  for (uint64_t budget : {uint64_t{0}, pixels * 4 + 4 + 11}) {  // no room for one node
    RenderOptions o;
    o.budgetBytes = budget;
    auto out = render(frame, m, o);
    ASSERT_FALSE(out.ok()) << budget;
    EXPECT_NE(out.error().message.find("budget " + std::to_string(budget) + " B: too small"),
              std::string::npos)
        << out.error().message;
    EXPECT_EQ(out.error().message.find('\n'), std::string::npos);
  }
  RenderOptions one;
  one.budgetBytes = pixels * 4 + 4 + 12;  // a pool of one node
  auto single = render(frame, m, one);
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single->stats.captured, 1u);
  // no k, no occupancy culling: not a per-pixel k-buffer
  EXPECT_FALSE(methodPreset("linked-list+occupancy").ok());
  MethodOverrides k;
  k.k = 4;
  auto withK = makeMethod("linked-list", k);
  ASSERT_FALSE(withK.ok());
  EXPECT_NE(withK.error().message.find("does not apply to linked-list"), std::string::npos)
      << withK.error().message;
  // the store and allocation go together
  MethodDesc bad = m;
  bad.store = StoreChoice::MaxArray;
  RenderOptions o;
  o.budgetBytes = 1u << 20;
  EXPECT_FALSE(render(frame, bad, o).ok());
}

}  // namespace
}  // namespace mfr
