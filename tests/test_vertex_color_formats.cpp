// Vertex colours and alpha textures of the other formats (issue 24): PLY red / green / blue
// [/ alpha] (uchar 0-255 or float 0-1; sRGB-encoded display values, decoded to linear, alpha
// linear; the file's material white, blended when some alpha is below 1) and OBJ Kd x map_Kd with
// a map_d alpha texture (its alpha channel multiplies alpha). Tiny hand-made files; expected values
// from the sRGB formula written here, and one head-on render per format compared pixel by pixel.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <glm/glm.hpp>

#include "mfr/core/image.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/load.hpp"
#include "quad_checks.hpp"
#include "temp_dir.hpp"

namespace {

namespace fs = std::filesystem;

/// This file's scratch folders (temp_dir.hpp).
class TempDir : public mfr::test::TempDir {
 public:
  TempDir() : mfr::test::TempDir("mfr_color_formats") {}
};

/// The sRGB transfer function's inverse (IEC 61966-2-1), in double.
double srgbDecode(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

constexpr int kSize = 32;
const glm::dvec3 kBackground{0.25, 0.5, 0.75};

mfr::RenderOutput renderHeadOn(const mfr::Scene& scene) {
  return mfr::test::renderAbuffer(scene, mfr::test::headOnQuadCamera(), kSize, kBackground);
}

/// A PLY square x, y in [-1, 1] whose four corners have the colour properties `header` declares
/// with the values `corner[i]` (one line each).
std::string plySquare(const std::string& header, const std::string (&corner)[4]) {
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\n" +
      header + "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const char* xyz[4] = {"-1 -1 0", "1 -1 0", "1 1 0", "-1 1 0"};
  for (int i = 0; i < 4; ++i) ply += std::string(xyz[i]) + " " + corner[i] + "\n";
  return ply + "4 0 1 2 3\n";
}

/// The scene's colour of the vertex at (x, y) (the loader may reorder vertices).
glm::vec4 colorAt(const mfr::Scene& scene, float x, float y) {
  for (size_t v = 0; v < scene.positions.size(); ++v)
    if (scene.positions[v].x == x && scene.positions[v].y == y) return scene.colors[v];
  ADD_FAILURE() << "no vertex at (" << x << ", " << y << ")";
  return glm::vec4(-1.0f);
}

TEST(PlyVertexColors, UcharRgbaIsSrgbDecodedAlphaLinear) {
  TempDir dir;
  const std::string corners[4] = {"255 0 0 255", "0 128 255 255", "64 200 16 102", "10 20 30 40"};
  const std::string path =
      dir.write("colors.ply", plySquare("property uchar red\nproperty uchar green\n"
                                        "property uchar blue\nproperty uchar alpha\n",
                                        corners));
  const mfr::Scene scene = mfr::loadScene(path).value();
  ASSERT_EQ(scene.colors.size(), 4u);
  const int codes[4][4] = {
      {255, 0, 0, 255}, {0, 128, 255, 255}, {64, 200, 16, 102}, {10, 20, 30, 40}};
  const float xy[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int i = 0; i < 4; ++i) {
    const glm::vec4 c = colorAt(scene, xy[i][0], xy[i][1]);
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(c[ch], srgbDecode(codes[i][ch] / 255.0), 1e-6) << i << " " << ch;
    EXPECT_NEAR(c[3], codes[i][3] / 255.0, 1e-6) << i;
  }
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].baseColor, glm::vec4(1.0f));
  EXPECT_EQ(scene.materials[0].alphaMode, mfr::AlphaMode::Blend);  // some alpha below 1
}

TEST(PlyVertexColors, FloatRgbRendersAsTheDecodedColour) {
  TempDir dir;
  const std::string same = "0.5 0.25 1.0";
  const std::string corners[4] = {same, same, same, same};
  const std::string path =
      dir.write("float.ply", plySquare("property float red\nproperty float green\n"
                                       "property float blue\n",
                                       corners));
  const mfr::Scene scene = mfr::loadScene(path).value();
  ASSERT_EQ(scene.colors.size(), 4u);
  const glm::dvec3 expected(srgbDecode(0.5), srgbDecode(0.25), 1.0);
  for (const glm::vec4& c : scene.colors) {
    EXPECT_NEAR(c.r, expected.r, 1e-6);
    EXPECT_NEAR(c.g, expected.g, 1e-6);
    EXPECT_NEAR(c.b, expected.b, 1e-6);
    EXPECT_EQ(c.a, 1.0f);
  }
  EXPECT_EQ(scene.materials[0].alphaMode, mfr::AlphaMode::Opaque);
  const mfr::RenderOutput out = renderHeadOn(scene);
  for (int p = 0; p < kSize * kSize; ++p) {
    const glm::vec3 got = out.image.at(p % kSize, p / kSize);
    ASSERT_NEAR(got.r, expected.r, 0.01) << p;
    ASSERT_NEAR(got.g, expected.g, 0.01) << p;
    ASSERT_NEAR(got.b, expected.b, 0.01) << p;
  }
}

