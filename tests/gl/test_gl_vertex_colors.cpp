// glTF COLOR_0 vertex colours and KHR_texture_transform on the GL engine (issue 24). The quad of
// tests/gltf_vertex_colors.hpp in each COLOR_0 format, blended head-on and opaque seen tilted
// (perspective-correct), and a MASK cutoff on the vertex alpha: every pixel against the colour
// computed independently (mfr::test::expectedQuadPixel), on both rasters; the exact raster also
// equals the CPU engine bit for bit (n(p) and the image), the native one within test_gl_native's
// agreement. A scene whose COLOR_0 is all white renders exactly as without it (exact raster: bit
// for bit). The Khronos VertexColorTest and TextureTransformTest agree with the CPU engine when
// the shared scenes are present. Without a GL 4.5 context the tests skip (fail under CI=true).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../gltf_vertex_colors.hpp"
#include "../shared_scenes.hpp"
#include "gl_engine_or_skip.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::gl {
namespace {

namespace fs = std::filesystem;
using mfr::test::ColorFormat;
using mfr::test::Rgba;
using nlohmann::json;

constexpr int kSize = 64;
const glm::dvec3 kBackground{0.5, 0.25, 0.75};
const Rgba kLeft{1.0, 0.2, 0.0, 1.0}, kRight{0.1, 0.9, 0.7, 0.3};

Scene loadText(const std::string& text) {
  auto scene = mfr::test::loadGltfText(text, "mfr_gl_vertex_colors");
  EXPECT_TRUE(scene.ok()) << scene.error().message;
  return std::move(scene.value());
}

struct Rendered {
  std::vector<uint32_t> counts;
  RenderOutput out;
};

Rendered renderOn(Engine& engine, const Scene& scene, const Camera& camera, int width, int height) {
  const View view{&scene, camera, width, height};
  auto prepared = engine.prepare(view);
  EXPECT_TRUE(prepared.ok()) << (prepared.ok() ? "" : prepared.error().message);
  if (!prepared.ok()) return {};
  Rendered r;
  r.counts = engine.countFragments(**prepared).value();
  RenderOptions options;
  options.background = glm::vec3(kBackground);
  auto out = engine.render(**prepared, methodPreset("abuffer").value(), options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  if (out.ok()) r.out = std::move(*out);
  return r;
}

/// The GL engine's render of `scene` against the CPU engine's: exact: n(p) and the image's bytes
/// equal; native: n(p) equal on 99.9% of the pixels, mean LDR-FLIP at most 2e-3. Returns the GL
/// render.
Rendered expectAgreement(Engine& gl, const std::string& raster, const Scene& scene,
                         const Camera& camera, int width, int height) {
  CpuEngine cpu(EngineOptions{2, 16});
  Rendered g = renderOn(gl, scene, camera, width, height);
  const Rendered c = renderOn(cpu, scene, camera, width, height);
  EXPECT_EQ(g.counts.size(), c.counts.size());
  size_t differ = 0;
  for (size_t p = 0; p < c.counts.size() && p < g.counts.size(); ++p)
    differ += g.counts[p] != c.counts[p];
  const Image8 gi = encodeSrgb(g.out.image), ci = encodeSrgb(c.out.image);
  const double flip = computeFlip(ci, gi).value().mean;
  std::printf("[ colour ] %s %dx%d: n(p) differs at %zu pixels, FLIP %.6f\n", raster.c_str(), width,
              height, differ, flip);
  if (raster == "exact") {
    EXPECT_EQ(g.counts, c.counts);
    EXPECT_EQ(gi.rgba, ci.rgba);
  } else {
    EXPECT_LE(static_cast<double>(differ), 1e-3 * static_cast<double>(c.counts.size()));
    EXPECT_LE(flip, 2e-3);
  }
  return g;
}

/// Every comparable pixel of the GL render against mfr::test::expectedQuadPixel (0.01 linear:
/// sRGB8 fragment colours and 8-bit alpha). Returns the pixels compared.
int expectColors(const RenderOutput& out, const Camera& camera, const Rgba& left, const Rgba& right,
                 const Rgba& factor, const std::string& alphaMode) {
  return mfr::test::expectQuadColors(out.image, camera, kSize, left, right, factor, alphaMode,
                                     kBackground);
}

class GlVertexColors : public ::testing::TestWithParam<const char*> {};

TEST_P(GlVertexColors, EveryFormatMatchesTheExpectedColours) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", GetParam());
  for (const ColorFormat f : {ColorFormat::FloatRgb, ColorFormat::FloatRgba,
                              ColorFormat::Unorm8Rgba, ColorFormat::Unorm16Rgb}) {
    SCOPED_TRACE(toString(f));
    const Rgba left = mfr::test::storedColor(f, kLeft), right = mfr::test::storedColor(f, kRight);
    const Rgba blendFactor{0.8, 0.6, 1.0, 0.9}, opaqueFactor{1.0, 0.7, 0.9, 1.0};
    const Scene blended = loadText(mfr::test::vertexColorQuadGltf(
        f, kLeft, kRight, mfr::test::vertexColorMaterial(blendFactor, "BLEND")));
    const Camera headOn = mfr::test::headOnQuadCamera(), tilted = mfr::test::vertexColorTilted();
    Rendered g = expectAgreement(*gl, GetParam(), blended, headOn, kSize, kSize);
    EXPECT_GT(expectColors(g.out, headOn, left, right, blendFactor, "BLEND"), 3000);
    const Scene opaque = loadText(mfr::test::vertexColorQuadGltf(
        f, kLeft, kRight, mfr::test::vertexColorMaterial(opaqueFactor, "OPAQUE")));
    g = expectAgreement(*gl, GetParam(), opaque, tilted, kSize, kSize);
    EXPECT_GT(expectColors(g.out, tilted, left, right, opaqueFactor, "OPAQUE"), 800);
  }
}

TEST_P(GlVertexColors, MaskCutoffSeesTheVertexAlpha) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", GetParam());
  const Rgba left{0.2, 0.4, 1.0, 1.0}, right{0.9, 0.1, 0.3, 0.0}, factor{1.0, 1.0, 1.0, 1.0};
  const Scene scene = loadText(mfr::test::vertexColorQuadGltf(
      ColorFormat::FloatRgba, left, right, mfr::test::vertexColorMaterial(factor, "MASK")));
  const Camera tilted = mfr::test::vertexColorTilted();
  const Rendered g = expectAgreement(*gl, GetParam(), scene, tilted, kSize, kSize);
  EXPECT_GT(expectColors(g.out, tilted, left, right, factor, "MASK"), 800);
}

