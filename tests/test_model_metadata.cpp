// The deep k-buffer's model metadata: the built-in model declares the code's feature set and
// target definition (one constant each, kDkbFeatureSet and learn::kDkbTargetScaling), models
// record each dataset by file name and content hash (not by path), and datasets or models of
// another feature set or target are refused. The byte-for-byte retraining check is
// tests/model_repro_test.sh.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/model_file.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

/// A folder of this test, removed at the end.
struct TempFolder {
  fs::path dir;
  explicit TempFolder(const std::string& tag)
      : dir(test::processTempDir("mfr_model_meta_" + tag)) {}
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  std::string operator/(const std::string& name) const { return (dir / name).string(); }
};

std::string readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

fs::path repositoryRoot() {
  return fs::path(__FILE__).parent_path().parent_path();
}

bool isHex16(const std::string& s) {
  return s.size() == 16 && s.find_first_not_of("0123456789abcdef") == std::string::npos;
}

/// Feature set, target and dataset records of a model written by mfr train.
void expectCurrentDefinitions(const learn::Model& model, const std::string& name) {
  SCOPED_TRACE(name);
  const auto meta = nlohmann::json::parse(model.metadata, nullptr, false);
  ASSERT_TRUE(meta.is_object()) << model.metadata;
  EXPECT_EQ(meta.value("features", ""), std::string(kDkbFeatureSet))
      << "stale model: retrain it (scripts/train-model.sh)";
  EXPECT_EQ(meta.value("target", ""), std::string(learn::kDkbTargetScaling))
      << "stale model: retrain it (scripts/train-model.sh)";
  EXPECT_EQ(meta.value("layers", std::vector<int>{}), learn::kDkbLayers);
  EXPECT_EQ(model.net.sizes, learn::kDkbLayers);
  ASSERT_TRUE(meta.contains("training") && meta["training"].contains("datasets"));
  const nlohmann::json& datasets = meta["training"]["datasets"];
  ASSERT_TRUE(datasets.is_array() && !datasets.empty()) << datasets.dump();
  for (const nlohmann::json& d : datasets) {
    ASSERT_TRUE(d.is_object()) << d.dump();
    const std::string file = d.value("file", "");
    EXPECT_FALSE(file.empty()) << d.dump();
    EXPECT_EQ(file.find('/'), std::string::npos) << "a file name, not a path: " << file;
    EXPECT_TRUE(isHex16(d.value("fnv1a64", ""))) << d.dump();
  }
}

TEST(ModelMetadata, BuiltInModelDeclaresTheCodesFeatureSetAndTarget) {
  auto model = builtinDkbModel();
  ASSERT_TRUE(model) << model.error().message;
  expectCurrentDefinitions(**model, "built-in model");
}

TEST(ModelMetadata, TinyReferenceModelDeclaresTheCodesFeatureSetAndTarget) {
  const fs::path path = repositoryRoot() / "models" / "test" / "dkb-tiny.mfrnn";
  auto model = learn::readModel(path.string());
  ASSERT_TRUE(model) << model.error().message;
  expectCurrentDefinitions(model.value(), path.string());
  EXPECT_TRUE(checkDkbModel(model.value(), path.string()));
}

