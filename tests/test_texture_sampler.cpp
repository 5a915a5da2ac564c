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

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kRepeat = 10497, kClamp = 33071, kMirror = 33648, kNearest = 9728, kLinear = 9729;
constexpr int kSize = 64;  // image side: the quad fills it, 4 pixels per texel across u

mfr::Result<mfr::Scene> loadText(const std::string& text) {
  const fs::path path =
      fs::temp_directory_path() / ("mfr_sampler_" + std::to_string(::getpid()) + ".gltf");
  std::ofstream(path) << text;
  auto scene = mfr::loadScene(path.string());
  fs::remove(path);
  return scene;
}

/// Head-on camera whose view is exactly the quad (x, y in [-1, 1]).
mfr::Camera headOn() {
  mfr::Camera camera;
  camera.fovYDegrees = 2.0f;
  const float d = 1.0f / std::tan(glm::radians(1.0f));
  camera.eye = {0.0f, 0.0f, d};
  camera.target = {0.0f, 0.0f, 0.0f};
  camera.zNear = 0.5f * d;
  camera.zFar = 2.0f * d;
  return camera;
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

/// Renders the quad under `sampler` (null: none) and compares every unambiguous pixel with
/// `expected`; returns how many pixels were compared.
int expectSamples(const json* sampler, int wrapS, int wrapT, bool nearest) {
  auto scene = loadText(mfr::test::texturedQuadGltf(sampler));
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
      const glm::dvec3 e =
          expected(mfr::test::quadU(x), mfr::test::quadV(y), wrapS, wrapT, nearest, ambiguous);
      if (ambiguous) continue;
      ++compared;
      const glm::vec3 got = out->image.at(px, py);
      // sRGB8 fragment colours: at most half a code (0.0045 in linear at 1), |n.v| >= 0.9997
      const bool close = std::abs(got.r - e.r) < 0.01 && std::abs(got.g - e.g) < 0.01 &&
                         std::abs(got.b - e.b) < 0.01;
      if (!close && ++wrong <= 5)
        ADD_FAILURE() << "pixel (" << px << ", " << py << "): got (" << got.r << ", " << got.g
                      << ", " << got.b << "), expected (" << e.r << ", " << e.g << ", " << e.b
                      << ")";
    }
  EXPECT_EQ(wrong, 0) << "of " << compared << " pixels";
  return compared;
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

}  // namespace
