// The command line's outputs and numbers, as a hostile user would try them (issue 49, rows 12, 13,
// 16, 19 and 20): two outputs of one run at one path are refused before any work, names up to
// NAME_MAX (255 bytes) are written, paths of any length are cut in error lines, 64-bit options do
// not saturate, and index options refuse negatives. Every run is tiny (16 x 16 pixels).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/core/image.hpp"
#include "temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::CliRun;

const std::string kScene = "procedural:spheres --width 16 --height 16 -q";

fs::path scratch() {
  static const fs::path dir = mfr::test::processTempDir("mfr_reliability_cli");
  return dir;
}

CliRun runCli(const std::string& args) {
  return mfr::test::runCli(args, scratch());
}

/// `mfr ARGS` run from the folder `cwd` (relative output paths).
CliRun runCliIn(const fs::path& cwd, const std::string& args) {
  return mfr::test::runShell("cd '" + cwd.string() + "' && " + MFR_CLI_PATH + " " + args,
                             scratch());
}

/// The TempDir's own folder.
fs::path folder(const mfr::test::TempDir& dir) {
  return fs::path(dir.file("x")).parent_path();
}

/// Every entry under `dir`, relative, symbolic links not followed.
std::set<std::string> entries(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    names.insert(fs::relative(e.path(), dir).string());
  return names;
}

/// Failed with exit `code` (no signal) and one line on stderr of under 1000 characters holding
/// every one of `needles`.
void expectOneLineError(const CliRun& r, int code, const std::vector<std::string>& needles,
                        const std::string& what) {
  EXPECT_FALSE(r.signaled) << what;
  EXPECT_EQ(r.exitCode, code) << what << "\n" << r.err.substr(0, 2000);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << "\n"
                                                             << r.err.substr(0, 2000);
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);)
    EXPECT_LT(line.size(), 1000u) << what << "\n" << line.substr(0, 2000);
  for (const std::string& needle : needles)
    EXPECT_NE(r.err.find(needle), std::string::npos) << what << ": no '" << needle << "' in\n"
                                                     << r.err.substr(0, 2000);
}

// --- JSON outputs that name a path which is not UTF-8 ------------------------------------------
TEST(ReliabilityCli, JsonOutputsNamingAPathThatIsNotUtf8AreWritten) {
  // JSON carries Unicode text only: the byte 0xff of the scene's name is written as U+FFFD (it
  // was nlohmann's "[json.exception.type_error.316]" and exit 1)
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const fs::path d = folder(dir);
  const std::string obj = (d / "quad\xff.obj").string();
  std::ofstream(obj) << "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n";
  const std::string shown = (d / "quad\xef\xbf\xbd.obj").string();
  const CliRun info = runCli("info '" + obj + "' --json --width 16 --height 16");
  ASSERT_EQ(info.exitCode, 0) << info.err;
  EXPECT_EQ(nlohmann::json::parse(info.out).at("scene"), shown) << info.out;
  const std::string stats = (d / "q.json").string();
  const CliRun render = runCli("render '" + obj + "' --width 16 --height 16 -q -o '" +
                               (d / "q.png").string() + "' --stats-json '" + stats + "'");
  ASSERT_EQ(render.exitCode, 0) << render.err;
  std::ifstream in(stats);
  EXPECT_EQ(nlohmann::json::parse(in).at("scene"), shown);
}

// --- row 12: two outputs of one run at one path ------------------------------------------------

