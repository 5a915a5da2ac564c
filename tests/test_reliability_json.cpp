// JSON and the files that carry it, as a hostile user writes them (issue 49 rows 1, 14 and 21):
//  - JSON nested deeper than kMaxJsonDepth in every reader (a glTF node's extras 20,000 levels
//    deep, a byteStride 100,000 deep, model and dataset metadata 200,000 deep, a JSON scene) is
//    one line naming the file and the limit; before the limit, tinygltf's conversion and mfr's own
//    error messages (which serialised the value) overflowed the stack. Every case runs in this
//    process, on the default stack, so a recursion on the value would crash the test;
//  - a dataset whose scene name or metadata is not UTF-8 is refused when read and when written
//    (mfr train printed nlohmann's "[json.exception.type_error.316]");
//  - a dataset sample outside the range readDataset accepts (a target of 2) is refused when
//    written, by the same check;
//  - models and datasets are opened once: a name switched between a file and a FIFO never blocks
//    a read.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_timeout.hpp"
#include "error_assertions.hpp"
#include "gltf_quads.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/dfaoit.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/scene/load.hpp"
#include "scratch_folder.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::cleanError;
using mfr::test::CliRun;
using mfr::test::contains;
using mfr::test::refused;
using nlohmann::json;

constexpr const char* kTooDeep = "JSON nested deeper than 64 levels";

class ReliabilityJson : public mfr::test::ScratchFolderTest {
 protected:
  ReliabilityJson() : ScratchFolderTest("mfr_reliability_json") {}
  std::string write(const std::string& name, const std::string& bytes) const {
    return mfr::test::writeFile(root() / name, bytes);
  }
  std::string path(const std::string& name) const { return (root() / name).string(); }
  CliRun cli(const std::string& args) const {
    return mfr::test::runCliTimed(args, root(), mfr::test::inDir(root()));
  }
};

/// `depth` arrays, one inside the other, around `inner`.
std::string nested(size_t depth, const std::string& inner = "0") {
  return std::string(depth, '[') + inner + std::string(depth, ']');
}

/// A glTF of one triangle (its buffer a data URI) as text, with `"@HOLE@"` replaced by `raw`
/// where `place` puts the hole: raw JSON text that nlohmann need not build (or dump) itself.
template <class Place>
std::string gltfWith(Place place, const std::string& raw) {
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::string bin(reinterpret_cast<const char*>(p), sizeof p);
  json doc = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
      {"buffers",
       {{{"byteLength", 36},
         {"uri", "data:application/octet-stream;base64," + mfr::test::base64Encode(bin)}}}}};
  place(doc);
  std::string text = doc.dump();
  const size_t hole = text.find("\"@HOLE@\"");
  if (hole != std::string::npos) text.replace(hole, 8, raw);
  return text;
}

void le32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}

/// A GLB whose JSON chunk is `text` (no BIN chunk).
std::string glbOf(std::string text) {
  while (text.size() % 4 != 0) text += ' ';
  std::string out = "glTF";
  le32(out, 2);
  le32(out, static_cast<uint32_t>(12 + 8 + text.size()));
  le32(out, static_cast<uint32_t>(text.size()));
  le32(out, 0x4E4F534Au);
  return out + text;
}

