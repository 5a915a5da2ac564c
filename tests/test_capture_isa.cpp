// The capture pass on the wide (AVX2) path against the scalar path (mfr/core/isa.hpp): for several
// scenes and presets, the same captured nodes in every slot, the same counters and the same image
// bytes, and the statistics name the path taken. Skipped on a CPU without AVX2 (the scalar path is
// then the only one; the ctest entry CaptureScalarPath runs the capture tests with MFR_ISA=scalar).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <random>

#include "cpu/max_heap_replace.hpp"
#include "cpu/raster_span_avx2.hpp"
#include "mfr/core/isa.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/cpu/fragment_stores.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/stats_json.hpp"
#include "mfr/scene/procedural.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr {
namespace {

/// Restores the process's path when a test ends.
struct IsaGuard {
  Isa saved = activeIsa();
  ~IsaGuard() { setActiveIsa(saved); }
};

RenderOutput renderOn(Isa isa, const RasterFrame& frame, const MethodDesc& method,
                      std::optional<uint64_t> budget) {
  setActiveIsa(isa);
  auto out = test::runMethod(frame, method, CaptureMode::TileOwned, budget);
  EXPECT_TRUE(out.has_value()) << method.name;
  return out ? std::move(*out) : RenderOutput{};
}

void expectSameCapture(const RasterFrame& frame, const MethodDesc& method,
                       std::optional<uint64_t> budget, const std::string& what) {
  const RenderOutput scalar = renderOn(Isa::Scalar, frame, method, budget);
  const RenderOutput wide = renderOn(detectedIsa(), frame, method, budget);
  // the path taken, as the statistics JSON names it
  EXPECT_EQ(statsToJson(scalar.stats)["isa"], "scalar") << what;
  EXPECT_EQ(statsToJson(wide.stats)["isa"], "avx2") << what;  // both rules, tile-owned
  EXPECT_FALSE(statsToJson(wide.stats)["engine_counters"].contains("isa")) << what;
  ASSERT_GT(scalar.stats.fragmentsGenerated, 0u) << what << ": nothing rasterized";
  // every slot, in store order (the same insertions in the same order leave the same heaps)
  EXPECT_TRUE(scalar.nodes == wide.nodes) << what << ": captured nodes differ";
  EXPECT_TRUE(scalar.counts == wide.counts) << what << ": per-pixel counts differ";
  EXPECT_EQ(scalar.stats.fragmentsGenerated, wide.stats.fragmentsGenerated) << what;
  EXPECT_EQ(scalar.stats.culledOccupancy, wide.stats.culledOccupancy) << what;
  EXPECT_EQ(scalar.stats.culledKPlus, wide.stats.culledKPlus) << what;
  EXPECT_EQ(scalar.stats.rejectedInStore, wide.stats.rejectedInStore) << what;
  EXPECT_EQ(scalar.stats.inserted, wide.stats.inserted) << what;
  EXPECT_EQ(scalar.stats.evicted, wide.stats.evicted) << what;
  EXPECT_TRUE(scalar.image.pixels == wide.image.pixels) << what << ": images differ";
}

Scene proceduralScene(const std::string& spec) {
  auto scene = makeProceduralScene(spec, 1);
  EXPECT_TRUE(scene.ok()) << spec;
  return scene.ok() ? std::move(scene.value()) : Scene{};
}

// An opaque, a blended, an alpha-masked and a textured material in one scene (all on the wide
// path), and one blending additively: the tiles it reaches run the scalar loop on the same sink.
Scene mixedMaterialScene(int size) {
  std::vector<test::TestTriangle> tris;
  for (int i = 0; i < 12; ++i) {
    const double o = 3.0 * i;
    const auto rect = test::screenRect(2 + o, 1 + 0.5 * o, size - 7 - 0.7 * o, size - 3 - o, size,
                                       -0.05f * static_cast<float>(i % 5),
                                       glm::vec4(0.1f * (i % 9), 0.9f - 0.05f * i, 0.5f, 0.35f));
    tris.insert(tris.end(), rect.begin(), rect.end());
  }
  Scene s = test::makeScene(tris);
  s.materials[2].alphaMode = AlphaMode::Opaque;
  s.materials[5].alphaMode = AlphaMode::Mask;
  s.materials[5].alphaCutoff = 0.3f;
  Texture checker;
  checker.width = checker.height = 2;
  checker.rgba = {255, 0, 0, 255, 0, 255, 0, 40, 0, 0, 255, 200, 255, 255, 255, 90};
  s.textures.push_back(checker);
  s.materials[8].baseColorTexture = 0;
  s.materials[10].blend = BlendMode::Additive;
  s.uvs.assign(s.positions.size(), glm::vec2(0.0f));
  for (size_t v = 0; v < s.uvs.size(); ++v)
    s.uvs[v] = glm::vec2(static_cast<float>(v % 3) * 0.7f, static_cast<float>(v % 2) * 1.3f);
  return s;
}

// The mixed scene with vertex colours on every other rectangle (some corners white, alpha below 1
// on some), its masked, textured and additive materials made plain blended ones: every tile takes
// the wide path, coloured triangles (blended and opaque) included.
Scene vertexColorScene(int size) {
  Scene s = mixedMaterialScene(size);
  s.materials[5].alphaMode = AlphaMode::Blend;
  s.materials[8].baseColorTexture = -1;
  s.materials[10].blend = BlendMode::Over;
  s.colors.assign(s.positions.size(), glm::vec4(1.0f));
  for (size_t v = 0; v < s.colors.size(); ++v)
    if ((v / 6) % 2 == 1)  // two triangles of 3 vertices per rectangle
      s.colors[v] = glm::vec4(0.2f + 0.1f * static_cast<float>(v % 7), 1.0f - 0.05f * (v % 11),
                              static_cast<float>(v % 3) * 0.4f, v % 4 == 0 ? 1.0f : 0.6f);
  return s;
}

// Textured materials of every sampler (bilinear and nearest; repeat, clamp to edge, mirrored
// repeat per axis), non-power-of-two textures with texel alpha, uv ranges far outside [0, 1]
// (the scalar wrap per lane), one beyond 1e9 (texelIndex's fmod) and one NaN, opaque, masked and
// alpha-overridden materials, vertex colours on some: every tile takes the wide path, with the
// texture sampled and the alpha test run on the lanes.
Scene texturedScene(int size) {
  Scene s = vertexColorScene(size);
  auto texture = [](int w, int h, int seed) {
    Texture t;
    t.width = w;
    t.height = h;
    for (int i = 0; i < w * h * 4; ++i)
      t.rgba.push_back(static_cast<uint8_t>((i * 37 + seed * 91 + (i / 4) * (i % 4) * 13) % 256));
    return t;
  };
  s.textures = {texture(2, 2, 1), texture(5, 3, 2), texture(7, 4, 3), texture(64, 33, 4)};
  const TextureWrap r = TextureWrap::Repeat, c = TextureWrap::ClampToEdge,
                    m = TextureWrap::MirroredRepeat;
  const TextureFilter lin = TextureFilter::Linear, nea = TextureFilter::Nearest;
  const struct {
    int material, texture;
    TextureSampler sampler;
  } textured[] = {{0, 3, {r, r, lin}}, {1, 0, {r, c, lin}}, {3, 1, {c, c, nea}},
                  {4, 2, {m, r, lin}}, {6, 3, {m, m, nea}}, {7, 1, {c, m, lin}},
                  {8, 0, {r, r, nea}}, {9, 2, {c, r, lin}}, {11, 3, {r, m, lin}}};
  for (const auto& t : textured) {
    s.materials[t.material].baseColorTexture = t.texture;
    s.materials[t.material].baseColorSampler = t.sampler;
  }
  s.materials[4].alphaMode = AlphaMode::Opaque;
  // alpha-masked: textured (texel alpha against the cutoff), textured and vertex-coloured, and
  // plain (material alpha and vertex colours)
  s.materials[3].alphaMode = s.materials[7].alphaMode = s.materials[10].alphaMode = AlphaMode::Mask;
  s.materials[3].alphaCutoff = 0.4f;
  s.materials[7].alphaCutoff = 0.25f;
  s.materials[10].alphaCutoff = 0.3f;
  s.uvs.assign(s.positions.size(), glm::vec2(0.0f));
  for (size_t v = 0; v < s.uvs.size(); ++v) {
    const float rect = static_cast<float>(v / 6);  // two triangles of 3 vertices per rectangle
    s.uvs[v] = glm::vec2(static_cast<float>(v % 3) * (0.4f + 0.3f * rect) - 0.2f * rect,
                         static_cast<float>(v % 2) * (1.1f - 0.07f * rect) + 0.05f * rect - 0.3f);
  }
  s.uvs[6 * 9] = glm::vec2(3e9f, -2e9f);  // rectangle 9: texelIndex's fmod
  s.uvs[6 * 11 + 4] = glm::vec2(std::numeric_limits<float>::quiet_NaN(), 0.5f);
  return s;
}

TEST(CaptureIsa, WidePathCapturesWhatTheScalarPathCaptures) {
  if (detectedIsa() == Isa::Scalar) GTEST_SKIP() << "no AVX2 on this CPU: only the scalar path";
  const IsaGuard guard;
  struct Case {
    std::string name;
    Scene scene;
    int width, height;
  };
  std::vector<Case> cases;
  cases.push_back({"layers", proceduralScene("layers?k=4&r=2&pd=0.55"), 97, 83});
  cases.push_back({"hairball", proceduralScene("hairball?strands=250"), 80, 72});
  cases.push_back({"mixed materials", mixedMaterialScene(70), 70, 70});
  cases.push_back({"vertex colours", vertexColorScene(70), 70, 70});
  cases.push_back({"hot pixels", test::hotPixelScene(24, 400, 7), 24, 24});
  cases.push_back({"textured", texturedScene(70), 70, 70});
  Scene overridden = texturedScene(70);
  overridden.alphaOverride = 0.45f;
  cases.push_back({"textured, alpha override", std::move(overridden), 70, 70});
  for (const Case& c : cases) {
    const Camera camera = c.scene.defaultCamera ? *c.scene.defaultCamera : test::screenCamera();
    const auto frame = test::buildFrame(c.scene, camera, c.width, c.height, 2);
    ASSERT_TRUE(frame) << c.name;
    for (const std::string preset :
         {"zbuffer", "fkb", "kplus-array", "kplus-heap", "kplus-heap+occupancy", "kplus-sb",
          "kplus-dynamic", "abuffer"}) {
      for (Compositing rule : {Compositing::KBuffer, Compositing::Hybrid}) {
        if (preset == "abuffer" && rule == Compositing::Hybrid) continue;
        // fixed k for the fixed-k presets, a budget (40 B per pixel) for the counted ones
        const bool budgeted = preset == "kplus-sb" || preset == "kplus-dynamic";
        const bool fixedK = !budgeted && preset != "abuffer" && preset != "zbuffer";
        const MethodDesc method =
            test::presetWithK(preset, fixedK ? std::optional<uint32_t>(3) : std::nullopt, rule);
        const std::optional<uint64_t> budget =
            budgeted ? std::optional<uint64_t>(static_cast<uint64_t>(c.width) * c.height * 40)
                     : std::nullopt;
        expectSameCapture(*frame, method, budget,
                          c.name + " " + method.name + " " + toString(rule));
      }
    }
  }
}

// The passes that shade every fragment (shaded_fragments.hpp: the deep k-buffer's features, the
// previous-frame cosines, the optimal oracle's pre-pass) give the same per-pixel results on the
// lanes as on the scalar loop, textured, masked and vertex-coloured triangles included.
TEST(CaptureIsa, ShadedPassesGiveWhatTheScalarPathGives) {
  if (detectedIsa() == Isa::Scalar) GTEST_SKIP() << "no AVX2 on this CPU: only the scalar path";
  const IsaGuard guard;
  Scene overridden = texturedScene(70);
  overridden.alphaOverride = 0.45f;
  const std::vector<std::pair<std::string, Scene>> scenes = {
      {"textured", texturedScene(70)},
      {"textured, alpha override", std::move(overridden)},
      {"hairball", proceduralScene("hairball?strands=250")}};
  for (const auto& [name, scene] : scenes) {
    const Camera camera = scene.defaultCamera ? *scene.defaultCamera : test::screenCamera();
    const auto frame = test::buildFrame(scene, camera, 70, 70, 2);
    ASSERT_TRUE(frame) << name;
    setActiveIsa(Isa::Scalar);
    const std::vector<FeatureAccumulator> scalarFeatures = accumulateFeatures(*frame);
    const std::vector<float> scalarCosine = nearestCosine(*frame);
    setActiveIsa(detectedIsa());
    const std::vector<FeatureAccumulator> wideFeatures = accumulateFeatures(*frame);
    const std::vector<float> wideCosine = nearestCosine(*frame);
    ASSERT_EQ(scalarFeatures.size(), wideFeatures.size());
    uint64_t covered = 0;
    ImageFeatureStats image;
    for (const FeatureAccumulator& a : scalarFeatures) image.add(a);
    for (size_t p = 0; p < scalarFeatures.size(); ++p) {
      const FeatureAccumulator &a = scalarFeatures[p], &b = wideFeatures[p];
      ASSERT_EQ(a.n, b.n) << name << " pixel " << p;
      if (a.n == 0) continue;
      ++covered;
      EXPECT_EQ(a.nearest, b.nearest) << name << " pixel " << p;
      EXPECT_EQ(a.second, b.second) << name << " pixel " << p;
      EXPECT_EQ(a.farthest, b.farthest) << name << " pixel " << p;
      EXPECT_TRUE(a.premultipliedSum == b.premultipliedSum) << name << " pixel " << p;
      EXPECT_EQ(a.premultipliedSquares, b.premultipliedSquares) << name << " pixel " << p;
      EXPECT_EQ(a.alphaSum, b.alphaSum) << name << " pixel " << p;
      EXPECT_TRUE(pixelFeatures(a, image, 1000) == pixelFeatures(b, image, 1000)) << name;
    }
    EXPECT_GT(covered, 100u) << name;
    EXPECT_TRUE(scalarCosine == wideCosine) << name << ": previous-frame cosines differ";
    // the oracle's curves through k(p), then the (already compared) capture
    const MethodDesc optimal = test::presetWithK("optimal", std::nullopt, Compositing::Hybrid);
    const uint64_t budget = 70 * 70 * 60;
    expectSameCapture(*frame, optimal, budget, name + " optimal");
  }
}

#if MFR_HAS_AVX2_KERNELS
/// encodeSrgb8x8 of 8 values (compiled for AVX2, called only where the CPU has it).
__attribute__((target("avx2"))) void encodeLanes(const float* v, int32_t* out) {
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out),
                      detail::encodeSrgb8x8(ColorTables::get(), _mm256_loadu_ps(v)));
}
#endif