TEST(ReliabilityCli, RenderOutputsAtOnePathAreRefusedBeforeAnyWork) {
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const fs::path d = folder(dir);
  fs::create_directories(d / "real");
  fs::create_directory_symlink(d / "real", d / "link");
  const std::string existing = dir.write("target.png", "old");
  fs::create_symlink(d / "target.png", d / "alias.png");
  const std::set<std::string> before = entries(d);
  const std::string D = d.string();
  struct Case {
    std::string args;
    std::vector<std::string> needles;
  };
  const std::vector<Case> cases = {
      {"-o " + D + "/x.png --stats-json " + D + "/x.png", {"--out", "--stats-json", "x.png"}},
      {"-o " + D + "/x.png --depth-complexity " + D + "/./x.png",
       {"--out", "--depth-complexity", "/./x.png"}},
      {"-o " + D + "/x.png --k-map " + D + "/sub/../x.png", {"--out", "--k-map", "sub/../x.png"}},
      {"-o " + D + "/y.png --k-map " + D + "/m.png --samples 4 --overflow-map " + D + "/m.png",
       {"--k-map", "--overflow-map", "m.png"}},
      {"-o " + D + "/real/x.png --stats-json " + D + "/link/x.png",
       {"--out", "--stats-json", "link/x.png"}},
      {"-o " + D + "/target.png --depth-complexity " + D + "/alias.png",
       {"--out", "--depth-complexity", "alias.png"}},
      {"-m vkb --importance-factors " + D + "/f -o " + D + "/f/depth.png",
       {"--out", "--importance-factors", "depth.png"}},
      {"-m vkb --importance-map " + D + "/i.png --stats-json " + D + "/i.png",
       {"--importance-map", "--stats-json"}},
  };
  for (const Case& c : cases) {
    const CliRun r = runCli("render " + kScene + " " + c.args);
    std::vector<std::string> needles = c.needles;
    needles.push_back("are the same file");
    expectOneLineError(r, 1, needles, c.args);
    EXPECT_EQ(entries(d), before) << c.args;  // nothing written, not even the first output
  }
  std::ifstream in(existing);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "old");
  // relative spellings, and the default --out (mfr.png) against a named output
  const CliRun relative = runCliIn(d, "render " + kScene + " -o x.png --stats-json ./x.png");
  expectOneLineError(relative, 1, {"--out 'x.png'", "--stats-json './x.png'"}, "relative");
  const CliRun byDefault = runCliIn(d, "render " + kScene + " --k-map mfr.png");
  expectOneLineError(byDefault, 1, {"--out 'mfr.png'", "--k-map 'mfr.png'"}, "default --out");
  EXPECT_EQ(entries(d), before);
}

TEST(ReliabilityCli, DistinctOutputsAndSpecialFilesStillRender) {
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const std::string D = folder(dir).string();
  const CliRun r =
      runCli("render " + kScene + " -o " + D + "/a.png --stats-json " + D +
             "/a.json --depth-complexity " + D + "/a_depth.png --k-map " + D + "/a_k.png");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* name : {"a.png", "a.json", "a_depth.png", "a_k.png"})
    EXPECT_TRUE(fs::exists(fs::path(D) / name)) << name;
  // a device is written in place: two outputs there replace nothing
  const CliRun null = runCli("render " + kScene + " -o " + D +
                             "/b.png --stats-json /dev/null --depth-complexity /dev/null");
  EXPECT_EQ(null.exitCode, 0) << null.err;
}

TEST(ReliabilityCli, TrainDatasetAndMetricsOutputsAtOnePathAreRefused) {
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const fs::path d = folder(dir);
  const std::string D = d.string();
  struct Case {
    std::string args;
    std::vector<std::string> needles;
  };
  const std::vector<Case> cases = {
      {"train " + D + "/none.mfrds -o " + D + "/m.mfrnn --log " + D + "/x --loss-curve " + D + "/x",
       {"--log", "--loss-curve"}},
      {"train " + D + "/none.mfrds -o " + D + "/m.mfrnn --log " + D + "/m.mfrnn",
       {"--out", "--log"}},
      // against the default log name, OUT.log.csv
      {"train " + D + "/none.mfrds -o " + D + "/m.mfrnn --loss-curve " + D + "/m.mfrnn.log.csv",
       {"--log", "--loss-curve", "m.mfrnn.log.csv"}},
      {"dataset " + kScene + " -o " + D + "/x.mfrds --curve-out " + D + "/./x.mfrds",
       {"--out", "--curve-out"}},
      {"metrics " + D + "/a.png " + D + "/b.png --flip-map " + D + "/m.png --error-map " + D +
           "/q/../m.png",
       {"--flip-map", "--error-map"}},
  };
  for (const Case& c : cases) {
    const CliRun r = runCli(c.args);
    std::vector<std::string> needles = c.needles;
    needles.push_back("are the same file");
    expectOneLineError(r, 1, needles, c.args);
    EXPECT_TRUE(entries(d).empty()) << c.args;
  }
  // the check refuses only what collides: a missing dataset is still the error it was
  const CliRun missing = runCli("train " + D + "/none.mfrds -o " + D + "/m.mfrnn");
  expectOneLineError(missing, 1, {"none.mfrds"}, "missing dataset");
}

