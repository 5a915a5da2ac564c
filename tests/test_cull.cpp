// Back-face culling (issue 24): `--cull auto|none|back`. auto follows the file (glTF materials
// with doubleSided false lose their back faces; OBJ, PLY, JSON and procedural scenes are
// double-sided), none keeps every face, back culls every back face. A front face winds
// counter-clockwise on screen; a glTF node transform with a negative determinant reverses the
// stored winding. The expectations come from the hand-made files' geometry (which quad faces the
// camera) and, on the Khronos conformance models, from what their READMEs say a correct render
// shows.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "gltf_quads.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/stats_json.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/scene_request.hpp"
#include "shared_scenes.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::GltfQuad;
using nlohmann::json;

fs::path writeTemp(const std::string& name, const std::string& text) {
  const fs::path path =
      fs::temp_directory_path() / ("mfr_cull_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path;
}

json material(bool doubleSided) {
  json m = mfr::test::gltfMaterial({0.8, 0.6, 0.4, 1.0}, "OPAQUE");
  m["doubleSided"] = doubleSided;
  return m;
}

/// Left quad (x in [-2, -0.25]) facing the camera on +z, right quad (x in [0.25, 2]) facing away.
std::string frontAndBack(bool doubleSided) {
  return mfr::test::gltfWithQuads(
      {GltfQuad{-2.0f, -1.0f, -0.25f, 1.0f, 0.0f, material(doubleSided)},
       GltfQuad{0.25f, -1.0f, 2.0f, 1.0f, 0.0f, material(doubleSided), true}});
}

mfr::Scene load(const std::string& name, const std::string& text, mfr::CullMode cull) {
  const fs::path path = writeTemp(name, text);
  auto scene = mfr::loadScene(path.string());
  fs::remove(path);
  EXPECT_TRUE(scene.ok()) << scene.error().message;
  scene->cull = cull;
  return std::move(scene.value());
}

constexpr int kWidth = 64, kHeight = 32;

/// Fragments per pixel seen from (0, 0, 5) (or from behind, (0, 0, -5)), 64 x 32.
std::vector<uint32_t> counts(const mfr::Scene& scene, bool fromBehind = false) {
  mfr::Camera camera;
  camera.eye = {0.0f, 0.0f, fromBehind ? -5.0f : 5.0f};
  camera.target = {0.0f, 0.0f, 0.0f};
  camera.fovYDegrees = 30.0f;
  auto frame = mfr::RasterFrame::build(scene, camera, mfr::RasterOptions{kWidth, kHeight, 16, 2});
  EXPECT_TRUE(frame.ok()) << frame.error().message;
  return mfr::countFragments(*frame);
}

/// Covered pixels in the image's left and right halves.
std::pair<int, int> coveredHalves(const std::vector<uint32_t>& n) {
  int left = 0, right = 0;
  for (size_t p = 0; p < n.size(); ++p)
    if (n[p] > 0) ++(static_cast<int>(p % kWidth) < kWidth / 2 ? left : right);
  return {left, right};
}

TEST(CullMode, NamesParseAndUnknownNamesAreOneLineErrors) {
  for (mfr::CullMode mode : {mfr::CullMode::Auto, mfr::CullMode::None, mfr::CullMode::Back})
    EXPECT_EQ(mfr::parseCullMode(mfr::toString(mode), "--cull").value(), mode);
  auto bad = mfr::parseCullMode("front", "--cull");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "--cull 'front': expected auto, none or back");
  mfr::SceneRequest request;
  request.cull = "sideways";
  auto checked = mfr::checkSceneRequest(request, mfr::Spelling::Python);
  ASSERT_FALSE(checked.ok());
  EXPECT_EQ(checked.error().message, "cull 'sideways': expected auto, none or back");
}

TEST(Cull, GltfDoubleSidedIsReadAndTheDefaultMaterialIsSingleSided) {
  const mfr::Scene scene = load("sided.gltf", frontAndBack(true), mfr::CullMode::Auto);
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_TRUE(scene.materials[0].doubleSided);
  EXPECT_FALSE(
      load("single.gltf", frontAndBack(false), mfr::CullMode::Auto).materials[0].doubleSided);
  json doc = json::parse(frontAndBack(true));
  for (json& primitive : doc["meshes"][0]["primitives"]) primitive.erase("material");
  const mfr::Scene plain = load("plain.gltf", doc.dump(), mfr::CullMode::Auto);
  ASSERT_EQ(plain.materials.size(), 1u);
  EXPECT_FALSE(plain.materials[0].doubleSided);  // glTF's default material
}

