// Depth peeling (Everitt 2001) and dual depth peeling (Bavoil & Myers 2008) on the GL engine
// (shaders/peel.frag, peel_step.comp, peel_resolve.comp):
//   - the GPU's own exact ground truth: on every real scene of ../shared/scenes, with GL's own
//     raster (--gl-raster native), peel's and dual-peel's images equal the GL A-buffer's within
//     float rounding, nothing lost, every fragment peeled (skipped when the scenes folder is
//     absent, failed naming the file when one is missing);
//   - against the CPU engine on procedural scenes with the CPU's raster (--gl-raster exact): the
//     same statistics (bytes, captured, lost, passes) and images, unbounded and with --max-peels
//     (dropped rest, hybrid tail).
// Without a GL 4.5 context the tests skip (fail under CI=true).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "../shared_scenes.hpp"
#include "../test_util.hpp"
#include "gl_engine_or_skip.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::gl {
namespace {

const glm::vec3 kBg(0.2f, 0.4f, 0.6f);

MethodDesc peelMethod(const std::string& preset, std::optional<int64_t> maxPeels = {},
                      bool hybrid = false) {
  MethodOverrides o;
  o.maxPeels = maxPeels;
  if (hybrid) o.composite = "hybrid";
  return makeMethod(preset, o).value();
}

Camera cameraOf(const Scene& scene) {
  return scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
}

// every glTF, GLB and PLY file of the shared scenes
constexpr const char* kRealScenes[] = {
    "khronos-conformance/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf",
    "khronos-conformance/MultiUVTest/glTF/MultiUVTest.gltf",
    "khronos-conformance/NegativeScaleTest/glTF/NegativeScaleTest.gltf",
    "khronos-conformance/OrientationTest/glTF/OrientationTest.gltf",
    "khronos-conformance/SimpleInstancing/glTF/SimpleInstancing.gltf",
    "khronos-conformance/SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf",
    "khronos-conformance/TextureCoordinateTest/glTF/TextureCoordinateTest.gltf",
    "khronos-conformance/TextureSettingsTest/glTF/TextureSettingsTest.gltf",
    "khronos-conformance/TextureTransformTest/glTF/TextureTransformTest.gltf",
    "khronos-conformance/TwoSidedPlane/glTF/TwoSidedPlane.gltf",
    "khronos-conformance/VertexColorTest/glTF/VertexColorTest.gltf",
    "khronos/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb",
    "khronos/GlassVaseFlowers/glTF-Binary/GlassVaseFlowers.glb",
    "khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf",
    "khronos/StainedGlassLamp/glTF-JPG-PNG/StainedGlassLamp.gltf",
    "khronos/TransmissionTest/glTF-Binary/TransmissionTest.glb",
    "stanford/bunny/bun_zipper.ply",
    "stanford/bunny/bun_zipper_res2.ply",
    "stanford/dragon/dragon_100k.ply",
};

TEST(GlPeel, EqualsTheGlABufferOnEveryRealScene) {
  if (!::mfr::test::sharedScenesPresent())
    GTEST_SKIP() << "shared scenes folder absent: " << ::mfr::test::sharedScenesRoot().string();
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", "native");
  for (const char* relative : kRealScenes) {
    SCOPED_TRACE(relative);
    ASSERT_TRUE(::mfr::test::sharedSceneExists(relative));
    auto scene = loadScene((::mfr::test::sharedScenesRoot() / relative).string());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    const View view{&*scene, cameraOf(*scene), 96, 96};
    auto prepared = gl->prepare(view);
    ASSERT_TRUE(prepared.ok()) << prepared.error().message;
    RenderOptions options;
    options.background = kBg;
    auto ab = gl->render(**prepared, methodPreset("abuffer").value(), options);
    ASSERT_TRUE(ab.ok()) << ab.error().message;
    for (const char* preset : {"peel", "dual-peel"}) {
      SCOPED_TRACE(preset);
      auto out = gl->render(**prepared, peelMethod(preset), options);
      ASSERT_TRUE(out.ok()) << out.error().message;
      // peel: the A-buffer resolve's "over" steps in the same order (float rounding at most);
      // dual-peel: its back layers blended back to front
      EXPECT_LT(::mfr::test::largestDifference(out->image, ab->image), 2e-6f);
      EXPECT_EQ(out->stats.fragmentsGenerated, ab->stats.fragmentsGenerated);
      EXPECT_EQ(out->stats.captured, ab->stats.fragmentsGenerated);
      EXPECT_EQ(out->stats.lost, 0u);
      const uint32_t maxN = ab->stats.maxDepthComplexity.value_or(0);
      ASSERT_TRUE(out->stats.peelPasses.has_value());
      // at most one pass per fragment of the deepest pixel (fewer when keys repeat)
      const uint32_t expectedMax = std::string(preset) == "peel" ? maxN : (maxN + 1) / 2;
      EXPECT_LE(*out->stats.peelPasses, std::max(expectedMax, 1u));
      EXPECT_GE(*out->stats.peelPasses, maxN > 0 ? 1u : 0u);
    }
  }
}

struct PeelCase {
  const char* scene;
  const char* method;
  std::optional<int64_t> maxPeels;
  bool hybrid;
};

class GlPeelSeam : public ::testing::TestWithParam<PeelCase> {};

// --gl-raster exact: the CPU engine's fragments, so the statistics are the CPU engine's (its
// fragment-parallel mode charges the lock word the GL capture takes) and the images agree within
// float rounding (the hybrid tail sums in arrival order, GLSL's pow).
TEST_P(GlPeelSeam, SameStatisticsAndImageAsTheCpuEngine) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", "exact");
  const PeelCase& c = GetParam();
  const Scene scene = loadScene(c.scene).value();
  const View view{&scene, cameraOf(scene), 96, 80};
  const MethodDesc method = peelMethod(c.method, c.maxPeels, c.hybrid);
  RenderOptions options;
  options.background = kBg;
  options.budgetBytes = 8u << 20;
  RenderOptions cpuOptions = options;
  cpuOptions.capture = CaptureMode::FragmentParallel;
  CpuEngine cpu(EngineOptions{2, 16});
  auto g = gl->render(view, method, options);
  auto r = cpu.render(view, method, cpuOptions);
  ASSERT_TRUE(g.ok()) << g.error().message;
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(g->stats.bytesUsed, r->stats.bytesUsed);
  EXPECT_EQ(g->stats.bytesByCategory, r->stats.bytesByCategory);
  EXPECT_EQ(g->stats.fragmentsGenerated, r->stats.fragmentsGenerated);
  EXPECT_EQ(g->stats.captured, r->stats.captured);
  EXPECT_EQ(g->stats.lost, r->stats.lost);
  EXPECT_EQ(g->stats.peelPasses, r->stats.peelPasses);
  if (c.maxPeels) {
    EXPECT_GT(r->stats.lost, 0u) << "the case should leave fragments";
  }
  std::vector<std::string> names;
  for (const PassTime& t : g->stats.passes)
    if (t.name.rfind("peel", 0) == 0) names.push_back(t.name);
  std::vector<std::string> cpuNames;
  for (const PassTime& t : r->stats.passes)
    if (t.name.rfind("peel", 0) == 0) cpuNames.push_back(t.name);
  EXPECT_EQ(names, cpuNames);
  const float tolerance = c.hybrid ? 1e-5f : 1e-6f;
  EXPECT_LT(::mfr::test::largestDifference(g->image, r->image), tolerance);
}

INSTANTIATE_TEST_SUITE_P(
    Presets, GlPeelSeam,
    ::testing::Values(PeelCase{"procedural:layers?r=2", "peel", {}, false},
                      PeelCase{"procedural:layers?r=2", "dual-peel", {}, false},
                      PeelCase{"procedural:hairball?strands=60", "peel", 3, false},
                      PeelCase{"procedural:hairball?strands=60", "dual-peel", 2, true},
                      PeelCase{"procedural:bottles?count=4", "peel", 2, true},
                      PeelCase{"procedural:bottles?count=4", "dual-peel", {}, false}),
    [](const auto& info) {
      std::string name = std::string(info.param.method) + "_" + std::to_string(info.index);
      for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return name;
    });

}  // namespace
}  // namespace mfr::gl
