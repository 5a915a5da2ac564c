// The small parsers of user input the fuzzers (fuzz/) drive: --camera (parseCameraSpec); byte
// sizes, method names and compositing rules quoting hostile text on one line; the procedural
// triangle cap (LoadOptions::maxProceduralTriangles); PLY headers that assimp would misread.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/camera_spec.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/procedural.hpp"

namespace mfr {
namespace {

bool isOneLine(const std::string& message) {
  return !message.empty() && message.find('\n') == std::string::npos &&
         message.find('\r') == std::string::npos;
}

TEST(CameraSpec, ParsesSixNineOrTenNumbers) {
  auto six = parseCameraSpec("0,0,5,0,0,0");
  ASSERT_TRUE(six.ok()) << six.error().message;
  EXPECT_EQ(six->eye, glm::vec3(0, 0, 5));
  EXPECT_EQ(six->target, glm::vec3(0, 0, 0));
  EXPECT_EQ(six->up, glm::vec3(0, 1, 0));
  EXPECT_EQ(six->fovYDegrees, 45.0f);
  EXPECT_EQ(six->zNear, 0.0f);  // automatic clip planes
  auto ten = parseCameraSpec(" -1.5e2, +2 ,3,0,0,0,0,0,1,90");
  ASSERT_TRUE(ten.ok()) << ten.error().message;
  EXPECT_EQ(ten->eye, glm::vec3(-150, 2, 3));
  EXPECT_EQ(ten->up, glm::vec3(0, 0, 1));
  EXPECT_EQ(ten->fovYDegrees, 90.0f);
  const double numbers[9] = {1, 2, 3, 0, 0, 0, 1, 0, 0};
  auto nine = cameraFromNumbers(numbers);
  ASSERT_TRUE(nine.ok()) << nine.error().message;
  EXPECT_EQ(nine->up, glm::vec3(1, 0, 0));
}

TEST(CameraSpec, RefusesWhatCannotBeAViewWithOneLineNamingTheOption) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"1,2,3", "expected 6, 9 or 10 numbers"},
      {"0,0,5,0,0,0,0,1,0,45,1", "expected 6, 9 or 10 numbers"},
      {"nan,0,5,0,0,0", "finite"},
      {"inf,0,5,0,0,0", "finite"},
      {"1e39,0,5,0,0,0", "fit a float"},
      {"1e400,0,5,0,0,0", "out of range"},
      {"0,0,5,0,0,x", "'x' is not a number"},
      {"0,0,5,0,0,", "'' is not a number"},
      {"0,0,5,0,0,0\n,1,2", "is not a number"},
      {"1,1,1,1,1,1", "eye and target must differ"},
      {"0,0,5,0,0,0,0,0,1", "not parallel"},
      {"0,0,5,0,0,0,0,0,0", "non-zero"},
      {"0,0,5,0,0,0,0,1,0,180", "field of view"},
      {"0,0,5,0,0,0,0,1,0,0", "field of view"},
  };
  for (const auto& [text, expected] : cases) {
    auto camera = parseCameraSpec(text, "--camera");
    ASSERT_FALSE(camera.ok()) << text;
    const std::string& m = camera.error().message;
    EXPECT_TRUE(isOneLine(m)) << m;
    EXPECT_EQ(m.rfind("--camera: ", 0), 0u) << m;
    EXPECT_NE(m.find(expected), std::string::npos) << text << ": " << m;
  }
}

TEST(InputErrors, QuoteHostileTextOnOneLine) {
  const std::string hostile = std::string("12\nXB\r\x1b[2J") + std::string(200, 'z');
  auto size = parseByteSize(hostile);
  ASSERT_FALSE(size.ok());
  EXPECT_TRUE(isOneLine(size.error().message)) << size.error().message;
  EXPECT_NE(size.error().message.find("'12?XB??[2J"), std::string::npos) << size.error().message;
  EXPECT_NE(size.error().message.find("zzz...'"), std::string::npos) << "long input not cut";
  auto method = methodPreset("fkb\n+occupancy");
  ASSERT_FALSE(method.ok());
  EXPECT_TRUE(isOneLine(method.error().message)) << method.error().message;
  auto rule = parseCompositing("hybrid\r\n");
  ASSERT_FALSE(rule.ok());
  EXPECT_TRUE(isOneLine(rule.error().message)) << rule.error().message;
  EXPECT_EQ(quoteInput("a\tb"), "'a?b'");
  EXPECT_EQ(oneLine("x\ny", 1), "x...");
}

TEST(ProceduralLimit, TriangleCapIsCheckedBeforeBuilding) {
  // layers?k=8&r=16: 128 quads, 256 triangles
  EXPECT_TRUE(makeProceduralScene("layers?k=8&r=16", 1, 256).ok());
  auto refused = makeProceduralScene("layers?k=8&r=16", 1, 255);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("256 triangles (limit 255)"), std::string::npos)
      << refused.error().message;
  LoadOptions options;
  options.maxProceduralTriangles = 100;
  auto loaded = loadScene("procedural:layers?k=8&r=16", options);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.error().message.find("limit 100"), std::string::npos) << loaded.error().message;
  EXPECT_TRUE(loadScene("procedural:layers?k=8&r=16").ok()) << "the default cap is 50 million";
}

// PLY headers that assimp reads otherwise than mfr's structure check (found by fuzz/fuzz_ply.cpp:
// a heap overflow inside assimp, an assertion, a leak) are refused before assimp sees them.
TEST(PlyHeaders, WhatAssimpMisreadsIsRefusedWithOneLine) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("mfr_ply_headers_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string body = "end_header\n0 0 0\n1 0 0\n1 1 0\n3 0 1 2\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"ply\nformat ascii 1.0\nelement vertex 1\n" + xyz + "element vertex 2\n" + xyz + faces +
           body,
       "element 'vertex' is declared twice"},
      {"ply\nformat ascii 1.0\nformat binary_big_endian 1.0\nelement vertex 3\n" + xyz + faces +
           body,
       "second format line"},
      {"ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
           std::string("property float \0nx\n", 19) + faces + body,
       "control character"},
  };
  int i = 0;
  for (const auto& [text, expected] : cases) {
    const std::string path = (dir / ("case" + std::to_string(i++) + ".ply")).string();
    std::ofstream(path, std::ios::binary) << text;
    auto scene = loadScene(path);
    ASSERT_FALSE(scene.ok()) << expected;
    EXPECT_TRUE(isOneLine(scene.error().message)) << scene.error().message;
    EXPECT_NE(scene.error().message.find(expected), std::string::npos) << scene.error().message;
    EXPECT_NE(scene.error().message.find(path), std::string::npos) << scene.error().message;
  }
  // the same file with one vertex element and one format line loads
  const std::string good = (dir / "good.ply").string();
  std::ofstream(good, std::ios::binary)
      << "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + faces + body;
  EXPECT_TRUE(loadScene(good).ok());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mfr