TEST(Cull, AutoCullsTheBackFacesOfSingleSidedMaterialsOnly) {
  const mfr::Scene none = load("a.gltf", frontAndBack(false), mfr::CullMode::None);
  const auto [left, right] = coveredHalves(counts(none));
  ASSERT_GT(left, 100);
  ASSERT_EQ(left, right);  // mirror images
  // single-sided: auto and back drop the quad that turns its back to the camera
  for (mfr::CullMode mode : {mfr::CullMode::Auto, mfr::CullMode::Back}) {
    SCOPED_TRACE(mfr::toString(mode));
    const auto halves = coveredHalves(counts(load("a.gltf", frontAndBack(false), mode)));
    EXPECT_EQ(halves, std::make_pair(left, 0));
    // seen from behind, the other quad (world x > 0) is the front face, and it shows on the
    // image's left: world +x points left for a camera looking down +z
    const auto behind =
        coveredHalves(counts(load("a.gltf", frontAndBack(false), mode), /*fromBehind=*/true));
    EXPECT_EQ(behind, std::make_pair(right, 0));
  }
  // double-sided: auto keeps both, back still culls
  EXPECT_EQ(coveredHalves(counts(load("b.gltf", frontAndBack(true), mfr::CullMode::Auto))),
            std::make_pair(left, right));
  EXPECT_EQ(coveredHalves(counts(load("b.gltf", frontAndBack(true), mfr::CullMode::Back))),
            std::make_pair(left, 0));
}

TEST(Cull, ANegativeDeterminantNodeTransformKeepsTheFrontFaceFront) {
  // scale x by -1: the front-facing quad moves to the right half and its stored winding turns
  // clockwise on screen, yet glTF says it is still the front face (NegativeScaleTest)
  json doc = json::parse(frontAndBack(false));
  doc["nodes"][0]["scale"] = {-1.0, 1.0, 1.0};
  const auto none = coveredHalves(counts(load("neg.gltf", doc.dump(), mfr::CullMode::None)));
  const auto culled = coveredHalves(counts(load("neg.gltf", doc.dump(), mfr::CullMode::Auto)));
  EXPECT_EQ(culled, std::make_pair(0, none.second));
  // two mirrors (scale -1, -1, 1: a rotation) leave the winding as stored
  doc["nodes"][0]["scale"] = {-1.0, -1.0, 1.0};
  const auto rotated = coveredHalves(counts(load("rot.gltf", doc.dump(), mfr::CullMode::Auto)));
  EXPECT_EQ(rotated, std::make_pair(0, none.second));
}

TEST(Cull, ObjPlyAndProceduralScenesAreDoubleSidedUnlessBackIsAsked) {
  // one quad facing +z and one facing -z, side by side
  const std::string obj =
      "v -2 -1 0\nv -0.25 -1 0\nv -0.25 1 0\nv -2 1 0\n"
      "v 0.25 -1 0\nv 2 -1 0\nv 2 1 0\nv 0.25 1 0\n"
      "f 1 2 3 4\nf 5 8 7 6\n";
  const mfr::Scene autoScene = load("q.obj", obj, mfr::CullMode::Auto);
  for (const mfr::Material& m : autoScene.materials) EXPECT_TRUE(m.doubleSided);
  const auto both = coveredHalves(counts(autoScene));
  EXPECT_GT(both.first, 100);
  EXPECT_EQ(both.first, both.second);
  EXPECT_EQ(coveredHalves(counts(load("q.obj", obj, mfr::CullMode::Back))),
            std::make_pair(both.first, 0));
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0.25 -1 0\n0.25 1 0\n2 1 0\n2 -1 0\n4 0 1 2 3\n";  // clockwise from +z
  EXPECT_EQ(coveredHalves(counts(load("q.ply", ply, mfr::CullMode::Auto))).second, both.second);
  EXPECT_EQ(coveredHalves(counts(load("q.ply", ply, mfr::CullMode::Back))).second, 0);
  auto procedural = mfr::loadScene("procedural:bottles?count=2");
  ASSERT_TRUE(procedural.ok()) << procedural.error().message;
  for (const mfr::Material& m : procedural->materials) EXPECT_TRUE(m.doubleSided);
}

TEST(Cull, ClosedGeometryLosesAboutHalfItsFragmentsUnderBack) {
  // a closed surface seen from outside: every pixel it covers has as many back as front faces
  mfr::Scene scene = mfr::loadScene("procedural:spheres?count=3").value();
  const mfr::Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : mfr::frameBounds(mfr::sceneBounds(scene));
  uint64_t total[2] = {0, 0};
  int index = 0;
  for (mfr::CullMode mode : {mfr::CullMode::None, mfr::CullMode::Back}) {
    scene.cull = mode;
    auto frame = mfr::RasterFrame::build(scene, camera, mfr::RasterOptions{48, 48, 16, 2});
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    for (uint32_t n : mfr::countFragments(*frame)) total[index] += n;
    ++index;
  }
  ASSERT_GT(total[0], 1000u);
  EXPECT_NEAR(static_cast<double>(total[1]) / static_cast<double>(total[0]), 0.5, 0.05);
}

