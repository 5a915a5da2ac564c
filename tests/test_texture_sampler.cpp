// Per-texture sampler wrap modes and filters (issue 24): glTF REPEAT, CLAMP_TO_EDGE and
// MIRRORED_REPEAT per axis, NEAREST and LINEAR magnification, read by the glTF loader and applied
// by the CPU engine's sampleTexture (the GL engine's rasters run the same rule:
// tests/gl/test_gl_cull.cpp). A hand-made quad whose texture coordinates run from -1.5 to 2.5 on
// both axes is rendered head-on through a 2-degree field of view (|n.v| within 3e-4 of 1), and
// every pixel is compared with a sample computed here, in double, with wrap rules written
// independently of the engine's (mirroring by the parity of the period).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "gltf_textured_quad.hpp"
#include "mfr/core/color.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/load.hpp"
#include "quad_checks.hpp"
#include "shared_scenes.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kRepeat = 10497, kClamp = 33071, kMirror = 33648, kNearest = 9728, kLinear = 9729;
constexpr int kSize = 64;  // image side: the quad fills it, 4 pixels per texel across u

mfr::Result<mfr::Scene> loadText(const std::string& text) {
  return mfr::test::loadGltfText(text, "mfr_sampler");
}

/// Head-on camera whose view is exactly the quad (x, y in [-1, 1]).
mfr::Camera headOn() {
  return mfr::test::headOnQuadCamera();
}

/// Texel index i wrapped into [0, n), written independently of method_math::wrapTexel.
int wrapReference(int i, int n, int mode) {
  if (mode == kClamp) return std::clamp(i, 0, n - 1);
  const int period = static_cast<int>(std::floor(static_cast<double>(i) / n));  // which copy
  const int r = i - period * n;                                                 // in [0, n)
  if (mode == kRepeat) return r;
  return period % 2 == 0 ? r : n - 1 - r;  // odd copies are mirrored
}

glm::dvec3 texelLinear(int x, int y) {
  const auto& t = mfr::test::kQuadTexels[static_cast<size_t>(y * mfr::test::kQuadTextureWidth + x)];
  return {t[0] / 255.0, t[1] / 255.0, t[2] / 255.0};  // 0 and 255 decode exactly
}

/// The expected linear colour at texture coordinate (u, v); nullopt-like flag `ambiguous` when a
/// nearest sample lies within 0.3 texel of a texel edge (skipped: float rounding may pick either).
glm::dvec3 expected(double u, double v, int wrapS, int wrapT, bool nearest, bool& ambiguous) {
  const int w = mfr::test::kQuadTextureWidth, h = mfr::test::kQuadTextureHeight;
  if (nearest) {
    const double x = u * w, y = v * h;
    ambiguous = std::abs(x - std::floor(x) - 0.5) > 0.2 || std::abs(y - std::floor(y) - 0.5) > 0.2;
    return texelLinear(wrapReference(static_cast<int>(std::floor(x)), w, wrapS),
                       wrapReference(static_cast<int>(std::floor(y)), h, wrapT));
  }
  ambiguous = false;
  const double x = u * w - 0.5, y = v * h - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double ax = x - x0, ay = y - y0;
  auto at = [&](int i, int j) {
    return texelLinear(wrapReference(i, w, wrapS), wrapReference(j, h, wrapT));
  };
  return (at(x0, y0) * (1 - ax) + at(x0 + 1, y0) * ax) * (1 - ay) +
         (at(x0, y0 + 1) * (1 - ax) + at(x0 + 1, y0 + 1) * ax) * ay;
}

