// Depth peeling (Everitt 2001) and dual depth peeling (Bavoil & Myers 2008) on the CPU engine
// (include/mfr/method/peel.hpp): unbounded, both equal the A-buffer (peel bit for bit) on
// procedural scenes and on constructed layers with fragments equal in depth and colour; the pass
// count is the most distinct keys of a pixel (dual: half, rounded up); --max-peels P against closed
// forms computed here in double precision (the P nearest layers, dual-peel's P nearest and P
// farthest, the rest dropped or, under hybrid, the tail of compositing.hpp); the memory layout and
// the budget; the option's errors; draw-order and capture-mode independence.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "mfr/core/color.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/pass_plan.hpp"
#include "mfr/method/peel.hpp"
#include "mfr/scene/draw_order.hpp"
#include "mfr/scene/load.hpp"
#include "test_util.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr {
namespace {

constexpr int kSize = 16;
const glm::vec3 kBg(0.2f, 0.4f, 0.6f);

struct Layer {
  float z;  // world z of the full-screen plane (further away: more negative)
  glm::vec4 color;
};

RasterFrame frameOf(const std::vector<Layer>& layers) {
  std::vector<test::TestTriangle> tris;
  for (const Layer& l : layers) {
    const auto r = test::screenRect(-1, -1, kSize + 1, kSize + 1, kSize, l.z, l.color);
    tris.insert(tris.end(), r.begin(), r.end());
  }
  return std::move(*test::buildFrame(test::makeScene(tris), test::screenCamera(), kSize, kSize, 2));
}

MethodDesc peelMethod(const std::string& preset, std::optional<int64_t> maxPeels = {},
                      bool hybrid = false) {
  MethodOverrides o;
  o.maxPeels = maxPeels;
  if (hybrid) o.composite = "hybrid";
  auto m = makeMethod(preset, o);
  EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message);
  return m.value();
}

RenderOutput run(const RasterFrame& frame, const MethodDesc& m,
                 CaptureMode mode = CaptureMode::TileOwned) {
  RenderOptions o;
  o.background = kBg;
  o.keepStores = m.allocation == AllocationPolicy::Unbounded;
  o.capture = mode;
  auto out = render(frame, m, o);
  EXPECT_TRUE(out.ok()) << m.name << ": " << (out.ok() ? "" : out.error().message);
  return std::move(out.value());
}

RenderOutput abuffer(const RasterFrame& frame) {
  return run(frame, methodPreset("abuffer").value());
}

// the most distinct keys (depth, colour) of a pixel, from the A-buffer's nodes
uint32_t maxDistinctKeys(const RenderOutput& ab) {
  uint32_t most = 0;
  for (std::vector<FragmentNode> nodes : test::capturedSets(ab)) {
    std::sort(nodes.begin(), nodes.end());
    most = std::max(most,
                    static_cast<uint32_t>(std::unique(nodes.begin(), nodes.end()) - nodes.begin()));
  }
  return most;
}

std::vector<std::string> passNames(const RenderStats& s) {
  std::vector<std::string> names;
  for (const PassTime& t : s.passes) names.push_back(t.name);
  return names;
}

// Every fragment peeled: the A-buffer's image (peel: the same "over" steps in the same order, bit
// for bit; dual-peel: back layers blended back to front, float rounding), nothing lost, and the
// pass count from the distinct keys.
void expectEqualsTheABuffer(const RasterFrame& frame, const std::string& what) {
  const RenderOutput ab = abuffer(frame);
  const uint32_t layers = maxDistinctKeys(ab);
  ASSERT_GT(layers, 2u) << what;
  const RenderOutput peel = run(frame, peelMethod("peel"));
  EXPECT_EQ(peel.image.pixels, ab.image.pixels) << what;
  EXPECT_EQ(peel.stats.lost, 0u) << what;
  EXPECT_EQ(peel.stats.captured, ab.stats.fragmentsGenerated) << what;
  EXPECT_EQ(peel.stats.fragmentsGenerated, ab.stats.fragmentsGenerated) << what;
  EXPECT_EQ(peel.stats.peelPasses, layers) << what;
  const RenderOutput dual = run(frame, peelMethod("dual-peel"));
  EXPECT_LT(test::largestDifference(dual.image, ab.image), 2e-6f) << what;
  EXPECT_EQ(dual.stats.lost, 0u) << what;
  EXPECT_EQ(dual.stats.peelPasses, (layers + 1) / 2) << what;
  // one timed entry per pass, in order
  std::vector<std::string> expected;
  for (uint32_t i = 0; i < (layers + 1) / 2; ++i) expected.push_back(peelPassName(i));
  std::vector<std::string> names = passNames(dual.stats);
  names.erase(std::remove_if(names.begin(), names.end(),
                             [](const std::string& n) { return n.rfind("peel", 0) != 0; }),
              names.end());
  EXPECT_EQ(names, expected) << what;
}