TEST(Cull, TheStatisticsRecordTheMode) {
  mfr::Scene scene = load("s.gltf", frontAndBack(false), mfr::CullMode::Back);
  mfr::Camera camera;
  camera.eye = {0.0f, 0.0f, 5.0f};
  camera.fovYDegrees = 30.0f;
  auto frame = mfr::RasterFrame::build(scene, camera, mfr::RasterOptions{16, 16, 16, 1});
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  auto out = mfr::render(*frame, mfr::methodPreset("abuffer").value(), {});
  ASSERT_TRUE(out.ok()) << out.error().message;
  EXPECT_EQ(out->stats.cull, mfr::CullMode::Back);
  EXPECT_EQ(mfr::statsToJson(out->stats)["cull"], "back");
}

TEST(Cull, TheCommandLineTakesCullAndReportsIt) {
  const fs::path path = writeTemp("cli.gltf", frontAndBack(true));
  const fs::path dir = path.parent_path();
  const std::string out = (dir / ("mfr_cull_" + std::to_string(::getpid()) + ".png")).string();
  const std::string stats = out + ".json";
  const std::string common = "render " + path.string() +
                             " --camera 0,0,5,0,0,0 --width 16 --height 16 -q -o " + out +
                             " --stats-json " + stats;
  for (const char* mode : {"auto", "none", "back"}) {
    const mfr::test::CliRun r = mfr::test::runCli(common + " --cull " + mode, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    std::ifstream in(stats);
    EXPECT_EQ(json::parse(in)["cull"], mode);
  }
  const mfr::test::CliRun bad = mfr::test::runCli(common + " --cull front", dir);
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.err.find("--cull 'front': expected auto, none or back"), std::string::npos)
      << bad.err;
  EXPECT_EQ(bad.err.find('\n'), bad.err.size() - 1) << "one line: " << bad.err;
  for (const std::string& f : {path.string(), out, stats}) fs::remove(f);
}

// --- the Khronos conformance models (skipped without ../shared/scenes) ---------------------------

/// Pixels of the A-buffer's image (sRGB8) that are the red of the models' "X" marks, from the
/// scene's own framing camera.
int redPixels(const mfr::Scene& scene, int width, int height) {
  auto frame = mfr::RasterFrame::build(scene, mfr::frameBounds(mfr::sceneBounds(scene)),
                                       mfr::RasterOptions{width, height, 16, 2});
  EXPECT_TRUE(frame.ok()) << frame.error().message;
  mfr::RenderOptions options;
  options.background = glm::vec3(1.0f);
  auto out = mfr::render(*frame, mfr::methodPreset("abuffer").value(), options);
  EXPECT_TRUE(out.ok()) << out.error().message;
  const mfr::Image8 image = mfr::encodeSrgb(out->image);
  int red = 0;
  for (size_t i = 0; i < image.rgba.size(); i += 4)
    red += image.rgba[i] >= 160 && image.rgba[i + 1] <= 90 && image.rgba[i + 2] <= 90;
  return red;
}

uint64_t fragments(const mfr::Scene& scene, const mfr::Camera& camera) {
  auto frame = mfr::RasterFrame::build(scene, camera, mfr::RasterOptions{96, 64, 16, 2});
  EXPECT_TRUE(frame.ok()) << frame.error().message;
  uint64_t total = 0;
  for (uint32_t n : mfr::countFragments(*frame)) total += n;
  return total;
}

// README: the "back" column shows the back faces of single-sided planes, culled in a correct
// render (check marks); a red X there means no culling, or culling that ignored the negative
// scale of the second row.
TEST(CullConformance, NegativeScaleTestShowsNoRedCrossUnderAuto) {
  MFR_SHARED_SCENE(path, "khronos-conformance/NegativeScaleTest/glTF/NegativeScaleTest.gltf");
  mfr::Scene scene = mfr::loadScene(path.string()).value();
  const mfr::Camera camera = mfr::frameBounds(mfr::sceneBounds(scene));
  scene.cull = mfr::CullMode::None;
  EXPECT_GT(redPixels(scene, 192, 128), 20) << "without culling both rows show the X";
  const uint64_t all = fragments(scene, camera);
  scene.cull = mfr::CullMode::Auto;
  EXPECT_EQ(redPixels(scene, 192, 128), 0);
  const uint64_t culled = fragments(scene, camera);
  EXPECT_LT(culled, all);
  std::printf("[ cull ] NegativeScaleTest 96x64: %llu fragments with none, %llu with auto\n",
              static_cast<unsigned long long>(all), static_cast<unsigned long long>(culled));
}