/// KHR_texture_transform's uv' = T * R * S * (u, v, 1) with the matrices as the extension's
/// specification writes them (row-major 3x3), multiplied out here.
glm::dvec2 transformUv(const json& t, glm::dvec2 uv) {
  const json offset = t.value("offset", json::array({0.0, 0.0}));
  const json scale = t.value("scale", json::array({1.0, 1.0}));
  const double r = t.value("rotation", 0.0);
  const double T[3][3] = {
      {1, 0, offset[0].get<double>()}, {0, 1, offset[1].get<double>()}, {0, 0, 1}};
  const double R[3][3] = {{std::cos(r), std::sin(r), 0}, {-std::sin(r), std::cos(r), 0}, {0, 0, 1}};
  const double S[3][3] = {
      {scale[0].get<double>(), 0, 0}, {0, scale[1].get<double>(), 0}, {0, 0, 1}};
  double TR[3][3] = {}, M[3][3] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) TR[i][j] += T[i][k] * R[k][j];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) M[i][j] += TR[i][k] * S[k][j];
  return {M[0][0] * uv.x + M[0][1] * uv.y + M[0][2], M[1][0] * uv.x + M[1][1] * uv.y + M[1][2]};
}

/// Renders the quad of glTF text `gltf` and compares every unambiguous pixel with `expected` at
/// the quad's texture coordinate, transformed by `transform` (a KHR_texture_transform object;
/// null: none); returns how many pixels were compared.
int expectSamplesOf(const std::string& gltf, int wrapS, int wrapT, bool nearest,
                    const json* transform = nullptr) {
  auto scene = loadText(gltf);
  EXPECT_TRUE(scene.ok()) << scene.error().message;
  if (!scene.ok()) return 0;
  auto frame = mfr::RasterFrame::build(*scene, headOn(), mfr::RasterOptions{kSize, kSize, 16, 2});
  EXPECT_TRUE(frame.ok()) << frame.error().message;
  mfr::RenderOptions options;
  options.background = glm::vec3(0.5f);
  auto out = mfr::render(*frame, mfr::methodPreset("abuffer").value(), options);
  EXPECT_TRUE(out.ok()) << out.error().message;
  if (!out.ok()) return 0;
  int compared = 0, wrong = 0;
  for (int py = 0; py < kSize; ++py)
    for (int px = 0; px < kSize; ++px) {
      const double x = 2.0 * (px + 0.5) / kSize - 1.0, y = 1.0 - 2.0 * (py + 0.5) / kSize;
      bool ambiguous = false;
      glm::dvec2 uv(mfr::test::quadU(x), mfr::test::quadV(y));
      if (transform) uv = transformUv(*transform, uv);
      const glm::dvec3 e = expected(uv.x, uv.y, wrapS, wrapT, nearest, ambiguous);
      if (ambiguous) continue;
      ++compared;
      // |n.v| >= 0.9997 head-on
      mfr::test::expectLinearPixel(out->image.at(px, py), e, px, py, wrong);
    }
  EXPECT_EQ(wrong, 0) << "of " << compared << " pixels";
  return compared;
}

/// Renders the quad under `sampler` (null: none); see expectSamplesOf.
int expectSamples(const json* sampler, int wrapS, int wrapT, bool nearest) {
  return expectSamplesOf(mfr::test::texturedQuadGltf(sampler), wrapS, wrapT, nearest);
}

json samplerJson(int wrapS, int wrapT, int magFilter) {
  return {{"wrapS", wrapS}, {"wrapT", wrapT}, {"magFilter", magFilter}, {"minFilter", 9987}};
}

struct WrapCase {
  int wrapS, wrapT;
};

class TextureSampler : public ::testing::TestWithParam<WrapCase> {};

TEST_P(TextureSampler, NearestMatchesHandDerivedTexels) {
  const json sampler = samplerJson(GetParam().wrapS, GetParam().wrapT, kNearest);
  EXPECT_GT(expectSamples(&sampler, GetParam().wrapS, GetParam().wrapT, true), 400);
}

TEST_P(TextureSampler, LinearMatchesHandDerivedBlend) {
  const json sampler = samplerJson(GetParam().wrapS, GetParam().wrapT, kLinear);
  EXPECT_EQ(expectSamples(&sampler, GetParam().wrapS, GetParam().wrapT, false), kSize * kSize);
}