TEST(Peeling, UnboundedEqualsTheABufferOnProceduralScenes) {
  for (const char* spec :
       {"procedural:hairball?strands=120", "procedural:bottles", "procedural:smoke"}) {
    const Scene scene = loadScene(spec).value();
    const auto frame = test::buildFrame(scene, *scene.defaultCamera, 48, 40, 2);
    ASSERT_TRUE(frame);
    expectEqualsTheABuffer(*frame, spec);
  }
}

// Fragments equal in depth AND colour are one key: a strict "farther than the last layer" would
// peel them once; the multiplicity composites them as often as they occur.
TEST(Peeling, DuplicatesOfDepthAndColourArePeeledWithTheirMultiplicity) {
  const glm::vec4 red(0.9f, 0.1f, 0.1f, 0.5f), green(0.1f, 0.8f, 0.2f, 0.4f),
      blue(0.1f, 0.2f, 0.9f, 0.4f), grey(0.5f, 0.5f, 0.5f, 0.3f);
  const RasterFrame frame = frameOf({{-1.0f, red},
                                     {-2.0f, grey},
                                     {-1.0f, red},  // the same key as the first
                                     {-1.5f, green},
                                     {-1.5f, blue},  // equal depth, another colour
                                     {-2.0f, grey},
                                     {-1.0f, red},
                                     {-3.0f, blue}});
  const RenderOutput ab = abuffer(frame);
  EXPECT_EQ(maxDistinctKeys(ab), 5u);  // red, green | blue, grey, blue far
  expectEqualsTheABuffer(frame, "constructed duplicates");
  // every pixel's 8 fragments were peeled, in 5 passes (dual: 3, the middle one met on one layer)
  const RenderOutput peel = run(frame, peelMethod("peel"));
  EXPECT_EQ(peel.stats.captured, 8u * kSize * kSize);
  EXPECT_EQ(peel.stats.peelPasses, 5u);
  const RenderOutput dual = run(frame, peelMethod("dual-peel"));
  EXPECT_EQ(dual.stats.captured, 8u * kSize * kSize);
  EXPECT_EQ(dual.stats.peelPasses, 3u);
  // and a strict comparison without the multiplicity would differ: red three times vs once
  EXPECT_GT(std::abs(ab.image.pixels[0].r - abuffer(frameOf({{-1.0f, red},
                                                             {-2.0f, grey},
                                                             {-1.5f, green},
                                                             {-1.5f, blue},
                                                             {-2.0f, grey},
                                                             {-3.0f, blue}}))
                                                .image.pixels[0]
                                                .r),
            1e-3f);
}

// ---- closed forms for --max-peels -------------------------------------------------------------

struct Frag {
  double r, g, b, a;
};

// each pixel's fragments, nearest first, as the A-buffer captured them (the shaded colours)
std::vector<std::vector<Frag>> fragmentsOf(const RasterFrame& frame) {
  std::vector<std::vector<Frag>> out;
  for (const std::vector<FragmentNode>& nodes : test::capturedSets(abuffer(frame))) {
    std::vector<Frag> px;
    for (FragmentNode n : nodes) {
      const glm::vec4 c = unpackFragmentColor(nodeColor(n));
      px.push_back({c.r, c.g, c.b, c.a});
    }
    out.push_back(px);
  }
  return out;
}