/// A .mfrds file written byte by byte (writeDataset refuses what these tests need): one sample
/// per target, in scene 0, zero features.
std::string datasetBytes(const std::vector<std::string>& scenes, const std::string& metadata,
                         const std::vector<float>& targets) {
  std::string out("MFRDS\0\0\0", 8);
  const auto u32 = [&out](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  u32(mfr::learn::kDatasetVersion);
  u32(12);
  u32(1);
  u32(static_cast<uint32_t>(scenes.size()));
  for (const std::string& name : scenes) {
    u32(static_cast<uint32_t>(name.size()));
    out += name;
  }
  u32(static_cast<uint32_t>(metadata.size()));
  out += metadata;
  const uint64_t count = targets.size();
  out.append(reinterpret_cast<const char*>(&count), 8);
  for (const float t : targets) {
    for (int i = 0; i < 4; ++i) u32(0);
    const float features[12] = {};
    out.append(reinterpret_cast<const char*>(features), sizeof features);
    out.append(reinterpret_cast<const char*>(&t), 4);
  }
  return out;
}

/// A network the deep k-buffer's size checks accept (12 inputs, 1 output) with `metadata`.
mfr::learn::Model dkbShapedModel(const std::string& metadata) {
  return {mfr::learn::makeMlp({12, 4, 1}, 1), metadata};
}

/// Metadata 200,000 levels deep and under the 1 MiB metadata limit.
std::string deepMetadata() {
  return "{\"features\": " + nested(200000) + "}";
}

// ---------------------------------------------------------------------------------------------
// The limit

TEST(JsonLimits, DepthLimitIsSixtyFourLevelsAndStringsDoNotCount) {
  EXPECT_EQ(mfr::kMaxJsonDepth, 64);
  EXPECT_EQ(mfr::jsonDepthProblem(nested(64)), "");
  EXPECT_EQ(mfr::jsonDepthProblem(nested(65)), std::string(kTooDeep) + " (arrays and objects)");
  std::string objects;  // objects count as arrays do
  for (int i = 0; i < 65; ++i) objects += "{\"a\":";
  objects += "0" + std::string(65, '}');
  EXPECT_NE(mfr::jsonDepthProblem(objects), "");
  // brackets inside strings (escaped quotes too) are text, not nesting
  EXPECT_EQ(mfr::jsonDepthProblem("[\"" + std::string(1000, '[') + "\\\"" + std::string(1000, '{') +
                                  "\"]"),
            "");
  // not JSON before the limit: parsing reports that (the check is silent); past the limit, an
  // unclosed text is still too deep
  EXPECT_EQ(mfr::jsonDepthProblem("[[1,]"), "");
  EXPECT_EQ(mfr::jsonDepthProblem(""), "");
  EXPECT_NE(mfr::jsonDepthProblem(std::string(1000000, '[')), "");
}

TEST(JsonLimits, ExcerptOfAValueIsBoundedAndNeverRecursive) {
  // nlohmann parses and destroys deep values iteratively; dump and copy recurse (crashed here)
  const json deep = json::parse(nested(200000));
  EXPECT_EQ(mfr::jsonExcerpt(deep), "an array of 1 item");
  EXPECT_EQ(mfr::jsonExcerpt(json::object({{"a", 1}, {"b", 2}})), "an object of 2 members");
  EXPECT_EQ(mfr::jsonExcerpt(json(2147483644)), "2147483644");
  EXPECT_EQ(mfr::jsonExcerpt(json(std::string(5000, 'x')), 10), "\"xxxxxxxxxx\"...");
  // bytes that are not UTF-8 (nlohmann's dump throws type_error.316 on them) and newlines
  EXPECT_EQ(mfr::jsonExcerpt(json(std::string("a\xff\nb"))), "\"a\xef\xbf\xbd\\nb\"");
}

// ---------------------------------------------------------------------------------------------
// glTF and GLB through tinygltf, JSON scenes

TEST_F(ReliabilityJson, GltfExtrasNestedTooDeeplyIsOneLine) {
  const auto extras = [](json& doc) { doc["nodes"][0]["extras"] = "@HOLE@"; };
  // 20,000 levels in 40 KB: tinygltf's recursive conversion of extras overflowed the stack
  const std::string deep = write("deep.gltf", gltfWith(extras, nested(20000)));
  EXPECT_TRUE(refused(mfr::loadScene(deep), deep, {kTooDeep}));
  const std::string deepGlb = write("deep.glb", glbOf(gltfWith(extras, nested(20000))));
  EXPECT_TRUE(refused(mfr::loadScene(deepGlb), deepGlb, {kTooDeep}));
  // extras up to the limit load: the node object is level 3, its extras levels 4 to 64
  const std::string limit = write("limit.gltf", gltfWith(extras, nested(61)));
  auto loaded = mfr::loadScene(limit);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded->triangleCount(), 1u);
  const std::string over = write("over.gltf", gltfWith(extras, nested(62)));
  EXPECT_TRUE(refused(mfr::loadScene(over), over, {kTooDeep}));
  // the CLI: one line, exit code 1
  EXPECT_TRUE(cleanError(cli("render deep.gltf --width 16 --height 16 -q -o a.png"),
                         {"deep.gltf", kTooDeep}));
  EXPECT_FALSE(fs::exists(root() / "a.png"));
  EXPECT_TRUE(cleanError(cli("info deep.glb -q"), {"deep.glb", kTooDeep}));
}