INSTANTIATE_TEST_SUITE_P(Wraps, TextureSampler,
                         ::testing::Values(WrapCase{kRepeat, kRepeat}, WrapCase{kClamp, kClamp},
                                           WrapCase{kMirror, kMirror}, WrapCase{kRepeat, kClamp},
                                           WrapCase{kMirror, kRepeat}, WrapCase{kClamp, kMirror}),
                         [](const auto& info) {
                           auto name = [](int mode) {
                             return mode == kRepeat  ? std::string("Repeat")
                                    : mode == kClamp ? std::string("Clamp")
                                                     : std::string("Mirror");
                           };
                           return name(info.param.wrapS) + name(info.param.wrapT);
                         });

// glTF defaults: no sampler, or one without fields, repeats on both axes and filters linearly.
TEST(TextureSamplerDefaults, AbsentSamplerOrFieldsRepeatLinearly) {
  EXPECT_EQ(expectSamples(nullptr, kRepeat, kRepeat, false), kSize * kSize);
  const json empty = json::object();
  EXPECT_EQ(expectSamples(&empty, kRepeat, kRepeat, false), kSize * kSize);
  const json onlyNearest = {{"magFilter", kNearest}};
  EXPECT_GT(expectSamples(&onlyNearest, kRepeat, kRepeat, true), 400);
}

TEST(TextureSamplerDefaults, LoaderRecordsTheSampler) {
  const json sampler = samplerJson(kClamp, kMirror, kNearest);
  const mfr::Scene scene = loadText(mfr::test::texturedQuadGltf(&sampler)).value();
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].baseColorSampler.wrapS, mfr::TextureWrap::ClampToEdge);
  EXPECT_EQ(scene.materials[0].baseColorSampler.wrapT, mfr::TextureWrap::MirroredRepeat);
  EXPECT_EQ(scene.materials[0].baseColorSampler.filter, mfr::TextureFilter::Nearest);
}

