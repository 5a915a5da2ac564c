// The command line end to end: bad input is one line on stderr naming the input and a non-zero
// exit (never a crash); good input writes the promised files with the promised keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/method/method.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;

using mfr::test::CliRun;

fs::path tempDir() {
  static const fs::path dir = mfr::test::processTempDir("mfr_cli_test");
  return dir;
}

CliRun runCli(const std::string& args) {
  return mfr::test::runCli(args, tempDir());
}

std::string write(const std::string& name, const std::string& content) {
  const fs::path p = tempDir() / name;
  std::ofstream(p, std::ios::binary) << content;
  return p.string();
}

// One line on stderr, naming `needle`, exit code 1, no signal, no image written.
void expectCleanFailure(const std::string& args, const std::string& needle) {
  const fs::path image = tempDir() / "never.png";
  fs::remove(image);
  const CliRun r = runCli(args + " -o " + image.string());
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
  EXPECT_FALSE(fs::exists(image)) << args;
}

TEST(Cli, MissingFileIsAnErrorNamingIt) {
  expectCleanFailure("render /nonexistent/scene.glb -q", "/nonexistent/scene.glb");
}

TEST(Cli, MalformedGltfIsAnErrorNamingIt) {
  const std::string path =
      write("broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [");
  expectCleanFailure("render " + path + " -q", path);
}

TEST(Cli, MalformedObjIsAnErrorNamingIt) {
  const std::string path = write("broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 9\n");
  expectCleanFailure("render " + path + " -q", path);
}

TEST(Cli, MalformedPlyIsAnErrorNamingIt) {
  const std::string path =
      write("broken.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n");
  expectCleanFailure("render " + path + " -q", path);
}

TEST(Cli, NaNVertexIsAnErrorNamingTheFile) {
  const std::string path = write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  expectCleanFailure("render " + path + " -q", path);
}

