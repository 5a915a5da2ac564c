// glTF COLOR_0 vertex colours on the CPU engine (issue 24): read in every accessor format glTF
// allows (float RGB / RGBA, normalized unsigned byte RGBA, normalized unsigned short RGB),
// multiplied into the base colour factor, alpha into alpha (blended, and the MASK cutoff),
// interpolated perspective-correctly. The quad of tests/gltf_vertex_colors.hpp has a colour linear
// in x, so the expected colour of a pixel is the colour at the surface point its ray hits,
// computed here from the camera's own ray (ray-plane intersection in double), the stored colour
// codes decoded as the specification says and the headlight 0.2 + 0.8 |n.v|. The Khronos
// VertexColorTest, when the shared scenes are present: the test row's checkmark patches match the
// sample row's (no cyan / magenta / yellow crosses).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "gltf_vertex_colors.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/load.hpp"
#include "shared_scenes.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::ColorFormat;
using mfr::test::Rgba;
using nlohmann::json;

constexpr int kSize = 64;
const glm::dvec3 kBackground{0.5, 0.25, 0.75};

mfr::Result<mfr::Scene> loadText(const std::string& text) {
  return mfr::test::loadGltfText(text, "mfr_vertex_colors");
}

mfr::Camera headOn() {
  return mfr::test::headOnQuadCamera();
}
mfr::Camera tilted() {
  return mfr::test::vertexColorTilted();
}

mfr::RenderOutput renderScene(const mfr::Scene& scene, const mfr::Camera& camera) {
  return mfr::test::renderAbuffer(scene, camera, kSize, kBackground);
}

json material(const Rgba& factor, const std::string& alphaMode) {
  return mfr::test::vertexColorMaterial(factor, alphaMode);
}

/// Renders `scene` and compares every pixel mfr::test::expectedQuadPixel names with its
/// expectation. Returns the pixels compared.
int expectColors(const mfr::Scene& scene, const mfr::Camera& camera, const Rgba& left,
                 const Rgba& right, const Rgba& factor, const std::string& alphaMode) {
  return mfr::test::expectQuadColors(renderScene(scene, camera).image, camera, kSize, left, right,
                                     factor, alphaMode, kBackground);
}

const Rgba kLeft{1.0, 0.2, 0.0, 1.0}, kRight{0.1, 0.9, 0.7, 0.3};

class VertexColors : public ::testing::TestWithParam<ColorFormat> {};

TEST_P(VertexColors, LoaderDecodesTheFormat) {
  const ColorFormat f = GetParam();
  const mfr::Scene scene =
      loadText(mfr::test::vertexColorQuadGltf(f, kLeft, kRight, json())).value();
  ASSERT_EQ(scene.colors.size(), 4u);
  const Rgba l = mfr::test::storedColor(f, kLeft), r = mfr::test::storedColor(f, kRight);
  const Rgba* corner[4] = {&l, &r, &r, &l};
  for (int v = 0; v < 4; ++v)
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(scene.colors[v][c], (*corner[v])[c], 1e-7) << "vertex " << v << " channel " << c;
  EXPECT_TRUE(scene.hasVertexColor(0));
}

TEST_P(VertexColors, BlendedQuadHeadOnMultipliesFactorAndAlpha) {
  const ColorFormat f = GetParam();
  const Rgba factor{0.8, 0.6, 1.0, 0.9};
  const mfr::Scene scene =
      loadText(mfr::test::vertexColorQuadGltf(f, kLeft, kRight, material(factor, "BLEND"))).value();
  EXPECT_GT(expectColors(scene, headOn(), mfr::test::storedColor(f, kLeft),
                         mfr::test::storedColor(f, kRight), factor, "BLEND"),
            3000);
}

TEST_P(VertexColors, TiltedQuadIsPerspectiveCorrect) {
  const ColorFormat f = GetParam();
  const Rgba factor{1.0, 0.7, 0.9, 1.0};
  const mfr::Scene scene =
      loadText(mfr::test::vertexColorQuadGltf(f, kLeft, kRight, material(factor, "OPAQUE")))
          .value();
  EXPECT_GT(expectColors(scene, tilted(), mfr::test::storedColor(f, kLeft),
                         mfr::test::storedColor(f, kRight), factor, "OPAQUE"),
            800);
}