// The near plane cuts the tilted quad: the geometry shader's clipper interpolates the colours as
// the CPU engine's does.
TEST_P(GlVertexColors, ClippedAtTheNearPlane) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", GetParam());
  Camera camera = mfr::test::vertexColorTilted();
  camera.zNear = 2.6f;
  camera.zFar = 10.0f;
  const Rgba factor{0.9, 1.0, 0.8, 0.75};
  const Scene scene = loadText(mfr::test::vertexColorQuadGltf(
      ColorFormat::FloatRgba, kLeft, kRight, mfr::test::vertexColorMaterial(factor, "BLEND")));
  const Rendered g = expectAgreement(*gl, GetParam(), scene, camera, kSize, kSize);
  EXPECT_GT(expectColors(g.out, camera, kLeft, kRight, factor, "BLEND"), 800);
}

TEST_P(GlVertexColors, WhiteColorsRenderAsNoColors) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", GetParam());
  const Rgba white{1.0, 1.0, 1.0, 1.0};
  const Scene scene = loadText(mfr::test::vertexColorQuadGltf(
      ColorFormat::FloatRgba, white, white,
      mfr::test::vertexColorMaterial({0.3, 0.6, 0.9, 0.7}, "BLEND")));
  Scene plain = scene;
  plain.colors.clear();
  const Camera tilted = mfr::test::vertexColorTilted();
  const Rendered a = renderOn(*gl, scene, tilted, kSize, kSize);
  const Rendered b = renderOn(*gl, plain, tilted, kSize, kSize);
  ASSERT_GT(a.out.stats.fragmentsGenerated, 1000u);
  EXPECT_EQ(a.counts, b.counts);
  if (std::string(GetParam()) == "exact") {
    EXPECT_TRUE(a.out.image.pixels == b.out.image.pixels);
  } else {  // GL's interpolation of white: within a code of the sRGB8 fragment colour
    const double flip = computeFlip(encodeSrgb(a.out.image), encodeSrgb(b.out.image)).value().mean;
    EXPECT_LE(flip, 2e-3);
  }
}

TEST_P(GlVertexColors, VertexColorTestAgrees) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", GetParam());
  MFR_SHARED_SCENE(path, "khronos-conformance/VertexColorTest/glTF/VertexColorTest.gltf");
  const Scene scene = loadScene(path.string()).value();
  ASSERT_FALSE(scene.colors.empty());
  expectAgreement(*gl, GetParam(), scene, frameBounds(sceneBounds(scene)), 96, 64);
}

TEST_P(GlVertexColors, TextureTransformTestAgrees) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", GetParam());
  MFR_SHARED_SCENE(path, "khronos-conformance/TextureTransformTest/glTF/TextureTransformTest.gltf");
  const Scene scene = loadScene(path.string()).value();
  expectAgreement(*gl, GetParam(), scene, frameBounds(sceneBounds(scene)), 96, 64);
}

INSTANTIATE_TEST_SUITE_P(Rasters, GlVertexColors, ::testing::Values("exact", "native"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace mfr::gl