// An enum value glTF does not define is one line naming the file, the sampler and the field.
TEST(TextureSamplerDefaults, UnknownEnumIsAOneLineError) {
  for (const auto& [field, value] : {std::pair<const char*, int>{"wrapS", 12345},
                                     {"wrapT", 9729},
                                     {"magFilter", 9984},
                                     {"minFilter", 1}}) {
    SCOPED_TRACE(field);
    json sampler = samplerJson(kRepeat, kRepeat, kLinear);
    sampler[field] = value;
    sampler["name"] = "odd";
    auto scene = loadText(mfr::test::texturedQuadGltf(&sampler));
    ASSERT_FALSE(scene.ok());
    const std::string& message = scene.error().message;
    EXPECT_NE(message.find(".gltf: sampler 0"), std::string::npos) << message;
    EXPECT_NE(message.find("odd"), std::string::npos) << message;
    EXPECT_NE(message.find(std::string(field) + " " + std::to_string(value)), std::string::npos)
        << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// KHR_texture_transform on the base colour texture (issue 24): offset, rotation and scale applied
// as the extension's T * R * S to the texture coordinates, before the sampler wraps them; its
// texCoord picks the coordinate set over the texture's own.
json withTransform(const json* sampler, const json& transform) {
  json doc = json::parse(mfr::test::texturedQuadGltf(sampler));
  doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
      {"KHR_texture_transform", transform}};
  doc["extensionsUsed"] = {"KHR_texture_transform"};
  return doc;
}

TEST(TextureTransform, OffsetRotationScaleAsTheExtensionsMatrix) {
  const json transform = {{"offset", {0.25, -0.5}}, {"rotation", 0.3}, {"scale", {0.5, 2.0}}};
  for (const int filter : {kNearest, kLinear}) {
    SCOPED_TRACE(filter);
    const json sampler = samplerJson(kRepeat, kMirror, filter);
    const int compared = expectSamplesOf(withTransform(&sampler, transform).dump(), kRepeat,
                                         kMirror, filter == kNearest, &transform);
    EXPECT_GT(compared, filter == kNearest ? 200 : kSize * kSize - 1);
  }
  // required by the file: implemented, so loaded
  json doc = withTransform(nullptr, transform);
  doc["extensionsRequired"] = {"KHR_texture_transform"};
  EXPECT_EQ(expectSamplesOf(doc.dump(), kRepeat, kRepeat, false, &transform), kSize * kSize);
}

TEST(TextureTransform, TexCoordOverridesTheTexturesSet) {
  const json sampler = samplerJson(kClamp, kRepeat, kLinear);
  const json transform = {{"texCoord", 1}, {"rotation", -0.7}, {"offset", {0.1, 0.2}}};
  json doc = withTransform(&sampler, transform);
  // TEXCOORD_0 all zeros (an accessor without a buffer view), TEXCOORD_1 the quad's coordinates
  doc["accessors"].push_back({{"componentType", 5126}, {"count", 4}, {"type", "VEC2"}});
  auto& attributes = doc["meshes"][0]["primitives"][0]["attributes"];
  attributes["TEXCOORD_1"] = attributes["TEXCOORD_0"];
  attributes["TEXCOORD_0"] = doc["accessors"].size() - 1;
  EXPECT_EQ(expectSamplesOf(doc.dump(), kClamp, kRepeat, false, &transform), kSize * kSize);
  // the texture's own texCoord without the extension's: set 1 as well, untransformed
  auto& info = doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"];
  info.erase("extensions");
  info["texCoord"] = 1;
  EXPECT_EQ(expectSamplesOf(doc.dump(), kClamp, kRepeat, false), kSize * kSize);
}

TEST(TextureTransform, MalformedFieldsAreOneLineErrors) {
  for (const json& transform : {json{{"offset", {0.1}}}, json{{"rotation", "half"}},
                                json{{"scale", {1.0, "two"}}}, json{{"texCoord", -1}}}) {
    SCOPED_TRACE(transform.dump());
    json doc = withTransform(nullptr, transform);
    doc["materials"][0]["name"] = "turned";
    auto scene = loadText(doc.dump());
    ASSERT_FALSE(scene.ok());
    const std::string& message = scene.error().message;
    EXPECT_NE(message.find(".gltf: material 0"), std::string::npos) << message;
    EXPECT_NE(message.find("turned"), std::string::npos) << message;
    EXPECT_NE(message.find("KHR_texture_transform"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// The Khronos TextureTransformTest (README), seen head-on from far away (|n.v| >= 0.998; world
// (x, y) at pixel ((x / 1.8 + 1) W / 2, (1 - y / 1.2) H / 2)). Top row: uv (0, 0)-(0.5, 0.5)
// offset by (0.5, 0), (0, 0.5), (0.5, 0.5) shows UV.png's green "U", blue "V" and cyan "UV"
// quadrants; the yellow crossed circle (offset not applied) must not show. Bottom row: the arrow
// (black) of the rotation, scale and combined quads must end next to the green "correct" marker,
// neither the yellow "not supported" nor the red "error" marker (world positions from the file's
// nodes).
TEST(TextureTransform, KhronosTextureTransformTest) {
  MFR_SHARED_SCENE(path, "khronos-conformance/TextureTransformTest/glTF/TextureTransformTest.gltf");
  const mfr::Scene scene = mfr::loadScene(path.string()).value();
  constexpr int W = 480, H = 320;
  mfr::Camera camera;
  camera.eye = {0.0f, 0.0f, 20.0f};
  camera.target = {0.0f, 0.0f, 0.0f};
  camera.fovYDegrees = static_cast<float>(2.0 * glm::degrees(std::atan(1.2 / 20.0)));
  auto frame = mfr::RasterFrame::build(scene, camera, mfr::RasterOptions{W, H, 16, 2});
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  mfr::RenderOptions options;
  options.background = glm::vec3(1.0f);
  const mfr::RenderOutput out =
      mfr::render(*frame, mfr::methodPreset("abuffer").value(), options).value();
  auto pixelOf = [&](double x, double y) {
    return glm::ivec2(static_cast<int>(std::floor((x / 1.8 + 1.0) / 2.0 * W)),
                      static_cast<int>(std::floor((1.0 - y / 1.2) / 2.0 * H)));
  };
  // top row: the inner 80% of each quad
  const double centres[3] = {-1.1, 0.0, 1.1};
  const glm::bvec3 quadrant[3] = {{false, true, false}, {false, false, true}, {false, true, true}};
  for (int q = 0; q < 3; ++q) {
    SCOPED_TRACE("top quad " + std::to_string(q));
    const glm::ivec2 lo = pixelOf(centres[q] - 0.4, 0.95), hi = pixelOf(centres[q] + 0.4, 0.15);
    int expected = 0, yellow = 0, total = 0;
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) {
        const glm::vec3 p = out.image.at(x, y);
        const glm::bvec3 lit(p.r > 0.3f, p.g > 0.3f, p.b > 0.3f);
        const glm::bvec3 dark(p.r < 0.05f, p.g < 0.05f, p.b < 0.05f);
        ++total;
        bool match = true;
        for (int c = 0; c < 3; ++c) match = match && (quadrant[q][c] ? lit[c] : dark[c]);
        expected += match;
        yellow += lit.r && lit.g && dark.b;
      }
    EXPECT_EQ(yellow, 0);
    EXPECT_GT(expected, total / 2) << "of " << total;  // the white checkmark covers the rest
  }
  // bottom row: black pixels within 0.22 of each marker's centre (markers 0.1 or 0.15 wide, at
  // least 0.37 apart)
  struct Marker {
    glm::dvec2 at;
    double size;
    bool touched;
  };
  const Marker markers[] = {
      {{-1.1 - 0.0790482, -0.55 - 0.5162675}, 0.075, true},   // rotation: correct
      {{-1.1 + 0.2778175, -0.55 - 0.2778175}, 0.075, false},  // not supported
      {{-1.1 + 0.5162675, -0.55 + 0.0790482}, 0.075, false},  // error
      {{0.0185450, -0.55 - 0.0185450}, 0.05, true},           // scale: correct
      {{0.2778175, -0.55 - 0.2778175}, 0.075, false},         // not supported
      {{1.1 - 0.07, -0.55 - 0.25}, 0.05, true},               // all: correct
  };
  for (const Marker& m : markers) {
    SCOPED_TRACE("marker at " + std::to_string(m.at.x) + ", " + std::to_string(m.at.y));
    const double r = 0.22;  // the tip stops up to ~0.1 short of the marker's edge
    const glm::ivec2 lo = pixelOf(m.at.x - r, m.at.y + r), hi = pixelOf(m.at.x + r, m.at.y - r);
    int black = 0;
    for (int y = std::max(lo.y, 0); y <= std::min(hi.y, H - 1); ++y)
      for (int x = std::max(lo.x, 0); x <= std::min(hi.x, W - 1); ++x) {
        const double wx = ((x + 0.5) / W * 2.0 - 1.0) * 1.8, wy = (1.0 - (y + 0.5) / H * 2.0) * 1.2;
        if (glm::length(glm::dvec2(wx, wy) - m.at) > r) continue;
        const glm::vec3 p = out.image.at(x, y);
        black += p.r < 0.05f && p.g < 0.05f && p.b < 0.05f;
      }
    if (m.touched)
      EXPECT_GT(black, 3);
    else
      EXPECT_EQ(black, 0);
  }
}

}  // namespace
