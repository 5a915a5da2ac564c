// makeMethod and the scene request: the library's one check of the options every front end takes
// (the command line, Python, the viewer), with errors in each front end's spelling; the same
// option sets through the CLI and Python are compared in python/tests/test_render.py.
#include <gtest/gtest.h>

#include <string>

#include "mfr/core/option_name.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/scene_request.hpp"

namespace mfr {
namespace {

std::string errorOf(const std::string& preset, const MethodOverrides& o,
                    Spelling spelling = Spelling::Cli) {
  auto m = makeMethod(preset, o, spelling);
  return m ? "" : m.error().message;
}

TEST(OptionName, PythonSpellsFlagsAsKeywords) {
  EXPECT_EQ(spell(Spelling::Cli, "--occupancy-d"), "--occupancy-d");
  EXPECT_EQ(spell(Spelling::Python, "--occupancy-d"), "occupancy_d");
  EXPECT_EQ(spell(Spelling::Python, "--width/--height"), "width/height");
  EXPECT_EQ(spell(Spelling::Python, "--view and --camera"), "view and camera");
  EXPECT_EQ(spell(Spelling::Python, "k"), "k");
}

TEST(MakeMethod, AppliesTheOverridesToThePreset) {
  MethodOverrides o;
  o.k = 6;
  o.composite = "hybrid";
  o.occupancyD = 3;
  MethodDesc m = makeMethod("kplus-heap+occupancy", o).value();
  EXPECT_EQ(m.k, 6u);
  EXPECT_EQ(m.compositing, Compositing::Hybrid);
  EXPECT_EQ(m.occupancyWords, 3);
  // nothing set: the preset as it is
  const MethodDesc plain = makeMethod("kplus-heap", {}).value();
  EXPECT_FALSE(plain.k.has_value());
  EXPECT_EQ(plain.compositing, methodPreset("kplus-heap")->compositing);
}

TEST(MakeMethod, ImportanceParametersAndTheNoiseSeed) {
  MethodOverrides o;
  o.importance.alpha = 0.5;
  o.importance.nLimit = 8;
  o.importance.fovea = std::vector<double>{10, 20};
  o.importance.fresnelTerm = false;
  o.seed = 42;
  const MethodDesc m = makeMethod("vkb", o).value();
  EXPECT_FLOAT_EQ(m.importance.alpha, 0.5f);
  EXPECT_FLOAT_EQ(m.importance.nLimit, 8.0f);
  ASSERT_TRUE(m.importance.fovea.has_value());
  EXPECT_FLOAT_EQ(m.importance.fovea->y, 20.0f);
  EXPECT_FALSE(m.importance.useFresnel);
  EXPECT_TRUE(m.importance.useDepth);
  EXPECT_EQ(m.importance.seed, 42u);
  EXPECT_FLOAT_EQ(m.importance.noise, ImportanceParams{}.noise);  // not set: the default
}

TEST(MakeMethod, OptionsAMethodDoesNotTakeAreRefusedInEachSpelling) {
  MethodOverrides k;
  k.k = 4;
  EXPECT_EQ(errorOf("abuffer", k).rfind("--k: does not apply to abuffer (only to ", 0), 0u);
  EXPECT_EQ(errorOf("abuffer", k, Spelling::Python).rfind("k: does not apply to abuffer", 0), 0u);
  MethodOverrides occ;
  occ.occupancyD = 2;
  EXPECT_EQ(errorOf("fkb", occ, Spelling::Python).rfind("occupancy_d: does not apply to fkb", 0),
            0u);
  MethodOverrides imp;
  imp.importance.noise = 0.2;
  EXPECT_EQ(errorOf("fkb", imp).rfind("--noise: does not apply to fkb", 0), 0u);
  EXPECT_EQ(errorOf("fkb", imp, Spelling::Python).rfind("importance: does not apply to fkb", 0),
            0u);
  MethodOverrides composite;
  composite.composite = "hybrid";
  EXPECT_EQ(errorOf("wboit", composite).rfind("--composite: does not apply to wboit", 0), 0u);
  MethodOverrides model;
  model.modelPath = "/nonexistent.mfrnn";
  EXPECT_EQ(errorOf("vkb", model).rfind("--model: does not apply to vkb", 0), 0u);
}

TEST(MakeMethod, ValuesOutOfRangeNameTheOptionAndItsRange) {
  const auto withK = [](int64_t k) {
    MethodOverrides o;
    o.k = k;
    return o;
  };
  EXPECT_EQ(errorOf("fkb", withK(0)), "--k: must be in [1, 1048576]");
  EXPECT_EQ(errorOf("fkb", withK((1 << 20) + 1)), "--k: must be in [1, 1048576]");
  EXPECT_EQ(errorOf("fkb", withK(-3), Spelling::Python), "k: must be in [1, 1048576]");
  EXPECT_EQ(errorOf("fkb", withK(1 << 20)), "");
  EXPECT_EQ(errorOf("zbuffer", withK(2)), "--k: zbuffer has k = 1");
  MethodOverrides occ;
  occ.occupancyD = 65;
  EXPECT_EQ(errorOf("fkb+occupancy", occ), "--occupancy-d: must be in [1, 64]");
  MethodOverrides rule;
  rule.composite = "sorted";
  EXPECT_EQ(errorOf("fkb", rule).rfind("--composite: ", 0), 0u);
  const auto importance = [](auto set) {
    MethodOverrides o;
    set(o.importance);
    return o;
  };
  EXPECT_EQ(errorOf("vkb", importance([](ImportanceOverrides& i) { i.alpha = 1.5; })),
            "--importance-alpha: must be in [0, 1]");
  EXPECT_EQ(
      errorOf("vkb", importance([](ImportanceOverrides& i) { i.nLimit = 0.5; }), Spelling::Python),
      "importance['n_limit']: must be in [1, 1e6]");
  EXPECT_EQ(errorOf("vkb", importance([](ImportanceOverrides& i) { i.peripheryD = 0; })),
            "--periphery-d: must be in (0, 100]");
  EXPECT_EQ(errorOf("vkb", importance([](ImportanceOverrides& i) { i.noise = -0.1; })),
            "--noise: must be in [0, 1]");
  EXPECT_EQ(errorOf("vkb",
                    importance([](ImportanceOverrides& i) { i.fovea = std::vector<double>{1.0}; })),
            "--fovea: expected two finite pixel coordinates X,Y");
}

TEST(MakeMethod, TheViewerKeepsSettingsAMethodDoesNotTake) {
  MethodOverrides o;
  o.ignoreInapplicable = true;
  o.k = 5;
  o.occupancyD = 4;
  o.composite = "hybrid";
  o.importance = ImportanceOverrides::all(ImportanceParams{});
  const MethodDesc abuffer = makeMethod("abuffer", o).value();  // takes none of them but hybrid
  EXPECT_FALSE(abuffer.k.has_value());
  EXPECT_EQ(abuffer.occupancyWords, 0);
  EXPECT_EQ(makeMethod("zbuffer", o)->k, methodPreset("zbuffer")->k);  // zbuffer keeps k = 1
  EXPECT_EQ(makeMethod("wboit", o)->compositing, Compositing::WeightedBlended);
  o.k = 0;  // a value out of range is still an error
  EXPECT_EQ(errorOf("fkb", o), "--k: must be in [1, 1048576]");
}

TEST(MakeMethod, ModelFilesAndComparisonModels) {
  MethodOverrides o;
  o.modelPath = "/nonexistent/m.mfrnn";
  const std::string e = errorOf("dkb", o);
  EXPECT_NE(e.find("/nonexistent/m.mfrnn"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
  auto unused = checkModelUsed({"fkb", "vkb"});
  ASSERT_FALSE(unused.ok());
  EXPECT_EQ(unused.error().message.rfind("--model: none of the methods uses it (only ", 0), 0u);
  EXPECT_EQ(checkModelUsed({"fkb"}, Spelling::Python).error().message.rfind("model: none", 0), 0u);
  EXPECT_TRUE(checkModelUsed({"fkb", "dkb"}).ok());
}

TEST(SceneRequest, ChecksInEachSpelling) {
  const auto errorOfRequest = [](auto set, Spelling s = Spelling::Cli) {
    SceneRequest r;
    set(r);
    auto ok = checkSceneRequest(r, s);
    return ok ? std::string() : ok.error().message;
  };
  EXPECT_EQ(errorOfRequest([](SceneRequest& r) { r.width = 0; }),
            "--width/--height 0x1024: must be in [1, 16384]");
  EXPECT_EQ(errorOfRequest([](SceneRequest& r) { r.width = 0; }, Spelling::Python),
            "width/height 0x1024: must be in [1, 16384]");
  EXPECT_EQ(errorOfRequest([](SceneRequest& r) { r.orbitView = 2; }, Spelling::Python),
            "orbit_view 2: needs orbit N with N > 2");
  EXPECT_EQ(errorOfRequest([](SceneRequest& r) { r.zoom = 0; }), "--zoom: must be in [0.01, 100]");
  EXPECT_EQ(errorOfRequest([](SceneRequest& r) {
              r.background = {0.5, 2, 0};
            }),
            "--background: components must be in [0, 1]");
  EXPECT_EQ(errorOfRequest([](SceneRequest& r) {
              r.view = 0;
              r.camera = "0,0,3,0,0,0";
            }),
            "--view and --camera: give one camera, not both");
  EXPECT_EQ(errorOfRequest(
                [](SceneRequest& r) {
                  r.cameraNumbers = {1, 2, 3};
                },
                Spelling::Python)
                .rfind("camera: expected 6, 9 or 10 numbers", 0),
            0u);
  EXPECT_EQ(errorOfRequest([](SceneRequest&) {}), "");
}

TEST(SceneRequest, OrbitViewsAndThePreviousCamera) {
  const Scene scene = loadScene("procedural:bottles?count=2").value();
  SceneRequest r;
  r.orbit = 6;
  const SceneViews all = sceneViews(scene, "s", r).value();
  ASSERT_EQ(all.cameras.size(), 6u);
  EXPECT_FALSE(all.previousCamera.has_value());
  r.orbitView = 4;
  const SceneViews one = sceneViews(scene, "s", r).value();
  ASSERT_EQ(one.cameras.size(), 1u);
  EXPECT_EQ(one.cameras[0].eye, all.cameras[4].eye);
  ASSERT_TRUE(one.previousCamera.has_value());
  EXPECT_EQ(one.previousCamera->eye, all.cameras[3].eye);
  // zoom moves the camera towards its target
  SceneRequest z;
  z.zoom = 2;
  const Camera near = sceneViews(scene, "s", z)->cameras[0];
  const Camera base = sceneViews(scene, "s", SceneRequest{})->cameras[0];
  EXPECT_NEAR(glm::length(near.eye - near.target), glm::length(base.eye - base.target) / 2, 1e-4);
  SceneRequest v;
  v.view = 0;  // a procedural scene has no file cameras
  EXPECT_EQ(sceneViews(scene, "s", v, Spelling::Python).error().message,
            "s: view 0 but the scene has 0 camera(s)");
}

}  // namespace
}  // namespace mfr