TEST(ReliabilityCli, AnOutputAtAnInputsPathIsRefusedAndTheInputKept) {
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const fs::path d = folder(dir);
  const std::string D = d.string();
  for (const char* name : {"d.mfrds", "a.png", "b.png", "q.obj", "m.mfrnn"})
    std::ofstream(d / name) << "kept";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"train " + D + "/d.mfrds -o " + D + "/./d.mfrds", "is the dataset"},
      {"metrics " + D + "/a.png " + D + "/b.png --flip-map " + D + "/x/../b.png",
       "is the test image"},
      {"metrics " + D + "/a.png " + D + "/b.png --error-map " + D + "/a.png", "is the reference"},
      {"render " + D + "/q.obj --width 16 --height 16 -o " + D + "/q.obj", "is the scene"},
      {"render procedural:spheres --width 16 --height 16 --method dkb --model " + D +
           "/m.mfrnn --stats-json " + D + "/m.mfrnn",
       "is the --model"},
  };
  for (const auto& [args, needle] : cases) {
    expectOneLineError(runCli(args), 1, {needle, "would replace that input"}, args);
    for (const char* name : {"d.mfrds", "a.png", "b.png", "q.obj", "m.mfrnn"}) {
      std::ifstream in(d / name);
      std::string text;
      in >> text;
      EXPECT_EQ(text, "kept") << args << ": " << name;
    }
  }
}

// --- row 13: output names up to NAME_MAX -----------------------------------------------------

TEST(ReliabilityCli, OutputNamesOf255BytesAreWritten) {
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const fs::path d = folder(dir);
  const std::string image = std::string(251, 'i') + ".png";   // 255 bytes, NAME_MAX
  const std::string stats = std::string(250, 's') + ".json";  // 255 bytes
  const std::string data = std::string(249, 'd') + ".mfrds";  // 255 bytes
  const std::string folder = std::string(255, 'c');           // the compare folder
  ASSERT_EQ(image.size(), 255u);
  ASSERT_EQ(stats.size(), 255u);
  ASSERT_EQ(data.size(), 255u);
  const CliRun render = runCli("render " + kScene + " -o " + (d / image).string() +
                               " --stats-json " + (d / stats).string());
  EXPECT_EQ(render.exitCode, 0) << render.err.substr(0, 2000);
  EXPECT_TRUE(fs::is_regular_file(d / image));
  EXPECT_TRUE(fs::is_regular_file(d / stats));
  const CliRun dataset =
      runCli("dataset " + kScene + " --budget-steps 1 -o " + (d / data).string());
  EXPECT_EQ(dataset.exitCode, 0) << dataset.err.substr(0, 2000);
  EXPECT_TRUE(fs::is_regular_file(d / data));
  const CliRun compare = runCli("compare " + kScene + " -M 50% -m fkb -o " + (d / folder).string());
  EXPECT_EQ(compare.exitCode, 0) << compare.err.substr(0, 2000);
  EXPECT_TRUE(fs::is_regular_file(d / folder / "report.html"));
  // nothing left beside them (no temporary or staging name)
  EXPECT_EQ(entries(d).size(), 3u + 1u + entries(d / folder).size());
}

// --- row 16: paths of any length are cut in error lines ----------------------------------------

TEST(ReliabilityCli, FiveThousandCharacterPathsGiveShortErrorLines) {
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const std::string D = folder(dir).string();
  std::string longFolder = D;  // 50 components of 99 characters: about 5,000, none exists
  for (int i = 0; i < 50; ++i) longFolder += "/" + std::string(99, 'p');
  ASSERT_GT(longFolder.size(), 5000u);
  const std::string L = longFolder;
  struct Case {
    std::string args;
    std::string reason;  // what must survive the cut
  };
  const std::vector<Case> cases = {
      {"render " + kScene + " -o " + L + "/x.png", "cannot write PNG"},
      {"render " + kScene + " -o " + D + "/x.png --stats-json " + L + "/s.json",
       "cannot open for writing"},
      {"render " + kScene + " -o " + D + "/x.png -m dkb --model " + L + "/m.mfrnn",
       "cannot be read"},
      {"compare " + kScene + " -M 50% -m dkb --model " + L + "/m.mfrnn -o " + D + "/c",
       "cannot be read"},
      {"compare " + kScene + " -M 50% -m fkb -o " + L + "/c", "cannot create the output folder"},
      {"train " + L + "/d.mfrds -o " + D + "/m.mfrnn", "cannot be read"},
      {"dataset " + kScene + " --budget-steps 1 -o " + L + "/x.mfrds", "cannot open for writing"},
      {"metrics " + L + "/a.png " + L + "/b.png", "cannot be read"},
      {"info " + L + "/scene.gltf -q", "cannot be read"},
  };
  for (const Case& c : cases)
    expectOneLineError(runCli(c.args), 1, {c.reason, "..."}, c.args.substr(0, 120));

  // existing files named by about 4,000 characters (PATH_MAX is 4096): "./" repeated
  std::string padded = D;
  for (int i = 0; i < 1950; ++i) padded += "/.";
  mfr::Image8 small;
  small.width = small.height = 2;
  small.rgba.assign(16, 255);
  mfr::Image8 large = small;
  large.width = large.height = 3;
  large.rgba.assign(36, 255);
  ASSERT_TRUE(mfr::writePng(D + "/small.png", small).ok());
  ASSERT_TRUE(mfr::writePng(D + "/large.png", large).ok());
  expectOneLineError(runCli("metrics " + padded + "/small.png " + padded + "/large.png"), 1,
                     {"images must have the same size", "..."}, "metrics of different sizes");
}