TEST_F(ReliabilityJson, GltfByteStrideNestedDeeplyIsOneLineAndNeverSerialised) {
  const auto stride = [](json& doc) { doc["bufferViews"][0]["byteStride"] = "@HOLE@"; };
  // 100,000 levels: the stride's error message serialised the whole value
  const std::string deep = write("stride.gltf", gltfWith(stride, nested(100000)));
  EXPECT_TRUE(refused(mfr::loadScene(deep), deep, {kTooDeep}));
  // a shallow array is named by its size, a long string is cut
  const std::string array = write("array.gltf", gltfWith(stride, nested(3, "4")));
  EXPECT_TRUE(refused(mfr::loadScene(array), array,
                      {"bufferViews[0].byteStride an array of 1 item: must be a multiple of 4"}));
  const std::string text =
      write("text.gltf", gltfWith(stride, "\"" + std::string(100000, 'x') + "\""));
  auto refusal = mfr::loadScene(text);
  EXPECT_TRUE(refused(refusal, text, {"byteStride \"xxxx", "...: must be a multiple of 4"}));
  if (!refusal.ok()) {  // (`text` is the file's path)
    EXPECT_LT(refusal.error().message.size(), text.size() + 150);
  }
}

TEST_F(ReliabilityJson, JsonSceneNestedTooDeeplyIsOneLine) {
  const std::string deep =
      write("deep.json", "{\"mesh\": \"procedural:layers\", \"cameras\": " + nested(200000) + "}");
  EXPECT_TRUE(refused(mfr::loadScene(deep), deep, {kTooDeep}));
  EXPECT_TRUE(cleanError(cli("info deep.json -q"), {"deep.json", kTooDeep}));
}

// ---------------------------------------------------------------------------------------------
// Models (.mfrnn)

TEST_F(ReliabilityJson, ModelMetadataNestedTooDeeplyIsOneLine) {
  const std::string metadata = deepMetadata();
  ASSERT_LT(metadata.size(), size_t{1} << 20);  // under the metadata's length limit
  const std::vector<uint8_t> bytes = mfr::learn::encodeModel(dkbShapedModel(metadata));
  const std::string file = write("deep.mfrnn", std::string(bytes.begin(), bytes.end()));
  EXPECT_TRUE(refused(mfr::learn::readModel(file), file, {"metadata: ", kTooDeep}));
  // never written either
  EXPECT_TRUE(refused(mfr::learn::writeModel(path("w.mfrnn"), dkbShapedModel(metadata)),
                      path("w.mfrnn"), {kTooDeep}));
  EXPECT_FALSE(fs::exists(root() / "w.mfrnn"));
  // a model made in memory (Python's mfr.Model): every check that reads its metadata
  const mfr::learn::Model model = dkbShapedModel(metadata);
  EXPECT_TRUE(refused(mfr::checkDkbModel(model, "(memory)"), "(memory)", {kTooDeep}));
  EXPECT_TRUE(refused(mfr::checkDkbCurveModel(model, "(memory)"), "(memory)", {kTooDeep}));
  EXPECT_TRUE(refused(mfr::dkbModelRule(model, "(memory)"), "(memory)", {kTooDeep}));
  const mfr::learn::Model dfaoit{mfr::learn::makeMlp(mfr::kDfaoitLayers, 1), metadata};
  EXPECT_TRUE(refused(mfr::checkDfaoitModel(dfaoit, "(memory)"), "(memory)", {kTooDeep}));
  // values within the limit that are not strings are named by their size, never serialised
  const std::string composite = "{\"composite\": " + nested(60) + "}";
  EXPECT_TRUE(refused(mfr::dkbModelRule(dkbShapedModel(composite), "(memory)"), "(memory)",
                      {"declares the compositing rule an array of 1 item"}));
  const std::string features = "{\"features\": " + nested(60) + "}";
  EXPECT_TRUE(refused(mfr::checkDkbModel(dkbShapedModel(features), "(memory)"), "(memory)",
                      {"trained on the feature set \"an array of 1 item\""}));
  // the CLI
  EXPECT_TRUE(cleanError(cli("render procedural:layers --width 16 --height 16 -q -o a.png "
                             "--method dkb --budget 64KB --model deep.mfrnn"),
                         {"deep.mfrnn", kTooDeep}));
}

// ---------------------------------------------------------------------------------------------
// Datasets (.mfrds)