INSTANTIATE_TEST_SUITE_P(Formats, VertexColors,
                         ::testing::Values(ColorFormat::FloatRgb, ColorFormat::FloatRgba,
                                           ColorFormat::Unorm8Rgba, ColorFormat::Unorm16Rgb),
                         [](const auto& info) { return std::string(toString(info.param)); });

// The near plane cuts the tilted quad: the clipped polygon's new corners get colours interpolated
// along its edges (the clipper's), which must continue the same linear colour.
TEST(VertexColorAlpha, ClippedAtTheNearPlane) {
  mfr::Camera camera = tilted();
  camera.zNear = 2.6f;
  camera.zFar = 10.0f;
  const Rgba factor{0.9, 1.0, 0.8, 0.75};
  const mfr::Scene scene =
      loadText(mfr::test::vertexColorQuadGltf(ColorFormat::FloatRgba, kLeft, kRight,
                                              material(factor, "BLEND")))
          .value();
  EXPECT_GT(expectColors(scene, camera, kLeft, kRight, factor, "BLEND"), 800);
}

// Vertex alpha takes part in the MASK test: alpha 1 at x = -1 to 0 at x = 1 cuts the quad at x = 0.
TEST(VertexColorAlpha, MaskCutoffSeesTheVertexAlpha) {
  const Rgba left{0.2, 0.4, 1.0, 1.0}, right{0.9, 0.1, 0.3, 0.0}, factor{1.0, 1.0, 1.0, 1.0};
  const mfr::Scene scene = loadText(mfr::test::vertexColorQuadGltf(ColorFormat::FloatRgba, left,
                                                                   right, material(factor, "MASK")))
                               .value();
  EXPECT_GT(expectColors(scene, tilted(), left, right, factor, "MASK"), 800);
}

// A white COLOR_0 is no colour: the triangles are shaded without it (Scene::hasVertexColor), so
// the image is byte for byte the one without the attribute, on a view where the interpolated white
// would not be exactly 1 everywhere.
TEST(VertexColorAlpha, WhiteColorsRenderAsNoColors) {
  const Rgba white{1.0, 1.0, 1.0, 1.0};
  const mfr::Scene scene =
      loadText(mfr::test::vertexColorQuadGltf(ColorFormat::FloatRgba, white, white,
                                              material({0.3, 0.6, 0.9, 0.7}, "BLEND")))
          .value();
  ASSERT_EQ(scene.colors.size(), 4u);
  EXPECT_FALSE(scene.hasVertexColor(0));
  EXPECT_FALSE(scene.hasVertexColor(1));
  mfr::Scene plain = scene;
  plain.colors.clear();
  const mfr::RenderOutput a = renderScene(scene, tilted()), b = renderScene(plain, tilted());
  ASSERT_GT(a.stats.fragmentsGenerated, 1000u);
  EXPECT_TRUE(a.image.pixels == b.image.pixels);
  EXPECT_TRUE(a.nodes == b.nodes);
}

// Primitives without COLOR_0 in a scene with some get white (and are shaded without colours).
TEST(VertexColorAlpha, PrimitivesWithoutColorsAreWhite) {
  json doc = json::parse(mfr::test::vertexColorQuadGltf(ColorFormat::FloatRgb, kLeft, kRight,
                                                        material({1, 1, 1, 1}, "OPAQUE")));
  json second = doc["meshes"][0]["primitives"][0];
  second["attributes"].erase("COLOR_0");
  doc["meshes"][0]["primitives"].push_back(second);
  const mfr::Scene scene = loadText(doc.dump()).value();
  ASSERT_EQ(scene.colors.size(), 8u);
  for (size_t v = 4; v < 8; ++v) EXPECT_EQ(scene.colors[v], glm::vec4(1.0f)) << v;
  EXPECT_TRUE(scene.hasVertexColor(0) && scene.hasVertexColor(1));
  EXPECT_FALSE(scene.hasVertexColor(2) || scene.hasVertexColor(3));
  // without any COLOR_0 the scene has no colours at all
  doc["meshes"][0]["primitives"][0]["attributes"].erase("COLOR_0");
  EXPECT_TRUE(loadText(doc.dump()).value().colors.empty());
}