TEST(ModelMetadata, Fnv1a64MatchesTheReferenceVectors) {
  EXPECT_EQ(learn::fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(learn::fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(learn::fnv1a64("foobar"), 0x85944171f73967e8ull);
  EXPECT_EQ(learn::fnv1a64(std::string("\0\xff", 2)), learn::fnv1a64(std::string("\0\xff", 2)));
  EXPECT_NE(learn::fnv1a64(std::string("\0", 1)), learn::fnv1a64(""));
  EXPECT_EQ(learn::hashHex(0x85944171f73967e8ull), "85944171f73967e8");
  EXPECT_EQ(learn::hashHex(1), "0000000000000001");
}

learn::Dataset tinyDataset(const std::string& metadata) {
  learn::Dataset d;
  d.scenes = {"procedural:layers", "procedural:smoke"};
  d.metadata = metadata;
  for (uint32_t i = 0; i < 40; ++i) {
    learn::DatasetSample s;
    s.scene = i % 2;
    s.view = i % 3;
    s.pixel = i;
    for (int c = 0; c < kDkbFeatureCount; ++c) s.features[c] = 0.05f * static_cast<float>(c + i);
    s.target = static_cast<float>(i % 5) / 4.0f;
    d.samples.push_back(s);
  }
  return d;
}

std::string currentDatasetMetadata() {
  return nlohmann::json{{"features", kDkbFeatureSet}, {"target", learn::kDkbTargetScaling}}.dump();
}

TEST(ModelMetadata, ReadingADatasetHashesItsBytes) {
  const TempFolder tmp("hash");
  const std::string path = tmp / "d.mfrds";
  ASSERT_TRUE(learn::writeDataset(path, tinyDataset(currentDatasetMetadata())));
  auto data = learn::readDataset(path);
  ASSERT_TRUE(data) << data.error().message;
  EXPECT_EQ(data->fileHash, learn::fnv1a64(readBytes(path)));
}

TEST(ModelMetadata, DatasetsOfAnotherFeatureSetOrTargetAreRefused) {
  const learn::Dataset current = tinyDataset(currentDatasetMetadata());
  EXPECT_TRUE(learn::checkDatasetDefinitions(current, "a.mfrds"));
  EXPECT_TRUE(learn::checkDatasetDefinitions(tinyDataset(R"({"generator":"test"})"), "b.mfrds"));
  EXPECT_TRUE(learn::checkDatasetDefinitions(tinyDataset("not json"), "c.mfrds"));
  auto features =
      learn::checkDatasetDefinitions(tinyDataset(R"({"features":"mfr-dkb-features-v0","target":")" +
                                                 std::string(learn::kDkbTargetScaling) + "\"}"),
                                     "old.mfrds");
  ASSERT_FALSE(features);
  EXPECT_NE(features.error().message.find("old.mfrds"), std::string::npos);
  EXPECT_NE(features.error().message.find("mfr-dkb-features-v0"), std::string::npos);
  auto target = learn::checkDatasetDefinitions(
      tinyDataset(nlohmann::json{{"features", kDkbFeatureSet}, {"target", "K_M(p) / F(M)"}}.dump()),
      "t.mfrds");
  ASSERT_FALSE(target);
  EXPECT_NE(target.error().message.find("K_M(p) / F(M)"), std::string::npos);
}

TEST(ModelMetadata, ModelsOfAnotherFeatureSetOrTargetAreRefused) {
  const learn::Mlp net = learn::makeMlp(learn::kDkbLayers, 3);
  const std::string features = kDkbFeatureSet, target = learn::kDkbTargetScaling;
  auto meta = [](const nlohmann::json& j) { return j.dump(); };
  EXPECT_TRUE(checkDkbModel({net, meta({{"features", features}, {"target", target}})}, "ok"));
  EXPECT_TRUE(checkDkbModel({net, meta({{"features", features}})}, "no target"));
  auto f = checkDkbModel({net, meta({{"features", "mfr-dkb-features-v0"}, {"target", target}})},
                         "f.mfrnn");
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("f.mfrnn"), std::string::npos);
  EXPECT_NE(f.error().message.find("feature set"), std::string::npos);
  auto t =
      checkDkbModel({net, meta({{"features", features}, {"target", "K_M(p) / F(M)"}})}, "t.mfrnn");
  ASSERT_FALSE(t);
  EXPECT_NE(t.error().message.find("t.mfrnn"), std::string::npos);
  EXPECT_NE(t.error().message.find("target"), std::string::npos);
}

TEST(ModelMetadata, TrainingRecordsDatasetNamesAndHashesNotFolders) {
  const TempFolder tmp("train");
  fs::create_directories(tmp.dir / "a" / "deeper");
  fs::create_directories(tmp.dir / "b");
  const std::string first = tmp / "a/deeper/set.mfrds", second = tmp / "b/set.mfrds";
  ASSERT_TRUE(learn::writeDataset(first, tinyDataset(currentDatasetMetadata())));
  fs::copy_file(first, second);
  const std::string options = " --epochs 2 --batch 8 --seed 3 --quiet ";
  auto r = test::runCli("train " + first + options + "-o " + (tmp / "a.mfrnn"), tmp.dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = test::runCli("train " + second + options + "-o " + (tmp / "b.mfrnn"), tmp.dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(readBytes(tmp / "a.mfrnn"), readBytes(tmp / "b.mfrnn"))
      << "the model's bytes must not depend on the dataset's folder";
  auto model = learn::readModel(tmp / "a.mfrnn");
  ASSERT_TRUE(model) << model.error().message;
  const auto meta = nlohmann::json::parse(model->metadata);
  EXPECT_EQ(meta.at("features"), kDkbFeatureSet);
  EXPECT_EQ(meta.at("target"), learn::kDkbTargetScaling);
  const nlohmann::json expected = nlohmann::json::array(
      {{{"file", "set.mfrds"}, {"fnv1a64", learn::hashHex(learn::fnv1a64(readBytes(first)))}}});
  EXPECT_EQ(meta.at("training").at("datasets"), expected);
  EXPECT_EQ(model->metadata.find(tmp.dir.string()), std::string::npos) << model->metadata;
}

TEST(ModelMetadata, TrainingRefusesADatasetOfAnotherFeatureSet) {
  const TempFolder tmp("refuse");
  const std::string path = tmp / "old.mfrds";
  ASSERT_TRUE(learn::writeDataset(path, tinyDataset(R"({"features":"mfr-dkb-features-v0"})")));
  const auto r = test::runCli("train " + path + " --epochs 1 -o " + (tmp / "m.mfrnn"), tmp.dir);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("mfr-dkb-features-v0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp / "m.mfrnn"));
}

}  // namespace
}  // namespace mfr
