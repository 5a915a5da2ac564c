// Deep k-buffer models per compositing rule (issue 14 sec. 3): datasets and models record the rule
// of their optimal targets, the built-in model matching a method's compositing is the one it runs,
// and a model trained for the other rule is a one-line error, in the library and on the command
// line.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/scene/procedural.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

fs::path tempDir() {
  static const fs::path dir = test::processTempDir("mfr_model_rule_test");
  return dir;
}

std::string path(const std::string& name) {
  return (tempDir() / name).string();
}

test::CliRun runCli(const std::string& args) {
  return test::runCli(args, tempDir());
}

void expectOneLineError(const test::CliRun& r, std::initializer_list<std::string> needles) {
  EXPECT_EQ(r.exitCode, 1) << r.err;
  for (const std::string& needle : needles)
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

learn::Model modelDeclaring(const nlohmann::json& extra) {
  nlohmann::json meta = {{"features", kDkbFeatureSet}, {"target", learn::kDkbTargetScaling}};
  if (extra.is_object()) meta.update(extra);
  return {learn::makeMlp(learn::kDkbLayers, 3), meta.dump()};
}

TEST(ModelRule, AModelsRuleIsItsDeclaredCompositeAndHybridWhenUndeclared) {
  EXPECT_EQ(dkbModelRule(modelDeclaring({}), "m").value(), Compositing::Hybrid);
  EXPECT_EQ(dkbModelRule(modelDeclaring({{"composite", "hybrid"}}), "m").value(),
            Compositing::Hybrid);
  EXPECT_EQ(dkbModelRule(modelDeclaring({{"composite", "kbuffer"}}), "m").value(),
            Compositing::KBuffer);
  for (const nlohmann::json& bad : {nlohmann::json("weighted-blended"), nlohmann::json(3)}) {
    auto rule = dkbModelRule(modelDeclaring({{"composite", bad}}), "bad.mfrnn");
    ASSERT_FALSE(rule);
    EXPECT_NE(rule.error().message.find("bad.mfrnn"), std::string::npos);
  }
}

TEST(ModelRule, BuiltInModelsDeclareTheirRuleAndDiffer) {
  auto hybrid = builtinDkbModel(Compositing::Hybrid);
  auto kbuffer = builtinDkbModel(Compositing::KBuffer);
  ASSERT_TRUE(hybrid) << hybrid.error().message;
  ASSERT_TRUE(kbuffer) << kbuffer.error().message;
  EXPECT_EQ(dkbModelRule(**hybrid, "h").value(), Compositing::Hybrid);
  EXPECT_EQ(dkbModelRule(**kbuffer, "k").value(), Compositing::KBuffer);
  EXPECT_NE(learn::encodeModel(**hybrid), learn::encodeModel(**kbuffer));
  EXPECT_EQ(builtinDkbModel().value(), hybrid.value()) << "the default is the hybrid model";
  EXPECT_FALSE(builtinDkbModel(Compositing::WeightedBlended));
}

TEST(ModelRule, AMethodRunsTheBuiltInModelOfItsCompositing) {
  for (const std::string preset : {"dkb", "dkb-fill"})
    for (Compositing rule : {Compositing::Hybrid, Compositing::KBuffer}) {
      MethodDesc m = methodPreset(preset).value();
      m.compositing = rule;
      auto model = dkbModelFor(m);
      ASSERT_TRUE(model) << model.error().message;
      EXPECT_EQ(model.value(), builtinDkbModel(rule).value()) << preset << " " << toString(rule);
    }
}

TEST(ModelRule, AGivenModelOfTheOtherRuleIsAOneLineError) {
  MethodDesc m = methodPreset("dkb").value();
  m.model = std::make_shared<const learn::Model>(modelDeclaring({{"composite", "hybrid"}}));
  m.compositing = Compositing::Hybrid;
  EXPECT_TRUE(dkbModelFor(m));
  m.compositing = Compositing::KBuffer;
  auto mismatch = dkbModelFor(m);
  ASSERT_FALSE(mismatch);
  const std::string& message = mismatch.error().message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_NE(message.find("hybrid"), std::string::npos) << message;
  EXPECT_NE(message.find("kbuffer"), std::string::npos) << message;
  m.model = std::make_shared<const learn::Model>(modelDeclaring({{"composite", "kbuffer"}}));
  EXPECT_TRUE(dkbModelFor(m));
}

TEST(ModelRule, TargetsDependOnTheRuleTheyWereComputedFor) {
  // hybrid composites the tail, so its optimal k(p) differs from kbuffer's, which drops it
  auto scene = makeProceduralScene("procedural:glassware?count=4&segments=16", 2);
  ASSERT_TRUE(scene);
  RasterOptions ro;
  ro.width = ro.height = 48;
  ro.threads = 1;
  auto frame = RasterFrame::build(*scene, *scene->defaultCamera, ro);
  ASSERT_TRUE(frame) << frame.error().message;
  learn::ViewSamplingOptions o;
  o.sampleFraction = 1.0;
  o.budgetSteps = 3;
  o.compositing = Compositing::Hybrid;
  auto hybrid = learn::sampleView(frame.value(), 0, 0, o);
  o.compositing = Compositing::KBuffer;
  auto kbuffer = learn::sampleView(frame.value(), 0, 0, o);
  ASSERT_TRUE(hybrid && kbuffer);
  ASSERT_EQ(hybrid->size(), kbuffer->size());
  ASSERT_FALSE(hybrid->empty());
  size_t differ = 0;
  for (size_t i = 0; i < hybrid->size(); ++i) {
    EXPECT_EQ((*hybrid)[i].pixel, (*kbuffer)[i].pixel);
    EXPECT_EQ((*hybrid)[i].features, (*kbuffer)[i].features) << "the features do not depend on it";
    differ += (*hybrid)[i].target != (*kbuffer)[i].target;
  }
  EXPECT_GT(differ, hybrid->size() / 50);
}

// --- the command line ---------------------------------------------------------------------------

std::string datasetFor(const std::string& rule) {
  const std::string out = path(rule + ".mfrds");
  if (fs::exists(out)) return out;
  const auto r = runCli(
      "dataset 'procedural:glassware?count=2&segments=12' 'procedural:city?rows=2&columns=2' "
      "'procedural:city?rows=3&columns=2' --width 32 --height 32 --orbit 2 --quiet --composite " +
      rule + " -o " + out);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return out;
}

std::string modelFor(const std::string& rule) {
  const std::string out = path(rule + ".mfrnn");
  if (fs::exists(out)) return out;
  const auto r = runCli("train " + datasetFor(rule) + " --epochs 1 --seed 2 --quiet -o " + out);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return out;
}

TEST(ModelRuleCli, DatasetsAndModelsRecordTheirRule) {
  for (const std::string rule : {"hybrid", "kbuffer"}) {
    auto data = learn::readDataset(datasetFor(rule));
    ASSERT_TRUE(data) << data.error().message;
    EXPECT_EQ(nlohmann::json::parse(data->metadata).at("composite"), rule);
    auto model = learn::readModel(modelFor(rule));
    ASSERT_TRUE(model) << model.error().message;
    EXPECT_EQ(nlohmann::json::parse(model->metadata).at("composite"), rule);
  }
  expectOneLineError(runCli("dataset procedural:city --width 16 --height 16 --composite wboit -o " +
                            path("w.mfrds")),
                     {"--composite", "wboit"});
}

TEST(ModelRuleCli, TrainingRefusesDatasetsOfBothRules) {
  expectOneLineError(runCli("train " + datasetFor("hybrid") + " " + datasetFor("kbuffer") +
                            " --epochs 1 --quiet -o " + path("mixed.mfrnn")),
                     {"kbuffer.mfrds", "hybrid"});
  EXPECT_FALSE(fs::exists(path("mixed.mfrnn")));
}

TEST(ModelRuleCli, ValidationFamilyHoldsOutEverySceneOfTheFamily) {
  const std::string out = path("family.mfrnn");
  const auto r = runCli("train " + datasetFor("hybrid") +
                        " --epochs 1 --quiet --validation-family city -o " + out);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  auto model = learn::readModel(out);
  ASSERT_TRUE(model);
  const auto training = nlohmann::json::parse(model->metadata).at("training");
  EXPECT_EQ(training.at("train_scenes"),
            nlohmann::json::array({"procedural:glassware?count=2&segments=12"}));
  EXPECT_EQ(training.at("validation_scenes"),
            nlohmann::json::array(
                {"procedural:city?rows=2&columns=2", "procedural:city?rows=3&columns=2"}));
  expectOneLineError(runCli("train " + datasetFor("hybrid") +
                            " --epochs 1 --quiet --validation-family hair -o " + out),
                     {"--validation-family", "hair"});
}

TEST(ModelRuleCli, RenderAndCompareRefuseAModelOfTheOtherRule) {
  const std::string scene = "'procedural:city?rows=2&columns=2' --width 32 --height 32 --quiet ";
  expectOneLineError(runCli("render " + scene + "-m dkb -M 60KB --composite kbuffer --model " +
                            modelFor("hybrid") + " -o " + path("x.png")),
                     {"hybrid.mfrnn", "kbuffer", "hybrid"});
  expectOneLineError(runCli("render " + scene + "-m dkb-fill -M 60KB --model " +
                            modelFor("kbuffer") + " -o " + path("x.png")),
                     {"kbuffer.mfrnn", "--composite kbuffer"});
  EXPECT_FALSE(fs::exists(path("x.png")));
  expectOneLineError(runCli("compare " + scene + "--methods fkb,dkb --budget 60KB --model " +
                            modelFor("kbuffer") + " --composite hybrid -o " + path("cmp")),
                     {"kbuffer.mfrnn"});
  {  // under the default rules (both), dkb runs under the one its model was trained for
    auto r = runCli("compare " + scene + "--methods fkb,dkb --budget 60KB --model " +
                    modelFor("kbuffer") + " --repeat 1 --warmup 0 -o " + path("cmp"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    std::ifstream in(path("cmp") + "/results.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    std::vector<std::string> labels;
    for (const nlohmann::json& run : j["methods"]) labels.push_back(run["label"]);
    EXPECT_EQ(labels, (std::vector<std::string>{"fkb-kbuffer", "fkb-hybrid", "dkb"}));
    EXPECT_EQ(j["methods"][2]["compositing"], "kbuffer");
  }
  // matching rules render, the built-in models included
  for (const std::string rule : {"hybrid", "kbuffer"}) {
    auto r = runCli("render " + scene + "-m dkb -M 60KB --composite " + rule + " --model " +
                    modelFor(rule) + " -o " + path(rule + ".png"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    r = runCli("render " + scene + "-m dkb -M 60KB --composite " + rule + " -o " +
               path(rule + "_builtin.png"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
  }
}

}  // namespace
}  // namespace mfr