// Formats glTF does not allow for COLOR_0 are one line naming the file and the attribute.
TEST(VertexColorAlpha, InvalidAccessorsAreOneLineErrors) {
  const json base =
      json::parse(mfr::test::vertexColorQuadGltf(ColorFormat::Unorm8Rgba, kLeft, kRight, json()));
  auto expectError = [&](json doc, const std::string& needle) {
    SCOPED_TRACE(needle);
    auto scene = loadText(doc.dump());
    ASSERT_FALSE(scene.ok());
    const std::string& message = scene.error().message;
    EXPECT_NE(message.find(".gltf: mesh 0"), std::string::npos) << message;
    EXPECT_NE(message.find("COLOR_0"), std::string::npos) << message;
    EXPECT_NE(message.find(needle), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  };
  json doc = base;
  doc["accessors"][2]["normalized"] = false;  // integers must be normalized
  expectError(doc, "normalized unsigned byte");
  doc = base;
  doc["accessors"][2]["type"] = "SCALAR";
  doc["accessors"][2]["count"] = 16;
  expectError(doc, "VEC3 or VEC4");
  doc = base;
  doc["accessors"][2]["count"] = 3;
  expectError(doc, "count differs");
}

// The Khronos VertexColorTest (README: the top "test" row's checkmarks, multiplied by red, green
// and blue vertex colours, must look like the bottom "sample" row's, multiplied by white; without
// vertex colours each test checkmark shows a cyan, magenta or yellow X, the channels the colours
// zero). Counted over the framed render: pixels of a secondary colour (two channels lit, the
// third dark) are the Xs: none with the colours, many without them (the same scene, colours
// dropped, so the check can fail); the red, green and blue checkmarks of both rows are there.
TEST(VertexColorConformance, TestRowShowsNoCrosses) {
  MFR_SHARED_SCENE(path, "khronos-conformance/VertexColorTest/glTF/VertexColorTest.gltf");
  const mfr::Scene scene = mfr::loadScene(path.string()).value();
  ASSERT_EQ(scene.colors.size(), scene.positions.size());
  const mfr::Camera camera = mfr::frameBounds(mfr::sceneBounds(scene));
  struct Counts {
    int secondary = 0, red = 0, green = 0;
  };
  auto count = [&](const mfr::Scene& s) {
    auto frame = mfr::RasterFrame::build(s, camera, mfr::RasterOptions{256, 192, 16, 2});
    EXPECT_TRUE(frame.ok());
    mfr::RenderOptions options;
    options.background = glm::vec3(1.0f);
    const mfr::RenderOutput out =
        mfr::render(*frame, mfr::methodPreset("abuffer").value(), options).value();
    Counts c;
    for (int y = 0; y < 192; ++y)
      for (int x = 0; x < 256; ++x) {
        const glm::vec3 p = out.image.at(x, y);
        const int lit = (p.r > 0.3f) + (p.g > 0.3f) + (p.b > 0.3f);
        const int dark = (p.r < 0.05f) + (p.g < 0.05f) + (p.b < 0.05f);
        c.secondary += lit == 2 && dark == 1;
        c.red += p.r > 0.3f && p.g < 0.05f && p.b < 0.05f;
        c.green += p.g > 0.3f && p.r < 0.05f && p.b < 0.05f;
      }
    return c;
  };
  const Counts with = count(scene);
  mfr::Scene without = scene;
  without.colors.clear();
  const Counts ignored = count(without);
  std::printf(
      "[ VertexColorTest ] secondary-colour pixels: %d with COLOR_0, %d without; red %d, "
      "green %d\n",
      with.secondary, ignored.secondary, with.red, with.green);
  EXPECT_LE(with.secondary, 3);
  EXPECT_GT(ignored.secondary, 200);
  EXPECT_GT(with.red, 300);  // both rows' red checkmarks
  EXPECT_GT(with.green, 300);
  EXPECT_NEAR(static_cast<double>(with.red) / with.green, 1.0, 0.35);  // same shapes
}

}  // namespace