// over of `front` (nearest first), then `behind`
glm::dvec3 over(const std::vector<Frag>& front, glm::dvec3 behind) {
  glm::dvec3 c(0.0);
  double T = 1.0;
  for (const Frag& f : front) {
    c += T * f.a * glm::dvec3(f.r, f.g, f.b);
    T *= 1.0 - f.a;
  }
  return c + T * behind;
}

// the hybrid tail of compositing.hpp over `behind`
glm::dvec3 tailOver(const std::vector<Frag>& tail, glm::dvec3 behind) {
  if (tail.empty()) return behind;
  glm::dvec3 sum(0.0);
  double alpha = 0.0;
  for (const Frag& f : tail) {
    sum += f.a * glm::dvec3(f.r, f.g, f.b);
    alpha += f.a;
  }
  const double t = static_cast<double>(tail.size());
  const double tailAlpha = 1.0 - std::pow(1.0 - alpha / t, t);
  return tailAlpha * (sum / alpha) + (1.0 - tailAlpha) * behind;
}

// the largest difference of the image from expected(pixel's fragments, nearest first)
template <class Expected>
double worstAgainst(const ImageRGB& image, const std::vector<std::vector<Frag>>& frags,
                    Expected&& expected) {
  double worst = 0.0;
  for (size_t p = 0; p < frags.size(); ++p) {
    const glm::dvec3 d = glm::abs(glm::dvec3(image.pixels[p]) - expected(frags[p]));
    worst = std::max({worst, d.x, d.y, d.z});
  }
  return worst;
}

TEST(Peeling, MaxPeelsKeepsTheNearestLayersAndDropsOrTailsTheRest) {
  // six layers, submitted out of depth order
  const std::vector<Layer> layers = {
      {-3.0f, {0.2f, 0.9f, 0.1f, 0.35f}}, {-1.0f, {0.9f, 0.2f, 0.1f, 0.5f}},
      {-5.0f, {0.5f, 0.5f, 0.9f, 0.6f}},  {-2.0f, {0.1f, 0.3f, 0.8f, 0.25f}},
      {-6.0f, {0.7f, 0.7f, 0.2f, 0.45f}}, {-4.0f, {0.3f, 0.1f, 0.6f, 0.4f}}};
  const RasterFrame frame = frameOf(layers);
  const std::vector<std::vector<Frag>> frags = fragmentsOf(frame);
  for (const auto& f : frags) ASSERT_EQ(f.size(), layers.size());
  const glm::dvec3 bg(kBg);
  const uint64_t pixels = kSize * kSize;
  for (uint32_t P : {1u, 2u, 3u, 4u, 6u, 9u}) {
    SCOPED_TRACE("max-peels " + std::to_string(P));
    const size_t peeled = std::min<size_t>(P, layers.size()), rest = layers.size() - peeled;
    const auto front = [&](const std::vector<Frag>& f) {
      return std::vector<Frag>(f.begin(), f.begin() + peeled);
    };
    const auto behind = [&](const std::vector<Frag>& f) {
      return std::vector<Frag>(f.begin() + peeled, f.end());
    };
    // peel: the P nearest, the rest dropped or tailed
    const RenderOutput drop = run(frame, peelMethod("peel", P));
    EXPECT_LT(worstAgainst(drop.image, frags, [&](const auto& f) { return over(front(f), bg); }),
              1e-5);
    EXPECT_EQ(drop.stats.lost, rest * pixels);
    EXPECT_EQ(drop.stats.peelPasses, peeled);
    const RenderOutput tail = run(frame, peelMethod("peel", P, true));
    EXPECT_LT(worstAgainst(tail.image, frags,
                           [&](const auto& f) { return over(front(f), tailOver(behind(f), bg)); }),
              1e-5);
    EXPECT_EQ(tail.stats.peelPasses, peeled);
    const std::vector<std::string> names = passNames(tail.stats);
    EXPECT_EQ(std::count(names.begin(), names.end(), kPeelTailPass), rest == 0 ? 0 : 1);
    // dual-peel: P passes peel the P nearest and the P farthest (all six from P = 3)
    const size_t side = std::min<size_t>(P, layers.size() / 2);
    const auto near = [&](const std::vector<Frag>& f) {
      return std::vector<Frag>(f.begin(), f.begin() + side);
    };
    const auto far = [&](const std::vector<Frag>& f) {
      return std::vector<Frag>(f.end() - side, f.end());
    };
    const auto middle = [&](const std::vector<Frag>& f) {
      return std::vector<Frag>(f.begin() + side, f.end() - side);
    };
    const RenderOutput dualDrop = run(frame, peelMethod("dual-peel", P));
    EXPECT_LT(worstAgainst(dualDrop.image, frags,
                           [&](const auto& f) { return over(near(f), over(far(f), bg)); }),
              1e-5);
    EXPECT_EQ(dualDrop.stats.lost, (layers.size() - 2 * side) * pixels);
    EXPECT_EQ(dualDrop.stats.peelPasses, std::min<uint32_t>(P, 3));
    const RenderOutput dualTail = run(frame, peelMethod("dual-peel", P, true));
    EXPECT_LT(worstAgainst(dualTail.image, frags,
                           [&](const auto& f) {
                             return over(near(f), tailOver(middle(f), over(far(f), bg)));
                           }),
              1e-5);
  }
}