TEST_F(ReliabilityJson, DatasetMetadataNestedTooDeeplyIsOneLine) {
  const std::string metadata = deepMetadata();
  const std::string file = write("deep.mfrds", datasetBytes({"scene"}, metadata, {0.5f}));
  EXPECT_TRUE(refused(mfr::learn::readDataset(file), file, {"metadata: ", kTooDeep}));
  EXPECT_TRUE(cleanError(cli("train deep.mfrds -q -o m.mfrnn"), {"deep.mfrds", kTooDeep}));
  EXPECT_FALSE(fs::exists(root() / "m.mfrnn"));
  // in memory: the checks that read a dataset's metadata, and the writer
  mfr::learn::Dataset data;
  data.scenes = {"scene"};
  data.metadata = metadata;
  EXPECT_TRUE(
      refused(mfr::learn::checkDatasetDefinitions(data, "mem.mfrds"), "mem.mfrds", {kTooDeep}));
  EXPECT_TRUE(refused(mfr::learn::datasetRule(data, "mem.mfrds"), "mem.mfrds", {kTooDeep}));
  EXPECT_TRUE(
      refused(mfr::learn::writeDataset(path("w.mfrds"), data), path("w.mfrds"), {kTooDeep}));
  EXPECT_FALSE(fs::exists(root() / "w.mfrds"));
  // a declared value within the limit is named by its size
  data.metadata = "{\"target\": " + nested(60) + "}";
  EXPECT_TRUE(refused(mfr::learn::checkDatasetDefinitions(data, "mem.mfrds"), "mem.mfrds",
                      {"declares target an array of 1 item"}));
}

TEST_F(ReliabilityJson, DatasetSceneNameOrMetadataNotUtf8IsOneLine) {
  // refused, not escaped: the format stores UTF-8 names and JSON metadata (which must be UTF-8),
  // as a model's metadata; Python would read such a name as a str it cannot decode
  const std::string name = write("name.mfrds", datasetBytes({"ok",
                                                             "a\xff"
                                                             "b"},
                                                            "{}", {0.5f}));
  EXPECT_TRUE(refused(mfr::learn::readDataset(name), name,
                      {"scene 1's name is not valid UTF-8 (at byte 1 of 3)"}));
  EXPECT_TRUE(cleanError(cli("train name.mfrds -q -o m.mfrnn"),
                         {"name.mfrds", "scene 1's name is not valid UTF-8"}));
  const std::string meta =
      write("meta.mfrds", datasetBytes({"ok"}, "{\"features\": \"\xc3(\"}", {0.5f}));
  EXPECT_TRUE(refused(mfr::learn::readDataset(meta), meta,
                      {"metadata is not valid UTF-8 (at byte 14 of 18)"}));
  EXPECT_TRUE(cleanError(cli("train meta.mfrds -q -o m.mfrnn"),
                         {"meta.mfrds", "metadata is not valid UTF-8"}));
  EXPECT_FALSE(fs::exists(root() / "m.mfrnn"));
  // neither is written
  mfr::learn::Dataset data;
  data.scenes = {
      "a\xff"
      "b"};
  data.metadata = "{}";
  EXPECT_TRUE(refused(mfr::learn::writeDataset(path("w.mfrds"), data), path("w.mfrds"),
                      {"scene 0's name is not valid UTF-8"}));
  data.scenes = {"ok"};
  data.metadata = "{\"a\": \"\xff\"}";
  EXPECT_TRUE(refused(mfr::learn::writeDataset(path("w.mfrds"), data), path("w.mfrds"),
                      {"metadata is not valid UTF-8"}));
  EXPECT_FALSE(fs::exists(root() / "w.mfrds"));
  // mfr dataset refuses such a scene name before it renders anything
  EXPECT_TRUE(cleanError(cli("dataset 'procedural:layers?k=2\xff' --width 8 --height 8 -q "
                             "-o d.mfrds"),
                         {"procedural:layers?k=2", "not valid UTF-8 (at byte 21)"}));
  EXPECT_FALSE(fs::exists(root() / "d.mfrds"));
}