TEST(PlyVertexColors, WithoutColorsTheMaterialStaysGrey) {
  TempDir dir;
  const std::string corners[4] = {"", "", "", ""};
  const mfr::Scene scene = mfr::loadScene(dir.write("plain.ply", plySquare("", corners))).value();
  EXPECT_TRUE(scene.colors.empty());
  EXPECT_EQ(scene.materials[0].baseColor, glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
}

/// An 8x1 RGBA PNG whose left four texels are `left` and right four `right`.
void writeStrip(const std::string& path, const glm::ivec4& left, const glm::ivec4& right) {
  mfr::Image8 image;
  image.width = 8;
  image.height = 1;
  for (int x = 0; x < 8; ++x) {
    const glm::ivec4& c = x < 4 ? left : right;
    for (int ch = 0; ch < 4; ++ch) image.rgba.push_back(static_cast<uint8_t>(c[ch]));
  }
  ASSERT_TRUE(mfr::writePng(path, image).ok());
}

// Kd multiplies map_Kd; map_d's alpha channel multiplies alpha (left half 255, right half 64).
// Compared where the bilinear sample lies inside one half: u in [0.15, 0.35] and [0.65, 0.85].
TEST(ObjAlphaTexture, KdTimesMapKdAndMapDAlpha) {
  TempDir dir;
  writeStrip(dir.file("color.png"), {255, 0, 0, 255}, {255, 255, 255, 255});
  writeStrip(dir.file("alpha.png"), {0, 0, 0, 255}, {0, 0, 0, 64});
  dir.write("quad.mtl", "newmtl m\nKd 0.5 0.8 1.0\nmap_Kd color.png\nmap_d alpha.png\n");
  const std::string path = dir.write(
      "quad.obj",
      "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
      "usemtl m\nf 1/1 2/2 3/3 4/4\n");
  const mfr::Scene scene = mfr::loadScene(path).value();
  ASSERT_EQ(scene.materials.size(), 1u);
  const mfr::Material& m = scene.materials[0];
  EXPECT_EQ(m.alphaMode, mfr::AlphaMode::Blend);
  ASSERT_GE(m.baseColorTexture, 0);
  const mfr::Texture& t = scene.textures[static_cast<size_t>(m.baseColorTexture)];
  ASSERT_EQ(t.width, 8);
  EXPECT_EQ(t.rgba[0 * 4 + 0], 255);  // map_Kd's colour kept
  EXPECT_EQ(t.rgba[0 * 4 + 3], 255);  // map_Kd alpha 255 x map_d 255
  EXPECT_EQ(t.rgba[7 * 4 + 1], 255);
  EXPECT_EQ(t.rgba[7 * 4 + 3], 64);  // 255 x 64 / 255
  const mfr::RenderOutput out = renderHeadOn(scene);
  int compared = 0;
  for (int py = 0; py < kSize; ++py)
    for (int px = 0; px < kSize; ++px) {
      const double u = (px + 0.5) / kSize;
      const bool leftHalf = u >= 0.15 && u <= 0.35, rightHalf = u >= 0.65 && u <= 0.85;
      if (!leftHalf && !rightHalf) continue;
      const glm::dvec3 texel = leftHalf ? glm::dvec3(1, 0, 0) : glm::dvec3(1, 1, 1);
      const double alpha = leftHalf ? 1.0 : 64.0 / 255.0;
      const glm::dvec3 e = glm::dvec3(0.5, 0.8, 1.0) * texel * alpha + kBackground * (1 - alpha);
      const glm::vec3 got = out.image.at(px, py);
      ++compared;
      EXPECT_NEAR(got.r, e.r, 0.01) << px << ", " << py;
      EXPECT_NEAR(got.g, e.g, 0.01) << px << ", " << py;
      EXPECT_NEAR(got.b, e.b, 0.01) << px << ", " << py;
    }
  EXPECT_GT(compared, 300);
}

// map_d without map_Kd: a white texture carrying map_d's alpha; a missing map_d names itself.
TEST(ObjAlphaTexture, MapDAloneAndMissingMapD) {
  TempDir dir;
  writeStrip(dir.file("alpha.png"), {9, 9, 9, 128}, {9, 9, 9, 32});
  dir.write("a.mtl", "newmtl m\nKd 1 1 1\nmap_d alpha.png\n");
  const std::string obj =
      "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl m\nf 1/1 2/2 3/3\n";
  const mfr::Scene scene = mfr::loadScene(dir.write("a.obj", "mtllib a.mtl\n" + obj)).value();
  const mfr::Texture& t =
      scene.textures.at(static_cast<size_t>(scene.materials[0].baseColorTexture));
  EXPECT_EQ(t.rgba[0], 255);  // white colour
  EXPECT_EQ(t.rgba[3], 128);
  EXPECT_EQ(t.rgba[7 * 4 + 3], 32);
  dir.write("b.mtl", "newmtl m\nmap_d nowhere.png\n");
  auto missing = mfr::loadScene(dir.write("b.obj", "mtllib b.mtl\n" + obj));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("map_d"), std::string::npos) << missing.error().message;
  EXPECT_NE(missing.error().message.find("nowhere.png"), std::string::npos)
      << missing.error().message;
  EXPECT_EQ(missing.error().message.find('\n'), std::string::npos);
}

}  // namespace
