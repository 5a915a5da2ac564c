// Issue 49, cameras and faces: inputs that rendered an empty or silently wrong image, each written
// here with the behaviour mfr now promises (docs/ROBUSTNESS.md):
//  - far planes beyond single precision (glTF zfar 1e300, a JSON scene's far 3e38) are clamped
//    and render the image a nearer far plane renders; near planes beyond 1e18 are refused;
//  - fields of view too narrow for single precision (1e-10, 1e-37 degrees) are refused;
//  - glTF --view N is the file's camera N as `mfr info` lists it; orthographic cameras and cameras
//    no node places are refused by --view, never replaced by another;
//  - self-crossing (bow-tie) quads are refused in OBJ and PLY, concave ones split inside;
//  - a PLY comment between an element and its properties loads;
//  - negative glTF accessor offsets and sparse counts are refused naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "error_assertions.hpp"
#include "gltf_quads.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/camera_spec.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/scene_request.hpp"
#include "scratch_folder.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::contains;
using mfr::test::oneLineNaming;
using mfr::test::refused;
using nlohmann::json;

class ReliabilityCamera : public mfr::test::ScratchFolderTest {
 protected:
  ReliabilityCamera() : ScratchFolderTest("mfr_rel_camera") {}
  std::string write(const std::string& name, const std::string& bytes) const {
    return mfr::test::writeFile(model() / name, bytes);
  }
  mfr::test::CliRun cli(const std::string& args) const { return mfr::test::runCli(args, root()); }
};

