// glTF scenes and primitive modes: `--scene N` picks one of a file's scenes (default the file's
// `scene`), an index the file lacks or a format without scenes is an error; points and lines are
// not surfaces: they are skipped and counted (Scene::primitivesSkipped, the statistics'
// primitives_skipped and the render summary line), never dropped silently. Expectations from the
// hand-made files' own contents and from the Khronos conformance model MeshPrimitiveModes (seven
// primitives: points, lines, line loop, line strip, triangles, triangle strip, triangle fan).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "gltf_quads.hpp"
#include "mfr/scene/load.hpp"
#include "shared_scenes.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// Two scenes: scene 0 holds node 0 (two triangles, a quad), scene 1 node 1 (one triangle) and
/// node 2 (a LINES primitive); the file's `scene` is `defaultScene`.
std::string twoScenes(int defaultScene) {
  const float positions[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  std::string bin(reinterpret_cast<const char*>(positions), sizeof positions);
  const uint16_t quad[] = {0, 1, 2, 0, 2, 3}, tri[] = {0, 1, 2};
  bin.append(reinterpret_cast<const char*>(quad), sizeof quad);
  bin.append(reinterpret_cast<const char*>(tri), sizeof tri);
  bin.append(2, '\0');
  const json views = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
                      {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 12}},
                      {{"buffer", 0}, {"byteOffset", 60}, {"byteLength", 6}}};
  const json accessors = {
      {{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
      {{"bufferView", 1}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}},
      {{"bufferView", 2}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}};
  const json meshes = {
      {{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}},
      {{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 2}}}}},
      {{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}, {"mode", 1}}}}}};
  return json{{"asset", {{"version", "2.0"}}},
              {"scene", defaultScene},
              {"scenes", {{{"nodes", {0}}}, {{"nodes", {1, 2}}}}},
              {"nodes", {{{"mesh", 0}}, {{"mesh", 1}}, {{"mesh", 2}}}},
              {"meshes", meshes},
              {"accessors", accessors},
              {"bufferViews", views},
              {"buffers", mfr::test::gltfEmbeddedBuffer(bin)}}
      .dump();
}

fs::path writeTemp(const std::string& name, const std::string& text) {
  const fs::path path =
      fs::temp_directory_path() / ("mfr_scenes_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path;
}

TEST(GltfScenes, TheFilesSceneByDefaultAndAnyOtherByIndex) {
  const fs::path path = writeTemp("two.gltf", twoScenes(1));
  auto byDefault = mfr::loadScene(path.string());
  ASSERT_TRUE(byDefault.ok()) << byDefault.error().message;
  EXPECT_EQ(byDefault->triangleCount(), 1u);    // scene 1: the triangle
  EXPECT_EQ(byDefault->primitivesSkipped, 1u);  // and its LINES primitive
  mfr::LoadOptions first;
  first.sceneIndex = 0;
  auto zero = mfr::loadScene(path.string(), first);
  ASSERT_TRUE(zero.ok()) << zero.error().message;
  EXPECT_EQ(zero->triangleCount(), 2u);  // scene 0: the quad
  EXPECT_EQ(zero->primitivesSkipped, 0u);
  mfr::LoadOptions missing;
  missing.sceneIndex = 2;
  auto none = mfr::loadScene(path.string(), missing);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("scene 2: the file has 2 scene(s)"), std::string::npos)
      << none.error().message;
  // the file's own `scene` 0 when it names it
  const fs::path other = writeTemp("zero.gltf", twoScenes(0));
  EXPECT_EQ(mfr::loadScene(other.string())->triangleCount(), 2u);
  // formats without scenes
  auto procedural = mfr::loadScene("procedural:bottles", first);
  ASSERT_FALSE(procedural.ok());
  EXPECT_NE(procedural.error().message.find("only glTF files hold several scenes"),
            std::string::npos);
  fs::remove(path);
  fs::remove(other);
}

TEST(GltfScenes, SkippedPrimitivesInTheStatisticsAndTheSummaryLine) {
  const fs::path path = writeTemp("cli.gltf", twoScenes(1));
  const fs::path dir = path.parent_path();
  const std::string out = (dir / ("mfr_scenes_" + std::to_string(::getpid()) + ".png")).string();
  const std::string stats = out + ".json";
  const mfr::test::CliRun r = mfr::test::runCli(
      "render " + path.string() + " --camera 0.5,0.5,3,0.5,0.5,0 --width 16 --height 16 -o " + out +
          " --stats-json " + stats,
      dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find(", 1 point/line primitives skipped"), std::string::npos) << r.err;
  std::ifstream in(stats);
  EXPECT_EQ(json::parse(in)["primitives_skipped"], 1);
  const mfr::test::CliRun bad = mfr::test::runCli(
      "render " + path.string() + " --scene 5 --width 16 --height 16 -o " + out, dir);
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.err.find("scene 5: the file has 2 scene(s)"), std::string::npos) << bad.err;
  for (const std::string& f : {path.string(), out, stats}) fs::remove(f);
}

TEST(GltfScenes, MeshPrimitiveModesSkipsItsFourPointAndLinePrimitives) {
  MFR_SHARED_SCENE(path, "khronos-conformance/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf");
  auto scene = mfr::loadScene(path.string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  // points, lines, line loop, line strip: skipped; triangles, strip, fan: drawn
  EXPECT_EQ(scene->primitivesSkipped, 4u);
  EXPECT_GT(scene->triangleCount(), 0u);
}

}  // namespace