/// The triangles of `full` whose material is one of `names`.
mfr::Scene onlyMaterials(const mfr::Scene& full, const std::vector<std::string>& names) {
  mfr::Scene part = full;
  part.indices.clear();
  part.triangleMaterial.clear();
  for (size_t t = 0; t < full.triangleCount(); ++t) {
    const std::string& name = full.materials[full.triangleMaterial[t]].name;
    if (std::find(names.begin(), names.end(), name) == names.end()) continue;
    part.indices.insert(part.indices.end(), full.indices.begin() + 3 * t,
                        full.indices.begin() + 3 * t + 3);
    part.triangleMaterial.push_back(full.triangleMaterial[t]);
  }
  return part;
}

// README (TextureSettingsTest): the "single-sided" row's test tile shows its back face: culled,
// the tile behind it (a check mark) shows. The sampler rows: test_texture_sampler.cpp.
TEST(CullConformance, TextureSettingsTestSidedRowsShowNoRedCross) {
  MFR_SHARED_SCENE(path, "khronos-conformance/TextureSettingsTest/glTF/TextureSettingsTest.gltf");
  const mfr::Scene full = mfr::loadScene(path.string()).value();
  mfr::Scene sided = onlyMaterials(full, {"SingleSidedMaterial", "DoubleSidedMaterial"});
  ASSERT_GT(sided.triangleCount(), 0u) << "the sided rows' materials are named in the file";
  sided.cull = mfr::CullMode::None;
  EXPECT_GT(redPixels(sided, 160, 160), 10);
  sided.cull = mfr::CullMode::Auto;
  EXPECT_EQ(redPixels(sided, 160, 160), 0);
}

// README (TextureSettingsTest): the clamp rows' test tiles clamp against a green bar (solid green;
// repeat or mirror shows a red X), the mirror rows' find the check mark by mirroring (repeat shows
// a red X, clamp a red block), the repeat rows' by repeating. Each row's test tile alone (its
// material), the file's samplers, then every texture forced to repeat (the red crosses return).
TEST(SamplerConformance, TextureSettingsTestSamplerRowsShowNoRedCross) {
  MFR_SHARED_SCENE(path, "khronos-conformance/TextureSettingsTest/glTF/TextureSettingsTest.gltf");
  const mfr::Scene full = mfr::loadScene(path.string()).value();
  int forcedRed = 0;
  for (const char* row :
       {"TextureClampMaterialS", "TextureClampMaterialT", "TextureMirrorMaterialS",
        "TextureMirrorMaterialT", "TextureRepeatMaterialS", "TextureRepeatMaterialT"}) {
    SCOPED_TRACE(row);
    mfr::Scene tile = onlyMaterials(full, {row});
    ASSERT_GT(tile.triangleCount(), 0u) << "the row's material is named in the file";
    const int red = redPixels(tile, 160, 160);
    EXPECT_EQ(red, 0);
    for (mfr::Material& m : tile.materials) m.baseColorSampler = mfr::TextureSampler{};
    const int redRepeating = redPixels(tile, 160, 160);
    forcedRed += redRepeating;
    std::printf(
        "[ sampler ] TextureSettingsTest %s: %d red pixels (%d with every texture "
        "repeating)\n",
        row, red, redRepeating);
  }
  EXPECT_GT(forcedRed, 100) << "repeat everywhere shows the crosses the file's samplers avoid";
}

// TwoSidedPlane: one double-sided textured plane, seen from both sides under auto; back culls it
// from exactly one side.
TEST(CullConformance, TwoSidedPlaneShowsBothSidesUnderAuto) {
  MFR_SHARED_SCENE(path, "khronos-conformance/TwoSidedPlane/glTF/TwoSidedPlane.gltf");
  mfr::Scene scene = mfr::loadScene(path.string()).value();
  ASSERT_TRUE(scene.materials[0].doubleSided);
  const mfr::Camera front = mfr::frameBounds(mfr::sceneBounds(scene));
  mfr::Camera back = front;
  back.eye = front.target - (front.eye - front.target);
  const uint64_t seenFront = fragments(scene, front), seenBack = fragments(scene, back);
  ASSERT_GT(seenFront, 100u);
  EXPECT_NEAR(static_cast<double>(seenBack), static_cast<double>(seenFront), 0.02 * seenFront);
  scene.cull = mfr::CullMode::Back;
  const uint64_t culledFront = fragments(scene, front), culledBack = fragments(scene, back);
  // one view sees the front face (all of it), the other the back face (none of it)
  EXPECT_TRUE((culledFront == seenFront && culledBack == 0) ||
              (culledFront == 0 && culledBack == seenBack))
      << culledFront << " of " << seenFront << ", " << culledBack << " of " << seenBack;
}

}  // namespace