// The lanes' sRGB encode (two gathers) gives the scalar encode's code: for the 64 floats on each
// side of every code boundary and of every bucket edge, on a sweep of [0, 1] and outside it.
TEST(CaptureIsa, LaneSrgbEncodeIsTheScalarEncode) {
#if MFR_HAS_AVX2_KERNELS
  if (detectedIsa() == Isa::Scalar) GTEST_SKIP() << "no AVX2 on this CPU: only the scalar path";
  std::vector<float> values = {-1.0f,
                               -0.0f,
                               0.0f,
                               1.0f,
                               2.0f,
                               std::numeric_limits<float>::quiet_NaN(),
                               std::numeric_limits<float>::infinity(),
                               -std::numeric_limits<float>::infinity()};
  const auto around = [&](float x) {
    float below = x, above = x;
    for (int i = 0; i < 64; ++i) {
      values.push_back(below = std::nextafter(below, -1.0f));
      values.push_back(above = std::nextafter(above, 2.0f));
    }
  };
  const ColorTables& t = ColorTables::get();
  for (int c = 1; c < 256; ++c) around(t.lowerBound[c]);
  for (int b = 0; b < 4096; ++b) around((static_cast<float>(b) - 0.5f) / 4095.0f);
  for (int i = 0; i <= 200000; ++i) values.push_back(static_cast<float>(i) / 200000.0f);
  while (values.size() % 8 != 0) values.push_back(0.5f);
  int mismatches = 0;
  for (size_t i = 0; i < values.size(); i += 8) {
    int32_t codes[8];
    encodeLanes(values.data() + i, codes);
    for (int lane = 0; lane < 8; ++lane)
      if (codes[lane] != encodeSrgb8(values[i + lane]) && ++mismatches <= 5)
        ADD_FAILURE() << values[i + lane] << ": lanes " << codes[lane] << ", scalar "
                      << int{encodeSrgb8(values[i + lane])};
  }
  EXPECT_EQ(mismatches, 0) << "of " << values.size() << " values";
#else
  GTEST_SKIP() << "no AVX2 kernels in this build";
#endif
}

