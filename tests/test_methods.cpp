// The k-buffer family through the whole pipeline (count -> allocate -> [occupancy] -> capture ->
// resolve), checked against the exact A-buffer of the same frame: with k at least the depth
// complexity every preset reproduces the A-buffer image byte for byte; with a smaller k every
// preset keeps the k(p) nearest nodes of each pixel; the hybrid resolve follows DHOIT's formula;
// the capture counters add up; memory follows the documented layout and stays within the budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mfr/cpu/render.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/scene/load.hpp"
#include "test_util.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr {
namespace {

using test::boundedPresets;
using test::capturedSets;
using test::modeName;
using test::presetWithK;
using test::runMethod;

constexpr CaptureMode kModes[] = {CaptureMode::TileOwned, CaptureMode::FragmentParallel};
constexpr Compositing kCompositing[] = {Compositing::KBuffer, Compositing::Hybrid};
const glm::vec3 kBackground(0.2f, 0.4f, 0.6f);

// One frame and its exact A-buffer: the reference every bounded method is compared with.
struct Case {
  std::string name;
  RasterFrame frame;
  RenderOutput abuffer;
  std::vector<std::vector<FragmentNode>> lists;  // per pixel, sorted: the ground truth
  uint32_t maxN = 0;
};

// Hand-made: full-screen layers with equal depths (ties broken by colour), layers equal in depth
// and colour, and a partial layer, submitted in no particular order.
Scene tiesScene(int size) {
  const glm::vec4 red(1, 0, 0, 0.4f), blue(0, 0, 1, 0.4f), green(0, 1, 0, 0.6f);
  std::vector<test::TestTriangle> tris;
  auto add = [&](double x0, double y0, double x1, double y1, float z, glm::vec4 c) {
    const auto r = test::screenRect(x0, y0, x1, y1, size, z, c);
    tris.insert(tris.end(), r.begin(), r.end());
  };
  add(-1, -1, size + 1, size + 1, -1.0f, red);
  add(-1, -1, size + 1, size + 1, -0.5f, green);
  add(-1, -1, size + 1, size + 1, -1.0f, blue);
  add(2, 2, size - 3, size - 5, -0.75f, green);
  add(-1, -1, size + 1, size + 1, -1.0f, red);  // equal to the first in depth and colour
  add(-1, -1, size + 1, size + 1, -0.5f, green);
  add(-1, -1, size + 1, size + 1, -2.0f, blue);
  return test::makeScene(tris);
}

Case prepare(const std::string& name, const Scene& scene, const Camera& camera, int w, int h) {
  Case c{name, std::move(*test::buildFrame(scene, camera, w, h, 2)), {}, {}, 0};
  RenderOptions options;
  options.keepStores = true;
  options.background = kBackground;
  auto out = render(c.frame, methodPreset("abuffer").value(), options);
  EXPECT_TRUE(out.ok());
  c.abuffer = std::move(out.value());
  c.lists = capturedSets(c.abuffer);
  c.maxN = c.abuffer.stats.maxDepthComplexity.value();
  return c;
}

Scene loadOrDie(const std::string& spec) {
  auto s = loadScene(spec);
  EXPECT_TRUE(s.ok()) << spec;
  return std::move(s.value());
}

const std::vector<Case>& cases() {
  static const std::vector<Case> all = [] {
    std::vector<Case> v;
    const Scene hair = loadOrDie("procedural:hairball?strands=150");
    v.push_back(prepare("hairball", hair, *hair.defaultCamera, 96, 96));
    const Scene layers = loadOrDie("procedural:layers?k=4&r=3&pd=0.6");
    v.push_back(prepare("layers", layers, *layers.defaultCamera, 64, 64));
    const Scene spheres = loadOrDie("procedural:spheres");
    v.push_back(prepare("spheres", spheres, *spheres.defaultCamera, 72, 60));
    const Scene smoke = loadOrDie("procedural:smoke?count=1500");
    v.push_back(prepare("smoke", smoke, *smoke.defaultCamera, 64, 64));
    v.push_back(prepare("ties", tiesScene(16), test::screenCamera(), 16, 16));
    v.push_back(
        prepare("hot-pixel", test::hotPixelScene(16, 150, 7), test::screenCamera(), 16, 16));
    return v;
  }();
  return all;
}

std::string label(const Case& c, const MethodDesc& m, CaptureMode mode) {
  std::string s = c.name;
  s += " / ";
  s += m.name;
  s += " k=";
  s += m.k ? std::to_string(*m.k) : std::string("budget");
  s += " d=";
  s += std::to_string(m.occupancyWords);
  s += " / ";
  s += modeName(mode);
  return s;
}

// The counters of the capture pass against each other and against the A-buffer.
void expectCountersAddUp(const Case& c, const MethodDesc& m, const RenderOutput& out,
                         const std::string& what) {
  const RenderStats& s = out.stats;
  EXPECT_EQ(s.fragmentsGenerated, c.abuffer.stats.fragmentsGenerated) << what;
  EXPECT_EQ(s.captured + s.lost, s.fragmentsGenerated) << what;
  EXPECT_EQ(s.culledOccupancy + s.culledKPlus + s.rejectedInStore + s.inserted,
            s.fragmentsGenerated)
      << what << ": every fragment is culled, rejected or inserted";
  EXPECT_EQ(s.inserted - s.evicted, s.captured) << what;
  uint64_t stored = 0;
  for (const uint32_t n : out.counts) stored += n;
  EXPECT_EQ(stored, s.captured) << what;
  if (m.occupancyWords == 0) {
    EXPECT_EQ(s.culledOccupancy, 0u) << what;
  }
  if (m.culling == CullingTest::None) {
    EXPECT_EQ(s.culledKPlus, 0u) << what;
  }
}

// --- independent compositing reference (double precision, sRGB by its formula) ---

double srgbDecode(uint32_t code) {
  const double c = code / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
glm::dvec4 nodeLinear(FragmentNode node) {
  const uint32_t rgba = nodeColor(node);
  return {srgbDecode(rgba & 0xff), srgbDecode((rgba >> 8) & 0xff), srgbDecode((rgba >> 16) & 0xff),
          (rgba >> 24) / 255.0};
}

// DHOIT sec. 3.3 on a pixel's sorted list: the first k over each other, the rest as the tail,
//   final = C_core + (1 - a_core) (a_tail C_tail + (1 - a_tail) bg),  a_tail = 1 - (1 - a_avg)^t.
glm::dvec3 hybridReference(const std::vector<FragmentNode>& sorted, size_t k, glm::dvec3 bg) {
  glm::dvec3 core(0.0);
  double T = 1.0;
  const size_t coreSize = std::min(k, sorted.size());
  for (size_t i = 0; i < coreSize; ++i) {
    const glm::dvec4 c = nodeLinear(sorted[i]);
    core += glm::dvec3(c) * c.a * T;
    T *= 1.0 - c.a;
  }
  glm::dvec3 accum(0.0);
  double alphaSum = 0.0;
  const size_t t = sorted.size() - coreSize;
  for (size_t i = coreSize; i < sorted.size(); ++i) {
    const glm::dvec4 c = nodeLinear(sorted[i]);
    accum += glm::dvec3(c) * c.a;
    alphaSum += c.a;
  }
  if (t == 0 || alphaSum <= 0.0) return core + T * bg;
  const glm::dvec3 tailColor = accum / alphaSum;
  const double tailAlpha = 1.0 - std::pow(1.0 - alphaSum / static_cast<double>(t), t);
  return core + T * (tailAlpha * tailColor + (1.0 - tailAlpha) * bg);
}

// --- with k covering the depth complexity ---

TEST(KBufferFamily, EveryPresetReproducesTheABufferWhenKCoversTheDepthComplexity) {
  for (const Case& c : cases()) {
    const std::vector<uint8_t> reference = encodeSrgb(c.abuffer.image).rgba;
    for (const std::string& base : boundedPresets())
      for (const std::string& preset : {base, base + "+occupancy"})
        for (const Compositing comp : kCompositing)
          for (const CaptureMode mode : kModes) {
            const MethodDesc m = presetWithK(preset, c.maxN, comp);
            const std::string what = label(c, m, mode);
            const auto out = runMethod(c.frame, m, mode);
            ASSERT_TRUE(out) << what;
            EXPECT_EQ(encodeSrgb(out->image).rgba, reference) << what;
            EXPECT_EQ(capturedSets(*out), c.lists) << what;
            EXPECT_EQ(out->stats.lost, 0u) << what;
            EXPECT_EQ(out->stats.evicted, 0u) << what;
            expectCountersAddUp(c, m, *out, what);
          }
  }
}

TEST(KBufferFamily, ZBufferEqualsTheNearestSurfaceOverTheBackground) {
  const glm::dvec3 bg(kBackground);
  for (const Case& c : cases())
    for (const CaptureMode mode : kModes)
      for (const std::string preset : {"zbuffer", "zbuffer+occupancy"}) {
        const MethodDesc m = presetWithK(preset, std::nullopt, Compositing::KBuffer);
        const std::string what = label(c, m, mode);
        const auto out = runMethod(c.frame, m, mode);
        ASSERT_TRUE(out) << what;
        EXPECT_EQ(out->stats.globalK, 1u) << what;
        expectCountersAddUp(c, m, *out, what);
        int mismatches = 0;
        for (size_t p = 0; p < c.lists.size(); ++p) {
          glm::dvec3 expected = bg;
          std::vector<FragmentNode> want;
          if (!c.lists[p].empty()) {
            const FragmentNode nearest = *std::min_element(c.lists[p].begin(), c.lists[p].end());
            want = {nearest};
            const glm::dvec4 f = nodeLinear(nearest);
            expected = glm::dvec3(f) * f.a + (1.0 - f.a) * bg;
          }
          const glm::vec3 got = out->image.pixels[p];
          const bool same =
              test::capturedAt(*out, p) == want && std::fabs(got.r - expected.r) < 1e-5 &&
              std::fabs(got.g - expected.g) < 1e-5 && std::fabs(got.b - expected.b) < 1e-5;
          if (!same && ++mismatches <= 3)
            ADD_FAILURE() << what << ": pixel " << p << " got " << got.r << "," << got.g << ","
                          << got.b << " expected " << expected.r << "," << expected.g << ","
                          << expected.b;
        }
        EXPECT_EQ(mismatches, 0) << what;
      }
}

// --- with k below the depth complexity ---

TEST(KBufferFamily, BoundedKCapturesTheKNearestOfEachPixel) {
  for (const Case& c : cases()) {
    ASSERT_GE(c.maxN, 4u) << c.name;
    std::vector<uint32_t> ks = {1, c.maxN / 3, c.maxN - 1};
    if (c.maxN > 20) ks.push_back(17);  // kplus-sb switches to the heap above 16
    for (const uint32_t k : ks)
      for (const std::string& base : boundedPresets())
        for (const int words : {0, 1, 4})
          for (const Compositing comp : kCompositing)
            for (const CaptureMode mode : kModes) {
              if (comp == Compositing::Hybrid && k != ks[1])
                continue;  // same capture, keep it short
              MethodDesc m = presetWithK(base, k, comp);
              m.occupancyWords = words;
              const std::string what = label(c, m, mode);
              const auto out = runMethod(c.frame, m, mode);
              ASSERT_TRUE(out) << what;
              EXPECT_EQ(out->stats.globalK, k) << what;
              expectCountersAddUp(c, m, *out, what);
              const bool counted = base == "kplus-sb" || base == "kplus-dynamic";
              int mismatches = 0;
              for (size_t p = 0; p < c.lists.size(); ++p) {
                const uint32_t n = static_cast<uint32_t>(c.lists[p].size());
                const uint32_t kp = counted ? std::min(n, k) : k;
                const std::vector<FragmentNode> want(c.lists[p].begin(),
                                                     c.lists[p].begin() + std::min(n, kp));
                if ((out->kMap[p] != kp || test::capturedAt(*out, p) != want) && ++mismatches <= 3)
                  ADD_FAILURE() << what << ": pixel " << p << " (n = " << n
                                << ", k(p) = " << out->kMap[p] << " expected " << kp << ")";
              }
              EXPECT_EQ(mismatches, 0) << what;
            }
  }
}

TEST(KBufferFamily, HybridResolveMatchesTheCorePlusWeightedTailFormula) {
  const glm::dvec3 bg(kBackground);
  for (const Case& c : cases())
    for (const std::string preset :
         {"zbuffer", "fkb", "kplus-array", "kplus-heap", "kplus-sb", "kplus-dynamic",
          "kplus-array+occupancy", "kplus-sb+occupancy"})
      for (const CaptureMode mode : kModes) {
        const std::optional<uint32_t> k =
            preset == "zbuffer" ? std::nullopt : std::optional<uint32_t>(std::max(1u, c.maxN / 3));
        const MethodDesc m = presetWithK(preset, k, Compositing::Hybrid);
        const std::string what = label(c, m, mode);
        const auto out = runMethod(c.frame, m, mode);
        ASSERT_TRUE(out) << what;
        expectCountersAddUp(c, m, *out, what);
        int withTail = 0, mismatches = 0;
        for (size_t p = 0; p < c.lists.size(); ++p) {
          const size_t kp = out->kMap[p];
          withTail += c.lists[p].size() > kp;
          const glm::dvec3 expected = hybridReference(c.lists[p], kp, bg);
          const glm::vec3 got = out->image.pixels[p];
          const double err = std::max({std::fabs(got.r - expected.r), std::fabs(got.g - expected.g),
                                       std::fabs(got.b - expected.b)});
          if (err > 1e-4 && ++mismatches <= 3)
            ADD_FAILURE() << what << ": pixel " << p << " n = " << c.lists[p].size()
                          << " k = " << kp << " got " << got.r << "," << got.g << "," << got.b
                          << " expected " << expected.r << "," << expected.g << "," << expected.b;
        }
        EXPECT_EQ(mismatches, 0) << what;
        EXPECT_GT(withTail, 0) << what << ": no pixel has a tail, the test checks nothing";
      }
}

// --- the counters on scenes whose arrival order is known ---

// L full-screen layers of a size x size image, submitted near to far or far to near.
Scene orderedLayers(int size, int layers, bool nearToFar) {
  std::vector<test::TestTriangle> tris;
  for (int i = 0; i < layers; ++i) {
    const int rank = nearToFar ? i : layers - 1 - i;
    const float z = -0.2f * static_cast<float>(rank);
    const glm::vec4 color(0.1f * static_cast<float>(rank % 10), 0.5f, 1.0f, 0.3f);
    const auto r = test::screenRect(-1, -1, size + 1, size + 1, size, z, color);
    tris.insert(tris.end(), r.begin(), r.end());
  }
  return test::makeScene(tris);
}

TEST(KBufferFamily, KPlusTestCullsFrontToBackArrivalsAndStoresEvictBackToFrontOnes) {
  const int size = 16, layers = 10;
  const uint64_t pixels = size * size;
  const uint32_t k = 3;
  for (const bool nearToFar : {true, false}) {
    const auto frame = test::buildFrame(orderedLayers(size, layers, nearToFar),
                                        test::screenCamera(), size, size, 2);
    ASSERT_TRUE(frame);
    for (const std::string preset : {"fkb", "kplus-array", "kplus-heap", "kplus-sb"}) {
      const auto out =
          runMethod(*frame, presetWithK(preset, k, Compositing::KBuffer), CaptureMode::TileOwned);
      ASSERT_TRUE(out);
      const RenderStats& s = out->stats;
      const std::string what = preset + (nearToFar ? " near to far" : " far to near");
      EXPECT_EQ(s.fragmentsGenerated, layers * pixels) << what;
      EXPECT_EQ(s.captured, k * pixels) << what;
      const uint64_t beyond = (layers - k) * pixels;
      if (nearToFar && preset == "fkb") {
        EXPECT_EQ(s.rejectedInStore, beyond) << what << ": full store, farther than its maximum";
        EXPECT_EQ(s.inserted, k * pixels) << what;
      } else if (nearToFar) {
        EXPECT_EQ(s.culledKPlus, beyond) << what << ": culled before the critical section";
        EXPECT_EQ(s.rejectedInStore, 0u) << what;
        EXPECT_EQ(s.inserted, k * pixels) << what;
      } else {
        EXPECT_EQ(s.culledKPlus + s.rejectedInStore, 0u) << what << ": each arrival is nearer";
        EXPECT_EQ(s.evicted, beyond) << what;
        EXPECT_EQ(s.inserted, layers * pixels) << what;
      }
    }
  }
}

TEST(KBufferFamily, OccupancyCullsLayersBehindTheKthOccupiedBucket) {
  // far-to-near arrival defeats the k+ test entirely; the occupancy map still culls the layers
  // beyond the k-th occupied bucket before they reach the store
  const int size = 16, layers = 10;
  const uint64_t pixels = size * size;
  const uint32_t k = 3;
  const auto frame =
      test::buildFrame(orderedLayers(size, layers, false), test::screenCamera(), size, size, 2);
  ASSERT_TRUE(frame);
  for (const int words : {1, 2, 4}) {
    MethodDesc m = presetWithK("kplus-array", k, Compositing::KBuffer);
    m.occupancyWords = words;
    const auto out = runMethod(*frame, m, CaptureMode::TileOwned);
    ASSERT_TRUE(out);
    const RenderStats& s = out->stats;
    EXPECT_GT(s.culledOccupancy, 0u) << "d = " << words;
    EXPECT_LE(s.culledOccupancy, (layers - k) * pixels) << "d = " << words;
    EXPECT_EQ(s.captured, k * pixels);
    EXPECT_EQ(s.evicted + s.culledOccupancy, (layers - k) * pixels) << "d = " << words;
  }
}

// --- memory ---

// The documented per-pixel layout (memory_model.hpp), by preset name.
struct Layout {
  uint64_t perPixel = 0, image = 0;
};
Layout documentedLayout(const std::string& base, int occupancyWords, Compositing comp) {
  Layout l;
  l.perPixel = 4;  // counter
  if (base == "abuffer" || base == "kplus-sb" || base == "kplus-dynamic")
    l.perPixel += 4;                                                     // offset
  if (base == "zbuffer" || base.starts_with("kplus-")) l.perPixel += 4;  // lock
  if (occupancyWords > 0) l.perPixel += 12 + 4 * static_cast<uint64_t>(occupancyWords);
  if (comp == Compositing::Hybrid) l.perPixel += 20;  // tail
  if (base == "kplus-dynamic") l.image = 4096;        // histogram
  return l;
}

uint64_t sumCapped(const std::vector<uint32_t>& n, uint64_t k) {
  uint64_t s = 0;
  for (const uint32_t c : n) s += std::min<uint64_t>(c, k);
  return s;
}

// What a budget buys, worked out from the allocation policies' definitions.
struct Expected {
  bool ok = false;
  uint64_t slots = 0;
  std::optional<uint32_t> k;
};
Expected expectedAllocation(const std::string& base, const Layout& layout, uint64_t budget,
                            const std::vector<uint32_t>& n) {
  const uint64_t pixels = n.size(), overhead = pixels * layout.perPixel + layout.image;
  Expected e;
  if (budget < overhead + 8) return e;
  const uint64_t F = (budget - overhead) / 8;
  if (base == "abuffer") {
    e.slots = sumCapped(n, UINT32_MAX);
  } else if (base == "zbuffer") {
    e.k = 1;
    e.slots = pixels;
  } else if (base == "fkb" || base == "kplus-array" || base == "kplus-heap") {
    if (F / pixels == 0) return e;
    e.k = static_cast<uint32_t>(F / pixels);
    e.slots = *e.k * pixels;
  } else if (base == "kplus-sb") {
    e.k = static_cast<uint32_t>(std::max<uint64_t>(1, F / pixels));
    e.slots = sumCapped(n, *e.k);
  } else {  // kplus-dynamic: the largest k <= min(1023, max n(p)) whose exact memory fits
    uint64_t sum = 0, best = 0, bestSlots = 0;
    const uint64_t maxN = std::max<uint64_t>(1, *std::max_element(n.begin(), n.end()));
    for (uint64_t k = 1; k <= std::min<uint64_t>(1023, maxN); ++k) {
      for (const uint32_t c : n) sum += c >= k;
      if (sum > F) break;
      best = k;
      bestSlots = sum;
    }
    if (best == 0) return e;
    e.k = static_cast<uint32_t>(best);
    e.slots = bestSlots;
  }
  e.ok = e.slots <= F;
  return e;
}

std::string baseName(const std::string& preset) {
  const auto plus = preset.find('+');
  return plus == std::string::npos ? preset : preset.substr(0, plus);
}

// The k-buffer family and its two ends (the variable k-buffer has its own tests).
std::vector<std::string> allPresets() {
  std::vector<std::string> v;
  for (const std::string p :
       {"zbuffer", "abuffer", "fkb", "kplus-array", "kplus-heap", "kplus-sb", "kplus-dynamic"}) {
    v.push_back(p);
    if (p != "abuffer") v.push_back(p + "+occupancy");
  }
  return v;
}

void checkBudget(const RasterFrame& frame, const std::vector<uint32_t>& n, uint64_t budget,
                 const std::string& sceneName) {
  for (const std::string& preset : allPresets())
    for (const Compositing comp : kCompositing) {
      MethodDesc m = presetWithK(preset, std::nullopt, comp);
      const std::string base = baseName(preset);
      const Layout layout = documentedLayout(base, m.occupancyWords, comp);
      const Expected want = expectedAllocation(base, layout, budget, n);
      std::string what = sceneName;
      what += " ";
      what += std::to_string(frame.width());
      what += "x";
      what += std::to_string(frame.height());
      what += " / ";
      what += m.name;
      what += " / budget ";
      what += std::to_string(budget);
      RenderOptions options;
      options.budgetBytes = budget;
      const auto out = render(frame, m, options);
      ASSERT_EQ(out.ok(), want.ok) << what << (out.ok() ? "" : ": " + out.error().message);
      if (!out.ok()) {
        EXPECT_NE(out.error().message.find(std::to_string(budget) + " B"), std::string::npos)
            << what << ": " << out.error().message;
        continue;
      }
      const RenderStats& s = out->stats;
      EXPECT_LE(s.bytesUsed, budget) << what;
      EXPECT_EQ(s.fragmentSlots, want.slots) << what;
      EXPECT_EQ(s.bytesUsed, n.size() * layout.perPixel + layout.image + 8 * want.slots) << what;
      if (base != "abuffer") {
        EXPECT_EQ(s.globalK, want.k) << what;
      }
      uint64_t byCategory = 0;
      for (const auto& [category, bytes] : s.bytesByCategory) byCategory += bytes;
      EXPECT_EQ(byCategory, s.bytesUsed) << what;
    }
}

TEST(MemoryBudget, BytesFollowTheDocumentedLayoutAndStayWithinTheBudget) {
  struct Setup {
    std::string spec;
    int width, height;
    std::vector<uint64_t> budgets;
  };
  const std::vector<Setup> setups = {
      {"procedural:hairball?strands=300", 64, 64, {1024, 40 * 1024, 100 * 1024, 1 << 20}},
      {"procedural:layers?k=4&r=4&pd=0.5", 64, 64, {40 * 1024, 100 * 1024, 1 << 20}},
      {"procedural:spheres", 64, 64, {40 * 1024, 100 * 1024, 1 << 20}},
      {"procedural:hairball?strands=300", 200, 150, {2 << 20}},
  };
  for (const Setup& setup : setups) {
    const Scene scene = loadOrDie(setup.spec);
    const auto frame = test::buildFrame(scene, *scene.defaultCamera, setup.width, setup.height, 2);
    ASSERT_TRUE(frame);
    const std::vector<uint32_t> n = countFragments(*frame);
    for (const uint64_t budget : setup.budgets) {
      checkBudget(*frame, n, budget, setup.spec);
      if (HasFatalFailure()) return;
    }
  }
}

TEST(MemoryBudget, SmallestSufficientBudgetSucceedsAndOneByteLessIsAnError) {
  const Scene scene = loadOrDie("procedural:hairball?strands=200");
  const auto frame = test::buildFrame(scene, *scene.defaultCamera, 48, 40, 2);
  ASSERT_TRUE(frame);
  const std::vector<uint32_t> n = countFragments(*frame);
  uint64_t covered = 0, total = 0;
  for (const uint32_t c : n) {
    covered += c > 0;
    total += c;
  }
  ASSERT_GT(covered, 0u);
  ASSERT_LT(covered, n.size()) << "the test wants uncovered pixels too";
  for (const std::string& preset : allPresets())
    for (const Compositing comp : kCompositing) {
      const MethodDesc m = presetWithK(preset, std::nullopt, comp);
      const std::string base = baseName(preset);
      const Layout layout = documentedLayout(base, m.occupancyWords, comp);
      // fixed k needs one slot per pixel, exact allocations one per covered pixel (k = 1) under
      // kbuffer compositing, none under hybrid (k = 0: every pixel from its tail, issue 28)
      const bool fixed =
          base == "zbuffer" || base == "fkb" || base == "kplus-array" || base == "kplus-heap";
      const bool tailOnly = !fixed && base != "abuffer" && comp == Compositing::Hybrid;
      const uint64_t slots = base == "abuffer" ? total : fixed ? n.size() : tailOnly ? 0 : covered;
      const uint64_t minimum = n.size() * layout.perPixel + layout.image + 8 * slots;
      RenderOptions options;
      options.budgetBytes = minimum;
      const auto fits = render(*frame, m, options);
      ASSERT_TRUE(fits.ok()) << m.name << " with " << minimum
                             << " B: " << (fits.ok() ? "" : fits.error().message);
      EXPECT_EQ(fits->stats.bytesUsed, minimum) << m.name;
      if (base != "abuffer") {
        EXPECT_EQ(fits->stats.globalK, tailOnly ? 0u : 1u) << m.name;
      }
      if (tailOnly) {
        EXPECT_EQ(fits->stats.captured, 0u) << m.name;
        EXPECT_EQ(fits->stats.fragmentSlots, 0u) << m.name;
      }
      options.budgetBytes = minimum - 1;
      const auto tooSmall = render(*frame, m, options);
      ASSERT_FALSE(tooSmall.ok()) << m.name << " with " << minimum - 1 << " B";
      const std::string& message = tooSmall.error().message;
      EXPECT_NE(message.find(std::to_string(minimum - 1) + " B"), std::string::npos) << message;
      // the message names the floor: the per-pixel words, or what one node per pixel needs
      EXPECT_NE(message.find(std::to_string(minimum) + " B"), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

TEST(MemoryBudget, FragmentSlotsFollowEquationOne) {
  // F(M) = floor((M - |P| S_p - S_i) / 8), worked out by hand at 100 x 100 pixels
  const uint64_t pixels = 100 * 100, M = 1'000'007;
  auto slots = [&](const std::string& preset, Compositing comp) {
    return MemoryModel::of(presetWithK(preset, std::nullopt, comp)).fragmentSlots(M, pixels);
  };
  EXPECT_EQ(slots("fkb", Compositing::KBuffer), 120000u);            // S_p = 4
  EXPECT_EQ(slots("zbuffer", Compositing::KBuffer), 115000u);        // 4 + lock 4
  EXPECT_EQ(slots("kplus-array", Compositing::KBuffer), 115000u);    // 4 + lock 4
  EXPECT_EQ(slots("abuffer", Compositing::KBuffer), 115000u);        // 4 + offset 4
  EXPECT_EQ(slots("kplus-sb", Compositing::KBuffer), 110000u);       // 4 + 4 + 4
  EXPECT_EQ(slots("kplus-dynamic", Compositing::KBuffer), 109488u);  // (M - 120000 - 4096) / 8
  EXPECT_EQ(slots("kplus-heap+occupancy", Compositing::KBuffer), 95000u);  // 8 + 16
  EXPECT_EQ(slots("kplus-sb+occupancy", Compositing::Hybrid), 65000u);     // 12 + 16 + 20
  EXPECT_EQ(slots("fkb", Compositing::Hybrid), 95000u);                    // 4 + 20
  // nothing left once the overhead is paid
  EXPECT_EQ(MemoryModel::of(presetWithK("kplus-sb", std::nullopt, Compositing::KBuffer))
                .fragmentSlots(120000, pixels),
            0u);
  EXPECT_EQ(MemoryModel::of(presetWithK("kplus-sb", std::nullopt, Compositing::KBuffer))
                .fragmentSlots(1000, pixels),
            0u);
  MethodDesc d4 = presetWithK("kplus-array+occupancy", std::nullopt, Compositing::KBuffer);
  d4.occupancyWords = 4;
  EXPECT_EQ(MemoryModel::of(d4).fragmentSlots(M, pixels), (M - pixels * (8 + 28)) / 8);
}

TEST(MemoryBudget, DynamicKIsTheLargestKThatFits) {
  const Scene scene = loadOrDie("procedural:hairball?strands=300");
  const auto frame = test::buildFrame(scene, *scene.defaultCamera, 80, 80, 2);
  ASSERT_TRUE(frame);
  const std::vector<uint32_t> n = countFragments(*frame);
  const uint32_t maxN = *std::max_element(n.begin(), n.end());
  ASSERT_GT(maxN, 8u);
  const MethodDesc m = presetWithK("kplus-dynamic", std::nullopt, Compositing::KBuffer);
  const uint64_t overhead = n.size() * 12 + 4096;
  for (const uint32_t target : {1u, 2u, 5u, maxN / 2, maxN - 1})
    for (const uint64_t slack : {0u, 7u}) {
      // exactly enough for k = target (plus less than one more node)
      const uint64_t budget = overhead + 8 * sumCapped(n, target) + slack;
      RenderOptions options;
      options.budgetBytes = budget;
      options.keepStores = true;
      const auto out = render(*frame, m, options);
      ASSERT_TRUE(out.ok()) << budget;
      const uint32_t k = out->stats.globalK.value();
      EXPECT_EQ(k, target) << "budget " << budget;
      EXPECT_LE(overhead + 8 * sumCapped(n, k), budget);
      EXPECT_GT(overhead + 8 * sumCapped(n, k + 1), budget) << "k + 1 would fit as well";
      for (size_t p = 0; p < n.size(); ++p) ASSERT_EQ(out->kMap[p], std::min(n[p], k)) << p;
    }
}

}  // namespace
}  // namespace mfr