TEST_F(ReliabilityJson, DatasetTargetOutsideItsRangeIsRefusedWhenWrittenAsWhenRead) {
  // the reader's check, written once (datasetSampleProblem): Python's save_dataset wrote a target
  // of 2 that load_dataset and mfr train then refused
  const std::string file = write("two.mfrds", datasetBytes({"scene"}, "{}", {0.5f, 2.0f}));
  EXPECT_TRUE(
      refused(mfr::learn::readDataset(file), file, {"sample 1: target is 2, outside [0, 1]"}));
  mfr::learn::Dataset data;
  data.scenes = {"scene"};
  data.metadata = "{}";
  data.samples.resize(2);
  data.samples[0].target = 0.5f;
  data.samples[1].target = 2.0f;
  EXPECT_TRUE(refused(mfr::learn::writeDataset(path("w.mfrds"), data), path("w.mfrds"),
                      {"cannot write it: sample 1: target is 2, outside [0, 1]"}));
  EXPECT_FALSE(fs::exists(root() / "w.mfrds"));
  auto problem = mfr::learn::datasetSampleProblem(data.samples[1], 1, 1);
  ASSERT_TRUE(problem.has_value());
  EXPECT_STREQ(problem->field, "targets");
  data.samples[1].target = 1.0f;
  data.samples[1].features[3] = NAN;
  problem = mfr::learn::datasetSampleProblem(data.samples[1], 1, 1);
  ASSERT_TRUE(problem.has_value());
  EXPECT_STREQ(problem->field, "features");
  EXPECT_EQ(problem->text, "feature 3 is nan, not a finite number");
  data.samples[1].features[3] = 0.0f;
  data.samples[1].scene = 1;
  problem = mfr::learn::datasetSampleProblem(data.samples[1], 1, 1);
  ASSERT_TRUE(problem.has_value());
  EXPECT_STREQ(problem->field, "scene");
  data.samples[1].scene = 0;
  ASSERT_TRUE(mfr::learn::writeDataset(path("w.mfrds"), data).ok());
  auto back = mfr::learn::readDataset(path("w.mfrds"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->samples.size(), 2u);
}

// ---------------------------------------------------------------------------------------------
// Opened once

TEST_F(ReliabilityJson, ModelAndDatasetReadsNeverBlockOnANameSwitchedToAFifo) {
  // `m.mfrnn` and `d.mfrds` are symbolic links switched between a good file and a FIFO by
  // another process: a reader that checks the name and then opens it again blocks forever in
  // open() when the FIFO comes in between (no writer); opened once, non-blocking, and checked
  // on the descriptor, every read is the good file or a refusal naming the FIFO
  const mfr::learn::Model model = dkbShapedModel("{}");
  ASSERT_TRUE(mfr::learn::writeModel(path("good.mfrnn"), model).ok());
  mfr::learn::Dataset data;
  data.scenes = {"scene"};
  data.metadata = "{}";
  data.samples.resize(3);
  ASSERT_TRUE(mfr::learn::writeDataset(path("good.mfrds"), data).ok());
  ASSERT_EQ(::mkfifo(path("pipe").c_str(), 0600), 0);
  const std::string modelLink = path("m.mfrnn"), dataLink = path("d.mfrds");
  ASSERT_EQ(::symlink("good.mfrnn", modelLink.c_str()), 0);
  ASSERT_EQ(::symlink("good.mfrds", dataLink.c_str()), 0);
  const std::string tmp = path("tmp.link");

  const pid_t swapper = ::fork();
  ASSERT_GE(swapper, 0);
  if (swapper == 0) {  // system calls only, until killed
    for (int i = 0;; ++i) {
      const char* target = i % 4 == 0 ? "good.mfrnn" : i % 4 == 2 ? "good.mfrds" : "pipe";
      const std::string& link = i % 4 < 2 ? modelLink : dataLink;
      ::unlink(tmp.c_str());
      if (::symlink(target, tmp.c_str()) == 0) ::rename(tmp.c_str(), link.c_str());
    }
  }
  const pid_t reader = ::fork();
  if (reader == 0) {
    ::alarm(10);  // a read blocked on the FIFO ends here, killed by SIGALRM
    // 4000 rounds: the old check-then-open readers blocked within them every time (3 of 3 runs),
    // 400 were not enough
    for (int i = 0; i < 4000; ++i) {
      auto m = mfr::learn::readModel(modelLink);
      if (m.ok() ? m->metadata != "{}" : !contains(m.error().message, "FIFO")) ::_exit(2);
      auto d = mfr::learn::readDataset(dataLink);
      if (d.ok() ? d->samples.size() != 3 : !contains(d.error().message, "FIFO")) ::_exit(3);
    }
    ::_exit(0);
  }
  int status = 0;
  if (reader > 0) ::waitpid(reader, &status, 0);
  ::kill(swapper, SIGKILL);
  ::waitpid(swapper, nullptr, 0);
  ASSERT_GT(reader, 0);
  ASSERT_FALSE(WIFSIGNALED(status)) << "the reader was killed by signal " << WTERMSIG(status)
                                    << " (14: blocked in open() on the FIFO)";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << "exit " << WEXITSTATUS(status) << ": 2: a model read, 3: a dataset read was wrong";
}

}  // namespace