// The branchless root replacement leaves every slot as maxHeapInsert does, on heaps of every size
// up to 12 with many equal keys (small key range).
TEST(CaptureIsa, BranchlessRootReplacementIsMaxHeapInsert) {
  std::mt19937_64 rng(12);
  for (uint32_t n = 1; n <= 12; ++n)
    for (int trial = 0; trial < 400; ++trial) {
      std::vector<FragmentNode> heap(n);
      uint32_t count = 0;
      FragmentNode evicted = 0;
      for (uint32_t i = 0; i < n; ++i)
        maxHeapInsert(heap.data(), count, n, FragmentNode{rng() % 40}, evicted);
      for (int step = 0; step < 20; ++step) {
        const FragmentNode node = rng() % 40;
        if (!(node < heap[0])) continue;  // its precondition (the k+ test passed)
        std::vector<FragmentNode> expected = heap;
        uint32_t expectedCount = n;
        FragmentNode expectedEvicted = 0;
        ASSERT_EQ(maxHeapInsert(expected.data(), expectedCount, n, node, expectedEvicted),
                  InsertOutcome::Replaced);
        EXPECT_EQ(detail::maxHeapReplaceRoot(heap.data(), n, node), expectedEvicted);
        ASSERT_EQ(heap, expected) << "n " << n << " trial " << trial << " step " << step;
      }
    }
}

}  // namespace
}  // namespace mfr