// ---- memory, options -----------------------------------------------------------------------

TEST(Peeling, MemoryIsTheDocumentedConstantPerPixel) {
  const Scene scene = loadScene("procedural:bottles").value();
  const auto frame = test::buildFrame(scene, *scene.defaultCamera, 40, 24, 2);
  ASSERT_TRUE(frame);
  const uint64_t P = 40 * 24;
  for (bool parallel : {false, true})
    for (bool hybrid : {false, true})
      for (const auto& [preset, words] : {std::pair{"peel", 36u}, std::pair{"dual-peel", 72u}}) {
        SCOPED_TRACE(std::string(preset) + (parallel ? " parallel" : "") +
                     (hybrid ? " hybrid" : ""));
        const MethodDesc m = peelMethod(preset, 2, hybrid);
        const uint64_t perPixel = words + (parallel ? 4 : 0) + (hybrid ? 20 : 0);
        EXPECT_EQ(MemoryModel::of(m, parallel).perPixel(), perPixel);
        for (uint64_t budget : {perPixel * P - 1, perPixel * P, perPixel * P + 1000}) {
          RenderOptions o;
          o.budgetBytes = budget;
          o.capture = parallel ? CaptureMode::FragmentParallel : CaptureMode::TileOwned;
          auto out = render(*frame, m, o);
          if (budget < perPixel * P) {
            ASSERT_FALSE(out.ok());
            EXPECT_NE(out.error().message.find("too small for " + std::string(preset)),
                      std::string::npos)
                << out.error().message;
            EXPECT_EQ(out.error().message.find('\n'), std::string::npos);
            continue;
          }
          ASSERT_TRUE(out.ok()) << out.error().message;
          EXPECT_EQ(out->stats.bytesUsed, perPixel * P);
          EXPECT_LE(out->stats.bytesUsed, budget);
          // measured: the per-pixel state (and tail) the engine allocated is what is charged
          EXPECT_EQ(out->stats.bytesAllocatedByCategory.at("accumulators"), words * P);
          if (hybrid) {
            EXPECT_EQ(out->stats.bytesAllocatedByCategory.at("tail"), 20 * P);
          }
        }
      }
}

