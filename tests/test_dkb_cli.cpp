// mfr dataset -> mfr train -> mfr render --model, end to end as a user runs them: files written,
// training deterministic, bad datasets, models and options rejected with one line naming them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cli_runner.hpp"

namespace {

namespace fs = std::filesystem;

fs::path tempDir() {
  static const fs::path dir = mfr::test::processTempDir("mfr_dkb_cli_test");
  return dir;
}

mfr::test::CliRun runCli(const std::string& args) {
  return mfr::test::runCli(args, tempDir());
}

std::string path(const std::string& name) {
  return (tempDir() / name).string();
}

std::string readBytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

void expectOneLineError(const mfr::test::CliRun& r, const std::string& needle) {
  EXPECT_FALSE(r.signaled);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// A small dataset from two procedural scenes (built once).
const std::string& dataset() {
  static const std::string file = [] {
    const std::string out = path("small.mfrds");
    const auto r = runCli(
        "dataset procedural:layers?k=6 procedural:hairball?strands=200 --width 48 --height 48 "
        "--orbit 2 --quiet -o " +
        out);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return out;
  }();
  return file;
}

TEST(DkbCli, DatasetTrainRenderEndToEndAndTrainingIsDeterministic) {
  const std::string model = path("m.mfrnn"), again = path("m2.mfrnn");
  const std::string common = " --epochs 3 --learning-rate 0.05 --momentum 0.9 --seed 5 --quiet ";
  auto r = runCli("train " + dataset() + common + "-o " + model);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(model + ".log.csv"));
  EXPECT_GT(fs::file_size(model + ".loss.png"), 1000u);
  std::ifstream log(model + ".log.csv");
  std::string line;
  int lines = 0;
  while (std::getline(log, line)) ++lines;
  EXPECT_EQ(lines, 4) << "header + one line per epoch";
  r = runCli("train " + dataset() + common + "-o " + again);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(readBytes(model), readBytes(again)) << "same data, same seed: same model bytes";
  r = runCli(
      "render procedural:hairball?strands=200 --width 64 --height 64 -m dkb-fill -M 200KB "
      "--model " +
      model + " --quiet -o " + path("dkb.png"));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(path("dkb.png")));
}

TEST(DkbCli, BuiltInModelRenders) {
  const auto r = runCli(
      "render procedural:hairball?strands=200 --width 64 --height 64 -m dkb "
      "-M 200KB --quiet -o " +
      path("builtin.png"));
  EXPECT_EQ(r.exitCode, 0) << r.err;
}

TEST(DkbCli, BadModelFilesAndOptionsAreOneLineErrors) {
  const std::string scene = "render procedural:layers --width 32 --height 32 -M 100KB ";
  expectOneLineError(
      runCli(scene + "-m dkb --model " + path("missing.mfrnn") + " -o " + path("x.png")),
      "missing.mfrnn");
  { std::ofstream(path("garbage.mfrnn"), std::ios::binary) << "not a model at all"; }
  expectOneLineError(
      runCli(scene + "-m dkb --model " + path("garbage.mfrnn") + " -o " + path("x.png")),
      "garbage.mfrnn");
  expectOneLineError(
      runCli(scene + "-m vkb --model " + path("garbage.mfrnn") + " -o " + path("x.png")),
      "--model");
  EXPECT_FALSE(fs::exists(path("x.png")));
}

TEST(DkbCli, BadDatasetAndTrainingOptionsAreOneLineErrors) {
  { std::ofstream(path("bad.mfrds"), std::ios::binary) << "MFRDS"; }
  expectOneLineError(runCli("train " + path("bad.mfrds") + " -o " + path("t.mfrnn")), "bad.mfrds");
  expectOneLineError(runCli("train " + dataset() + " --epochs 0 -o " + path("t.mfrnn")),
                     "--epochs");
  expectOneLineError(runCli("train " + dataset() + " --learning-rate nan -o " + path("t.mfrnn")),
                     "--learning-rate");
  expectOneLineError(
      runCli("train " + dataset() + " --validation-scene nope -o " + path("t.mfrnn")), "nope");
  expectOneLineError(runCli("dataset procedural:layers --sample 0 -o " + path("d.mfrds")),
                     "--sample");
  expectOneLineError(runCli("dataset procedural:nothing -o " + path("d.mfrds")), "nothing");
  EXPECT_FALSE(fs::exists(path("t.mfrnn")));
  EXPECT_FALSE(fs::exists(path("d.mfrds")));
}

}  // namespace