TEST(Cli, EmptySceneIsAnErrorNamingTheFile) {
  const std::string path = write("empty.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  expectCleanFailure("render " + path + " -q", path);
}

TEST(Cli, UnknownProceduralSceneAndParameterAreErrors) {
  expectCleanFailure("render procedural:teapot -q", "teapot");
  expectCleanFailure("render 'procedural:layers?depth=3' -q", "depth");
  expectCleanFailure("render 'procedural:layers?k=abc' -q", "abc");
}

TEST(Cli, ZeroNegativeAndAbsurdSizesAreErrors) {
  expectCleanFailure("render procedural:spheres --width 0 -q", "0x1024");
  expectCleanFailure("render procedural:spheres --height -5 -q", "-5");
  expectCleanFailure("render procedural:spheres --width 16385 -q", "16385");
}

TEST(Cli, BadBudgetsAreErrors) {
  expectCleanFailure("render procedural:spheres --method fkb --budget 12XB -q", "12XB");
  expectCleanFailure(
      "render procedural:spheres --method fkb --budget 1KB --width 64 --height 64 -q", "1024 B");
  expectCleanFailure("render procedural:spheres --method kplus-heap -q", "budget");
}

TEST(Cli, ThreadsOutsideZeroTo1024AreErrorsAndZeroIsAllCores) {
  expectCleanFailure("render procedural:spheres --threads -1 -q",
                     "--threads -1: must be in [0, 1024], 0 = all cores");
  expectCleanFailure("render procedural:spheres --threads 1025 -q",
                     "--threads 1025: must be in [0, 1024], 0 = all cores");
  const CliRun r = runCli("render procedural:spheres --width 16 --height 16 --threads 0 -q --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GE(j["engine_counters"]["threads"].get<int>(), 1);
}

TEST(Cli, UnknownMethodAndNonFiniteCameraAreErrors) {
  expectCleanFailure("render procedural:spheres --method kbuffer9 -q", "kbuffer9");
  expectCleanFailure("render procedural:spheres --camera nan,0,5,0,0,0 -q", "--camera");
}

TEST(Cli, RenderWritesImageMapsAndStatsWithTheDocumentedKeys) {
  const fs::path dir = tempDir() / "render";
  fs::create_directories(dir);
  const CliRun r = runCli(
      "render procedural:spheres --width 96 --height 80 --method kplus-sb --budget 400KB "
      "--composite hybrid -q -o " +
      (dir / "img.png").string() + " --k-map " + (dir / "k.png").string() + " --depth-complexity " +
      (dir / "n.png").string() + " --stats-json " + (dir / "stats.json").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* f : {"img.png", "k.png", "n.png", "stats.json"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "stats.json"));
  for (const char* key : {"method", "budget_bytes", "bytes_used", "fragments_generated",
                          "fragments_captured", "fragments_lost", "k_min", "k_max", "time_ms"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["method"], "kplus-sb");
  EXPECT_EQ(j["budget_bytes"].get<uint64_t>(), 400u * 1024u);
  EXPECT_LE(j["bytes_used"].get<uint64_t>(), 400u * 1024u);
  EXPECT_EQ(j["fragments_captured"].get<uint64_t>() + j["fragments_lost"].get<uint64_t>(),
            j["fragments_generated"].get<uint64_t>());
  EXPECT_TRUE(j["time_ms"].contains("capture"));
  EXPECT_TRUE(j["time_ms"].contains("count"));
}

TEST(Cli, InfoReportsTrianglesAndDepthComplexity) {
  const CliRun r = runCli("info procedural:spheres?count=3 --width 64 --height 64 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["triangles"].get<uint64_t>(), 0u);
  EXPECT_EQ(j["views"][0]["max_depth_complexity"].get<uint32_t>(), 6u);
  // A-buffer bytes: 8 B per pixel (counter + offset) + 8 B per fragment
  EXPECT_EQ(j["views"][0]["abuffer_bytes"].get<uint64_t>(),
            64u * 64u * 8u + j["views"][0]["fragments"].get<uint64_t>() * 8u);
}

TEST(Cli, OrbitWritesOneImagePerView) {
  const fs::path dir = tempDir() / "orbit";
  fs::create_directories(dir);
  const CliRun r = runCli("render procedural:bottles --width 32 --height 32 --orbit 3 -q -o " +
                          (dir / "o.png").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* f : {"o_v000.png", "o_v001.png", "o_v002.png"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
}

// Command-line syntax errors: one "mfr: error: ..." line on stderr and exit 2 (not CLI11's exit
// codes 104-114 and its two lines); --help and --version still print and exit 0.
TEST(Cli, SyntaxErrorsAreOneLineAndExitTwo) {
  const std::pair<const char*, const char*> cases[] = {
      {"render --width 1.5 procedural:spheres", "--width"},
      {"render --no-such-option procedural:spheres", "--no-such-option"},
      {"render procedural:spheres --width", "--width"},
      {"render", "scene"},
      {"", "subcommand"},
      {"rendr procedural:spheres", "'rendr'"},
  };
  for (const auto& [args, needle] : cases) {
    const CliRun r = runCli(args);
    EXPECT_FALSE(r.signaled) << args;
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("mfr: error: ", 0), 0u) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
  // an echoed value is cut short: the line stays bounded whatever the argument's length
  const CliRun longValue =
      runCli("render --width " + std::string(5000, '7') + "x procedural:spheres");
  EXPECT_EQ(longValue.exitCode, 2) << longValue.err;
  EXPECT_LT(longValue.err.size(), 400u) << longValue.err;
}

// An option value echoed in an error is cut (quoteInput): a 5000-character value gives a line of
// bounded length, its start quoted (an unknown method's line also lists the known presets).
TEST(Cli, EchoedOptionValuesAreCutShort) {
  const std::string huge(5000, 'q');
  size_t presetList = 0;
  for (const std::string& name : mfr::presetNames()) presetList += name.size() + 2;
  const std::pair<std::string, std::string> cases[] = {
      {"render procedural:spheres -q --capture " + huge, "--capture 'qqqq"},
      {"render procedural:spheres -q --memory-limit " + huge, "--memory-limit 'qqqq"},
      {"render procedural:spheres -q --method " + huge, "method 'qqqq"},
      {"compare procedural:spheres -q --budget 1MB --methods fkb,fkb" + huge + ",fkb" + huge +
           " --out " + (tempDir() / "never").string(),
       "--methods: method 'fkbqqqq"},
      {"dataset procedural:spheres -q --budget 1MB" + huge + " -o " +
           (tempDir() / "never.mfrds").string(),
       "--budget"},
  };
  for (const auto& [args, needle] : cases) {
    const CliRun r = runCli(args);
    EXPECT_EQ(r.exitCode, 1) << r.err.substr(0, 300);
    EXPECT_LT(r.err.size(), 400u + presetList) << r.err.substr(0, 300);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err.substr(0, 300);
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err.substr(0, 300);
  }
}

TEST(Cli, HelpAndVersionExitZero) {
  for (const char* args : {"--help", "render --help", "--version"}) {
    const CliRun r = runCli(args);
    EXPECT_EQ(r.exitCode, 0) << args << "\n" << r.err;
    EXPECT_FALSE(r.out.empty()) << args;
    EXPECT_TRUE(r.err.empty()) << args << "\n" << r.err;
  }
}

// Past the file-size limit (ulimit -f) the write fails with EFBIG: one line naming the output and
// the reason, a non-zero exit, no signal (SIGXFSZ) and no partial file.
TEST(Cli, FileSizeLimitIsAWriteErrorNotASignal) {
  const fs::path dir = tempDir() / "fsize";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path image = dir / "out.png", stats = dir / "stats.json";
  // 10 blocks of 512 bytes: a 512x512 noisy render's PNG is far larger
  const std::string limited = "sh -c 'ulimit -f 10; exec " + MFR_CLI_PATH;
  const CliRun r =
      mfr::test::runShell(limited + " render procedural:hairball --width 512 --height 512 -q -o " +
                              image.string() + "'",
                          tempDir());
  EXPECT_FALSE(r.signaled) << r.exitCode << " " << r.err;
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(r.err.rfind("mfr: error: " + image.string() + ": ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("write error (File too large)"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(fs::is_empty(dir)) << "a partial or temporary file was left";

  // stdout past the limit (--json into a file) is an error too, not a silently cut output
  const CliRun json = mfr::test::runShell(
      "sh -c 'ulimit -f 1; exec " + MFR_CLI_PATH + " presets --format json'", tempDir());
  EXPECT_FALSE(json.signaled) << json.err;
  EXPECT_EQ(json.exitCode, 1) << json.err;
  EXPECT_EQ(json.err, "mfr: error: stdout: write error (File too large)\n");
}

}  // namespace