/// A CLI run that failed with exit code 1 and one error line naming `file` with `parts`.
::testing::AssertionResult cliRefused(const mfr::test::CliRun& run, const std::string& file,
                                      std::initializer_list<std::string> parts) {
  ::testing::AssertionResult clean = mfr::test::cleanError(run, parts);
  if (!clean || contains(run.err, file)) return clean;
  return ::testing::AssertionFailure() << "'" << run.err << "' does not name " << file;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string floatBytes(const std::vector<float>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
}

std::string dataUri(const std::string& bytes) {
  return "data:application/octet-stream;base64," + mfr::test::base64Encode(bytes);
}

/// Two squares facing +z: [-1, 1]^2 at z = 0 and [-0.5, 0.5]^2 at z = -1 (depth complexity 2 in
/// the middle, 1 around it).
const std::vector<float> kTwoSquares = {-1,   -1,   0,  1,   -1,   0,  1,   1,   0,  -1,   1,   0,
                                        -0.5, -0.5, -1, 0.5, -0.5, -1, 0.5, 0.5, -1, -0.5, 0.5, -1};
constexpr const char* kTwoSquaresObj =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
    "v -0.5 -0.5 -1\nv 0.5 -0.5 -1\nv 0.5 0.5 -1\nv -0.5 0.5 -1\nf 1 2 3 4\nf 5 6 7 8\n";

/// A glTF of the two squares (indexed, one blended material) with `cameras`, node i + 1 placing
/// `placements[i].first` at translation `placements[i].second`.
json twoSquaresGltf(const json& cameras, const std::vector<std::pair<int, glm::vec3>>& placements) {
  const std::vector<uint16_t> indices = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  const std::string bytes =
      floatBytes(kTwoSquares) +
      std::string(reinterpret_cast<const char*>(indices.data()), indices.size() * 2);
  json nodes = json::array({{{"mesh", 0}}});
  json sceneNodes = json::array({0});
  for (const auto& [camera, at] : placements) {
    nodes.push_back({{"camera", camera}, {"translation", {at.x, at.y, at.z}}});
    sceneNodes.push_back(nodes.size() - 1);
  }
  json doc = {{"asset", {{"version", "2.0"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", sceneNodes}}}},
              {"nodes", nodes},
              {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
              {"accessors",
               {{{"bufferView", 0}, {"componentType", 5126}, {"count", 8}, {"type", "VEC3"}},
                {{"bufferView", 1}, {"componentType", 5123}, {"count", 12}, {"type", "SCALAR"}}}},
              {"bufferViews",
               {{{"buffer", 0}, {"byteLength", 96}},
                {{"buffer", 0}, {"byteOffset", 96}, {"byteLength", 24}}}},
              {"buffers", {{{"byteLength", bytes.size()}, {"uri", dataUri(bytes)}}}}};
  if (!cameras.empty()) doc["cameras"] = cameras;
  return doc;
}

json perspective(double yfov, double znear, std::optional<double> zfar = std::nullopt) {
  json p = {{"yfov", yfov}, {"znear", znear}};
  if (zfar) p["zfar"] = *zfar;
  return {{"type", "perspective"}, {"perspective", p}};
}

/// Per-pixel fragment counts of `scene` seen by `camera` (CPU engine, one sample).
mfr::Result<std::vector<uint32_t>> counts(const mfr::Scene& scene, const mfr::Camera& camera,
                                          int size = 32) {
  mfr::RasterOptions ro;
  ro.width = ro.height = size;
  ro.threads = 1;
  auto frame = mfr::RasterFrame::build(scene, camera, ro);
  if (!frame) return frame.error();
  return mfr::countFragments(frame.value());
}

// ---------------------------------------------------------------------------------------------
// Row 8: far planes beyond single precision

TEST_F(ReliabilityCamera, FarPlaneBeyondSinglePrecisionIsClampedAndRendersTheNearerPlanesImage) {
  // the bound: 2 far near and far + near stay within FLT_MAX / 2 in single precision
  for (const float zNear : {1e-3f, 0.1f, 1.0f, 1e6f, 1e18f}) {
    const float bound = mfr::maxFarPlane(zNear);
    ASSERT_GT(bound, zNear);
    mfr::Camera c;
    c.zNear = zNear;
    c.zFar = std::numeric_limits<float>::infinity();
    const mfr::Camera fitted = mfr::fitClipPlanes(c, mfr::Bounds{glm::vec3(-1), glm::vec3(1)});
    EXPECT_EQ(fitted.zFar, bound) << zNear;
    const glm::mat4 p = mfr::projectionMatrix(fitted, 32, 32);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) EXPECT_TRUE(std::isfinite(p[i][j])) << zNear;
    EXPECT_TRUE(std::isfinite(2.0f * zNear * fitted.zFar)) << zNear;  // the surface point's
  }
  // the library: the two squares' depth complexity with far 3e38 and infinity is far 100's
  auto scene = mfr::loadScene(write("squares.obj", kTwoSquaresObj));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  mfr::Camera camera;
  camera.eye = {0.0f, 0.0f, 5.0f};
  camera.zNear = 0.1f;
  camera.zFar = 100.0f;
  auto expected = counts(*scene, camera);
  ASSERT_TRUE(expected.ok()) << expected.error().message;
  uint64_t fragments = 0;
  for (uint32_t n : *expected) fragments += n;
  ASSERT_GT(fragments, 0u);
  for (const float far :
       {3e38f, std::numeric_limits<float>::max(), std::numeric_limits<float>::infinity()}) {
    camera.zFar = far;
    auto got = counts(*scene, camera);
    ASSERT_TRUE(got.ok()) << got.error().message;
    EXPECT_EQ(*got, *expected) << "far " << far;
  }
  // the command line: a JSON scene's far 3e38 and a glTF zfar 1e300 render the image (and the
  // fragments) of far 100, not an empty one
  const auto render = [&](const std::string& scene, const std::string& name) {
    const std::string png = (root() / (name + ".png")).string();
    const std::string stats = (root() / (name + ".json")).string();
    const auto run = cli("render " + scene + " --view 0 --width 32 --height 32 -q -o " + png +
                         " --stats-json " + stats);
    EXPECT_EQ(run.exitCode, 0) << run.err;
    const json s = json::parse(readFile(stats), nullptr, false);
    EXPECT_TRUE(s.is_object() && s.contains("fragments_generated")) << name;
    return std::make_pair(readFile(png), s.value("fragments_generated", uint64_t{0}));
  };
  write("squares_mesh.obj", kTwoSquaresObj);
  const auto jsonScene = [&](const std::string& far) {
    return write("far_" + far + ".json", R"({"mesh": "squares_mesh.obj", "alpha": 0.5, "cameras": )"
                                         R"([{"eye": [0, 0, 5], "target": [0, 0, 0], "near": 0.1, )"
                                         R"("far": )" +
                                             far + "}]}");
  };
  const auto near = render(jsonScene("100"), "json_100");
  ASSERT_GT(near.second, 0u);
  ASSERT_FALSE(near.first.empty());
  EXPECT_EQ(render(jsonScene("3e38"), "json_3e38"), near);
  const auto gltfScene = [&](double zfar, const std::string& name) {
    return write(
        name, twoSquaresGltf(json::array({perspective(0.785398163, 0.1, zfar)}), {{0, {0, 0, 5}}})
                  .dump());
  };
  const auto gltfNear = render(gltfScene(100.0, "far_100.gltf"), "gltf_100");
  ASSERT_GT(gltfNear.second, 0u);
  EXPECT_EQ(render(gltfScene(1e300, "far_1e300.gltf"), "gltf_1e300"), gltfNear);
}

TEST_F(ReliabilityCamera, NearPlaneBeyondSinglePrecisionIsRefusedNamingTheInput) {
  const std::string gltf = write(
      "near.gltf", twoSquaresGltf(json::array({perspective(0.8, 1e20)}), {{0, {0, 0, 5}}}).dump());
  EXPECT_TRUE(
      refused(mfr::loadScene(gltf), gltf, {"camera 0: perspective.znear 1e+20", "beyond 1e18"}));
  write("squares_mesh.obj", kTwoSquaresObj);
  const std::string scene =
      write("near.json",
            R"({"mesh": "squares_mesh.obj", "cameras": [{"eye": [0, 0, 5], "target": [0, 0, 0], )"
            R"("near": 1e20}]})");
  EXPECT_TRUE(refused(mfr::loadScene(scene), scene, {"'cameras[0].near' is 1e+20, beyond 1e18"}));
  // the library refuses an explicit near plane, and a fitted one (the eye 1e20 from the scene),
  // rather than rendering nothing
  auto squares = mfr::loadScene(write("squares.obj", kTwoSquaresObj));
  ASSERT_TRUE(squares.ok()) << squares.error().message;
  mfr::Camera camera;
  camera.zNear = 1e20f;
  auto explicitNear = counts(*squares, camera);
  ASSERT_FALSE(explicitNear.ok());
  EXPECT_TRUE(contains(explicitNear.error().message, "camera: near plane 1e+20 is beyond 1e18"))
      << explicitNear.error().message;
  camera = mfr::Camera{};
  camera.eye = {0.0f, 0.0f, 5e18f};
  auto fitted = counts(*squares, camera);
  ASSERT_FALSE(fitted.ok());
  EXPECT_TRUE(contains(fitted.error().message, "fitted to the scene's distance from the eye"))
      << fitted.error().message;
  // an eye 1e20 from its target: the view transform squares the distance (it looked nowhere)
  camera.eye = {0.0f, 0.0f, 1e20f};
  auto apart = counts(*squares, camera);
  ASSERT_FALSE(apart.ok());
  EXPECT_TRUE(contains(apart.error().message, "camera: eye and target 1e+20 apart, beyond 1e19"))
      << apart.error().message;
  // the CLI says the same through --camera, exit code 1
  EXPECT_TRUE(cliRefused(cli("render " + squares->name +
                             " --camera 0,0,5e18,0,0,0 -q --width 8 "
                             "--height 8 -o " +
                             (root() / "x.png").string()),
                         squares->name, {"near plane", "beyond 1e18"}));
}

// ---------------------------------------------------------------------------------------------
// Row 18: fields of view too narrow to represent

TEST_F(ReliabilityCamera, FieldOfViewTooNarrowForSinglePrecisionIsRefusedNamingTheInput) {
  // glTF yfov (radians): 1e-10 degrees and 1e-37 degrees
  for (const double yfov : {1e-10 * M_PI / 180.0, 1e-37 * M_PI / 180.0, 0.0019}) {
    const std::string path =
        write("narrow.gltf",
              twoSquaresGltf(json::array({perspective(yfov, 0.1)}), {{0, {0, 0, 5}}}).dump());
    EXPECT_TRUE(refused(mfr::loadScene(path), path,
                        {"camera 0: perspective.yfov", "narrower than 0.112 degrees"}))
        << yfov;
  }
  // a JSON scene's fov (degrees)
  write("squares_mesh.obj", kTwoSquaresObj);
  for (const std::string fov : {"1e-10", "1e-37", "0.1"}) {
    const std::string path =
        write("narrow.json",
              R"({"mesh": "squares_mesh.obj", "cameras": [{"eye": [0, 0, 5], "target": [0, 0, 0], )"
              R"("fov": )" +
                  fov + "}]}");
    EXPECT_TRUE(refused(mfr::loadScene(path), path,
                        {"'cameras[0].fov' is " + fov + " degrees", "narrower than 0.112"}))
        << fov;
  }
  // --camera's tenth number, in the library and on the command line
  auto spec = mfr::parseCameraSpec("0,0,5,0,0,0,0,1,0,1e-10", "--camera");
  ASSERT_FALSE(spec.ok());
  EXPECT_TRUE(contains(spec.error().message,
                       "--camera: field of view 1e-10 degrees is narrower than 0.112 degrees"))
      << spec.error().message;
  const std::string squares = write("squares.obj", kTwoSquaresObj);
  EXPECT_TRUE(cliRefused(cli("render " + squares + " --camera 0,0,5,0,0,0,0,1,0,1e-37 -q -o " +
                             (root() / "x.png").string()),
                         "--camera", {"field of view 1e-37 degrees", "narrower than 0.112"}));
  // a camera made in code reaches the raster's check
  auto scene = mfr::loadScene(squares);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  mfr::Camera camera;
  camera.fovYDegrees = 1e-37f;
  auto tiny = counts(*scene, camera);
  ASSERT_FALSE(tiny.ok());
  EXPECT_TRUE(contains(tiny.error().message, "camera: field of view 1e-37 degrees is narrower"))
      << tiny.error().message;
}

TEST_F(ReliabilityCamera, NarrowestFieldOfViewRendersTheFramedSquareExactly) {
  // a square framed to cover the middle half of a 64 x 64 image (32 x 32 pixels), its coordinates
  // about its distance from the eye (the case the bound is derived for): at the narrowest view
  // allowed it covers exactly its pixels (at 1e-5 degrees it covered 1444, at 1e-10 none)
  const double fov = mfr::kMinFovYDegrees * 1.01;
  const double half = 5.0 * std::tan(fov * M_PI / 360.0) * 0.5;
  std::string obj;
  char buffer[256];
  for (const auto& [x, y] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    std::snprintf(buffer, sizeof buffer, "v %.17g %.17g 0\n", 1.0 + x * half, 1.0 + y * half);
    obj += buffer;
  }
  auto scene = mfr::loadScene(write("framed.obj", obj + "f 1 2 3 4\n"));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  mfr::Camera camera;
  camera.eye = {1.0f, 1.0f, 5.0f};
  camera.target = {1.0f, 1.0f, 0.0f};
  camera.fovYDegrees = static_cast<float>(fov);
  auto n = counts(*scene, camera, 64);
  ASSERT_TRUE(n.ok()) << n.error().message;
  uint32_t covered = 0, inside = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const uint32_t c = (*n)[static_cast<size_t>(y * 64 + x)];
      EXPECT_LE(c, 1u);
      covered += c;
      inside += (x >= 16 && x < 48 && y >= 16 && y < 48) ? c : 0;
    }
  EXPECT_EQ(covered, 1024u);
  EXPECT_EQ(inside, 1024u);
  EXPECT_TRUE(mfr::validFovYDegrees(mfr::kMinFovYDegrees));
  EXPECT_FALSE(mfr::validFovYDegrees(std::nextafter(mfr::kMinFovYDegrees, 0.0)));
}

// ---------------------------------------------------------------------------------------------
// Row 9: --view N is the file's camera N

TEST_F(ReliabilityCamera, GltfViewNIsTheFilesCameraNAsInfoListsIt) {
  // file camera 0 placed by the last node, 1 orthographic, 2 placed by the first camera node,
  // 3 placed by no node; the old loader's list was [camera 2, camera 0]: --view 0 was camera 2
  const json cameras = {
      perspective(0.9, 0.1),
      {{"type", "orthographic"},
       {"orthographic", {{"xmag", 1.0}, {"ymag", 1.0}, {"znear", 0.1}, {"zfar", 10.0}}}},
      perspective(0.5, 0.1),
      perspective(0.7, 0.1)};
  json doc = twoSquaresGltf(cameras, {{2, {0, 0, 6}}, {1, {0, 0, 4}}, {0, {0, 1, 5}}});
  doc["cameras"][1]["name"] = "top view";
  const std::string path = write("cameras.gltf", doc.dump());
  auto scene = mfr::loadScene(path);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  ASSERT_EQ(scene->cameras.size(), 4u);
  ASSERT_EQ(scene->cameraProblems.size(), 4u);
  EXPECT_NEAR(scene->cameras[0].fovYDegrees, 0.9 * 180.0 / M_PI, 1e-4);
  EXPECT_EQ(scene->cameras[0].eye, glm::vec3(0.0f, 1.0f, 5.0f));
  EXPECT_NEAR(scene->cameras[2].fovYDegrees, 0.5 * 180.0 / M_PI, 1e-4);
  EXPECT_EQ(scene->cameras[2].eye, glm::vec3(0.0f, 0.0f, 6.0f));
  // --view through the one function every front end uses
  for (int i : {0, 2}) {
    auto chosen = mfr::fileCamera(*scene, path, i);
    ASSERT_TRUE(chosen.ok()) << chosen.error().message;
    EXPECT_EQ(chosen->eye, scene->cameras[static_cast<size_t>(i)].eye);
  }
  const auto refusal = [&](int i) {
    auto chosen = mfr::fileCamera(*scene, path, i);
    return chosen.ok() ? std::string("accepted") : chosen.error().message;
  };
  EXPECT_TRUE(oneLineNaming(
      refusal(1), path,
      {"--view 1: camera 1 'top view' is 'orthographic'", "perspective cameras only"}));
  EXPECT_TRUE(oneLineNaming(refusal(3), path, {"--view 3: camera 3 is placed by no node"}));
  EXPECT_TRUE(oneLineNaming(refusal(4), path, {"--view 4 but the scene has 4 camera(s)"}));
  EXPECT_TRUE(oneLineNaming(refusal(-1), path, {"--view -1: must be a camera index"}));

  // mfr info lists the same cameras, in the same order, the refused ones with the reason
  const auto info = cli("info " + path + " --width 8 --height 8 --json -q");
  ASSERT_EQ(info.exitCode, 0) << info.err;
  const json j = json::parse(info.out, nullptr, false);
  ASSERT_TRUE(j.is_object()) << info.out;
  EXPECT_EQ(j["cameras_in_file"], 4);
  ASSERT_EQ(j["file_cameras"].size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(j["file_cameras"][i]["camera"], i);
  EXPECT_NEAR(j["file_cameras"][0]["fov"].get<double>(), 0.9 * 180.0 / M_PI, 1e-3);
  EXPECT_EQ(j["file_cameras"][0]["eye"], json({0.0, 1.0, 5.0}));
  EXPECT_NEAR(j["file_cameras"][2]["fov"].get<double>(), 0.5 * 180.0 / M_PI, 1e-3);
  EXPECT_TRUE(contains(j["file_cameras"][1].value("refused", ""), "orthographic"));
  EXPECT_TRUE(contains(j["file_cameras"][3].value("refused", ""), "placed by no node"));
  // render --view N takes file camera N: its info view is camera N's, the refused ones exit 1
  for (int i : {0, 2}) {
    const auto view =
        cli("info " + path + " --view " + std::to_string(i) + " --width 8 --height 8 --json -q");
    ASSERT_EQ(view.exitCode, 0) << view.err;
    const json v = json::parse(view.out, nullptr, false);
    ASSERT_TRUE(v.is_object()) << view.out;
    EXPECT_EQ(v["views"][0]["camera"]["eye"], j["file_cameras"][i]["eye"]) << i;
    EXPECT_EQ(v["views"][0]["camera"]["fov"], j["file_cameras"][i]["fov"]) << i;
  }
  const std::string png = (root() / "x.png").string();
  EXPECT_TRUE(cliRefused(cli("render " + path + " --view 1 --width 8 --height 8 -q -o " + png),
                         path, {"--view 1: camera 1", "orthographic"}));
  EXPECT_FALSE(fs::exists(png));
  EXPECT_TRUE(cliRefused(cli("render " + path + " --view 3 --width 8 --height 8 -q -o " + png),
                         path, {"--view 3: camera 3 is placed by no node"}));
}

// ---------------------------------------------------------------------------------------------
// Row 10: self-crossing quads

/// The summed area of the scene's triangles (a face split into overlapping triangles sums to
/// more than its area).
double summedArea(const mfr::Scene& scene) {
  double area = 0.0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const glm::dvec3 a(scene.positions[scene.indices[3 * t]]);
    const glm::dvec3 b(scene.positions[scene.indices[3 * t + 1]]);
    const glm::dvec3 c(scene.positions[scene.indices[3 * t + 2]]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

constexpr const char* kPlyQuadHeader =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST_F(ReliabilityCamera, SelfCrossingQuadFacesAreRefusedInObjAndPly) {
  // a bow-tie: edges 1-2 and 3-4 cross at (0.5, 0.5); every split of it overlaps itself
  const std::string bowtie = "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\n";
  const std::string obj = write("bowtie.obj", bowtie + "f 1 2 3 4\n");
  EXPECT_TRUE(
      refused(mfr::loadScene(obj), obj, {"a face of 4 vertices crosses itself", "vertex 1"}));
  const std::string ply =
      write("bowtie.ply", std::string(kPlyQuadHeader) + "0 0 0\n1 1 0\n1 0 0\n0 1 0\n4 0 1 2 3\n");
  EXPECT_TRUE(refused(mfr::loadScene(ply), ply, {"face 0: a face of 4 vertices crosses itself"}));
  // the other pair of edges crossing (1-2 and 3-4 of the face), in a plane tilted out of every
  // axis plane, and the CLI's exit code
  const std::string tilted =
      write("tilted.obj", "v 0 0 0\nv 1 0 0.5\nv 0 1 0.25\nv 1 1 0.75\nf 1 2 3 4\n");
  EXPECT_TRUE(refused(mfr::loadScene(tilted), tilted, {"crosses itself"}));
  EXPECT_TRUE(cliRefused(cli("info " + obj + " -q --width 8 --height 8"), obj,
                         {"a face of 4 vertices crosses itself"}));
  // a square, concave darts and a degenerate quad still load, each covering its area once
  const std::string square = write("square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  auto loaded = mfr::loadScene(square);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_NEAR(summedArea(*loaded), 1.0, 1e-9);
  // darts with their reflex corner third: (0,0) (2,0) (0.5,0.5) (0,2), area 1, whose shorter
  // diagonal is the inside one; and the arrow (-10,0) (0,-1) (-1,0) (0,1), area 9, whose shorter
  // diagonal (0,-1)-(0,1) lies outside it: split along it (tinyobjloader's rule) the two
  // triangles cover 11, the notch and the overlap included
  const std::vector<std::pair<std::string, double>> darts = {
      {"v 0 0 0\nv 2 0 0\nv 0.5 0.5 0\nv 0 2 0\n", 1.0},
      {"v -10 0 0\nv 0 -1 0\nv -1 0 0\nv 0 1 0\n", 9.0}};
  for (const auto& [vertices, area] : darts)
    for (const std::string face : {"f 1 2 3 4\n", "f 2 3 4 1\n", "f 3 4 1 2\n", "f 4 3 2 1\n"}) {
      auto d = mfr::loadScene(write("dart.obj", vertices + face));
      ASSERT_TRUE(d.ok()) << d.error().message;
      EXPECT_NEAR(summedArea(*d), area, 1e-6) << vertices << face;
    }
  const std::string plyDart = write(
      "dart.ply", std::string(kPlyQuadHeader) + "-10 0 0\n0 -1 0\n-1 0 0\n0 1 0\n4 0 1 2 3\n");
  auto d = mfr::loadScene(plyDart);
  ASSERT_TRUE(d.ok()) << d.error().message;
  EXPECT_NEAR(summedArea(*d), 9.0, 1e-6);
  auto line = mfr::loadScene(write("line.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3 4\n"));
  EXPECT_TRUE(line.ok() || !contains(line.error().message, "crosses itself"));
}

// ---------------------------------------------------------------------------------------------
// Row 17: PLY comments anywhere in the header

TEST_F(ReliabilityCamera, PlyCommentsBetweenAnElementAndItsPropertiesLoad) {
  const std::string header =
      "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\ncomment inside vertex\n"
      "property float x\nobj_info between properties\nproperty float y\nproperty float z\n"
      "element face 1\ncomment before the list\nproperty list uchar int vertex_indices\n"
      "comment last\nend_header\n";
  const std::string ascii = write("comments.ply", header +
                                                      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                                                      "4 0 1 2 3\n");
  auto scene = mfr::loadScene(ascii);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->triangleCount(), 2u);
  EXPECT_NEAR(summedArea(*scene), 1.0, 1e-9);
  // binary, CRLF header: the body's offset is unchanged, its values read as written
  std::string binary =
      "ply\r\nformat binary_little_endian 1.0\r\nelement vertex 3\r\ncomment x y z follow\r\n"
      "property float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\n"
      "comment a triangle\r\nproperty list uchar int vertex_indices\r\nend_header\n";
  binary += floatBytes({0, 0, 0, 2, 0, 0, 0, 3, 0});
  binary += '\3';
  const std::vector<int32_t> face = {0, 1, 2};
  binary.append(reinterpret_cast<const char*>(face.data()), 12);
  auto bin = mfr::loadScene(write("comments_binary.ply", binary));
  ASSERT_TRUE(bin.ok()) << bin.error().message;
  EXPECT_EQ(bin->triangleCount(), 1u);
  EXPECT_NEAR(summedArea(*bin), 3.0, 1e-9);
  // comments still count toward the 10,000-line header bound
  std::string many = "ply\nformat ascii 1.0\nelement vertex 3\n";
  for (int i = 0; i < 10001; ++i) many += "comment " + std::to_string(i) + "\n";
  many +=
      "property float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string manyPath = write("many_comments.ply", many);
  EXPECT_TRUE(refused(mfr::loadScene(manyPath), manyPath, {"more than 10000 lines"}));
}

// ---------------------------------------------------------------------------------------------
// Row 20 (glTF): negative offsets and counts

TEST_F(ReliabilityCamera, GltfNegativeAccessorOffsetsAndSparseCountsAreRefusedNamingTheField) {
  const auto refusedWith = [&](const std::function<void(json&)>& edit, const std::string& field) {
    json doc = twoSquaresGltf({}, {});
    edit(doc);
    const std::string path = write("negative.gltf", doc.dump());
    return refused(mfr::loadScene(path), path, {field, "must be a non-negative integer"});
  };
  EXPECT_TRUE(refusedWith([](json& d) { d["accessors"][0]["byteOffset"] = -4; },
                          "accessors[0].byteOffset -4"));
  EXPECT_TRUE(refusedWith([](json& d) { d["accessors"][0]["byteOffset"] = 4.0; },
                          "accessors[0].byteOffset 4.0"));
  EXPECT_TRUE(refusedWith(
      [](json& d) {
        d["accessors"][0]["sparse"] = {{"count", -1},
                                       {"indices", {{"bufferView", 1}, {"componentType", 5123}}},
                                       {"values", {{"bufferView", 0}}}};
      },
      "accessors[0].sparse.count -1"));
  EXPECT_TRUE(refusedWith(
      [](json& d) {
        d["accessors"][0]["sparse"] = {
            {"count", 1},
            {"indices", {{"bufferView", 1}, {"componentType", 5123}, {"byteOffset", -2}}},
            {"values", {{"bufferView", 0}}}};
      },
      "accessors[0].sparse.indices.byteOffset -2"));
  EXPECT_TRUE(refusedWith([](json& d) { d["bufferViews"][1]["byteOffset"] = -96; },
                          "bufferViews[1].byteOffset -96"));
  EXPECT_TRUE(refusedWith([](json& d) { d["accessors"][1]["bufferView"] = -1; },
                          "accessors[1].bufferView -1"));
  // zero and positive values load
  json good = twoSquaresGltf({}, {});
  good["accessors"][0]["byteOffset"] = 0;
  auto loaded = mfr::loadScene(write("good.gltf", good.dump()));
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded->triangleCount(), 4u);
}

}  // namespace