TEST(Peeling, MaxPeelsErrorsNameTheOption) {
  const auto errorOf = [](const std::string& preset, MethodOverrides o, Spelling s) {
    auto m = makeMethod(preset, o, s);
    EXPECT_FALSE(m.ok()) << preset;
    return m.ok() ? std::string() : m.error().message;
  };
  for (int64_t bad : {int64_t{0}, int64_t{-1}, int64_t{-100}, kMaxPeels + 1}) {
    MethodOverrides o;
    o.maxPeels = bad;
    EXPECT_EQ(errorOf("peel", o, Spelling::Cli), "--max-peels: must be in [1, 65536]");
    EXPECT_EQ(errorOf("dual-peel", o, Spelling::Python), "max_peels: must be in [1, 65536]");
  }
  MethodOverrides o;
  o.maxPeels = 3;
  for (const char* other : {"fkb", "abuffer", "wboit", "mlab"}) {
    const std::string e = errorOf(other, o, Spelling::Cli);
    EXPECT_EQ(e.rfind(std::string("--max-peels: does not apply to ") + other, 0), 0u) << e;
    EXPECT_NE(e.find("peel, dual-peel"), std::string::npos) << e;
  }
  EXPECT_EQ(errorOf("fkb", o, Spelling::Python).rfind("max_peels: does not apply to fkb", 0), 0u);
  // --composite applies to peeling (its tail), and is checked like for the k-buffers
  MethodOverrides c;
  c.composite = "sorted";
  EXPECT_EQ(errorOf("peel", c, Spelling::Cli).rfind("--composite: ", 0), 0u);
  EXPECT_TRUE(peelMethod("peel", {}, true).peelTail);
  EXPECT_EQ(peelMethod("peel", {}, true).compositing, Compositing::Peel);
}

TEST(Peeling, CommandLineErrorsAreOneLineNamingTheOption) {
  const auto dir = test::processTempDir("mfr_peeling_test");
  const std::string common =
      "render procedural:bottles --width 16 --height 16 -o " + (dir / "x.png").string() + " ";
  for (const std::string& args :
       {common + "--method peel --max-peels 0", common + "--method peel --max-peels -2",
        common + "--method dual-peel --max-peels abc", common + "--method fkb --max-peels 2",
        common + "--method peel --max-peels 2.5"}) {
    const test::CliRun r = test::runCli(args, dir);
    EXPECT_FALSE(r.signaled) << args;
    EXPECT_NE(r.exitCode, 0) << args;
    EXPECT_NE(r.err.find("--max-peels"), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
  const test::CliRun ok = test::runCli(common + "--method dual-peel --max-peels 2 --json", dir);
  ASSERT_EQ(ok.exitCode, 0) << ok.err;
  EXPECT_NE(ok.out.find("\"peel_passes\": 2"), std::string::npos) << ok.out;
}

// ---- order independence -------------------------------------------------------------------

// Peeling finds each layer by the key order alone: under a shuffled submission order the image is
// the same bits (also with --max-peels; the hybrid tail sums in arrival order: rounding only), and
// fragment-parallel capture gives the same bits as tile-owned.
TEST(Peeling, DrawOrderAndCaptureModeDoNotChangeTheImage) {
  for (const char* spec : {"procedural:hairball?strands=60", "procedural:smoke"}) {
    const Scene scene = loadScene(spec).value();
    Scene shuffled = scene;
    shuffleDrawOrder(shuffled, 1234);
    ASSERT_NE(scene.indices, shuffled.indices);
    const auto a = test::buildFrame(scene, *scene.defaultCamera, 24, 24, 2);
    const auto b = test::buildFrame(shuffled, *scene.defaultCamera, 24, 24, 2);
    ASSERT_TRUE(a && b);
    for (const char* preset : {"peel", "dual-peel"})
      for (std::optional<int64_t> P : {std::optional<int64_t>{}, std::optional<int64_t>{2}}) {
        const std::string what = std::string(spec) + " " + preset + (P ? " P=2" : "");
        const MethodDesc m = peelMethod(preset, P);
        const RenderOutput x = run(*a, m), y = run(*b, m);
        EXPECT_EQ(x.image.pixels, y.image.pixels) << what;
        EXPECT_EQ(x.stats.captured, y.stats.captured) << what;
        const RenderOutput z = run(*a, m, CaptureMode::FragmentParallel);
        EXPECT_EQ(x.image.pixels, z.image.pixels) << what << " parallel";
        const MethodDesc h = peelMethod(preset, P ? P : 1, true);
        EXPECT_LT(test::largestDifference(run(*a, h).image, run(*b, h).image), 1e-5f)
            << what << " tail";
      }
  }
}

}  // namespace
}  // namespace mfr