// --- row 19: 64-bit options do not saturate ------------------------------------------------------

TEST(ReliabilityCli, SeedAndShuffleDrawOrderRefuseNegativeAndTooLargeValues) {
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const fs::path d = folder(dir);
  const std::string D = d.string();
  const std::vector<std::string> commands = {
      "render " + kScene + " -o " + D + "/x.png",
      "info " + kScene,
      "compare " + kScene + " -M 50% -m fkb -o " + D + "/c",
      "dataset " + kScene + " -o " + D + "/x.mfrds",
  };
  const std::vector<std::pair<std::string, std::string>> values = {
      {"-1", "must be 0 or more"},
      {"18446744073709551616", "out of range"},
      {"12345678901234567890123", "out of range"},
      {"-99999999999999999999999", "out of range"}};
  for (const std::string& command : commands)
    for (const char* option : {"--seed", "--shuffle-draw-order"})
      for (const auto& [value, reason] : values) {
        const std::string args = command + " " + option + " " + value;
        expectOneLineError(runCli(args), 2, {option, reason, value}, args);
      }
  for (const auto& [value, reason] : values) {
    const std::string args = "train " + D + "/x.mfrds -o " + D + "/m.mfrnn --seed " + value;
    expectOneLineError(runCli(args), 2, {"--seed", reason}, args);
  }
  // signed 64-bit options too (strtoll saturates at 2^63 - 1)
  expectOneLineError(runCli("render " + kScene + " -o " + D + "/x.png --k 99999999999999999999"), 2,
                     {"--k", "out of range"}, "--k");
  EXPECT_TRUE(entries(d).empty());
  // the whole range is still taken
  const CliRun largest =
      runCli("info " + kScene + " --seed 18446744073709551615 --shuffle-draw-order 0");
  EXPECT_EQ(largest.exitCode, 0) << largest.err;
  const CliRun hex = runCli("info " + kScene + " --seed 0xffffffffffffffff");
  EXPECT_EQ(hex.exitCode, 0) << hex.err;
}

// --- row 20: index options refuse negatives --------------------------------------------------

TEST(ReliabilityCli, NegativeViewSceneAndOrbitViewAreRefused) {
  const mfr::test::TempDir dir("mfr_reliability_cli");
  const fs::path d = folder(dir);
  const std::string D = d.string();
  const std::vector<std::string> commands = {"render " + kScene + " -o " + D + "/x.png",
                                             "info " + kScene,
                                             "compare " + kScene + " -M 50% -m fkb -o " + D + "/c",
                                             "dataset " + kScene + " -o " + D + "/x.mfrds"};
  const std::vector<std::pair<std::string, std::string>> options = {
      {"--view -1", "--view"},
      {"--view=-1", "--view"},
      {"--view -2", "--view"},
      {"--scene -1", "--scene"},
      {"--orbit 4 --orbit-view -1", "--orbit-view"}};
  for (const std::string& command : commands)
    for (const auto& [option, name] : options) {
      const std::string args = command + " " + option;
      expectOneLineError(runCli(args), 2, {name, "must be 0 or more"}, args);
    }
  EXPECT_TRUE(entries(d).empty());
  // 0 is an index
  const CliRun first = runCli("info " + kScene + " --orbit 4 --orbit-view 0");
  EXPECT_EQ(first.exitCode, 0) << first.err;
}

}  // namespace
