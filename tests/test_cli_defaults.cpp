// The command line does what docs/CLI.md says by default: each preset composites with its own
// rule unless --composite is given (checked on the recorded compositing and bytes, not the exit
// code), and an option that would change nothing for the chosen method is a one-line error.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/method/method_options.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

fs::path tempDir() {
  static const fs::path dir = test::processTempDir("mfr_cli_defaults");
  return dir;
}

nlohmann::json readJson(const fs::path& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f);
}

constexpr int kSize = 64;
constexpr uint64_t kPixels = kSize * kSize;
const std::string kScene = "procedural:bottles --width 64 --height 64 --quiet";

// Renders and returns the stats JSON.
nlohmann::json renderStats(const std::string& options) {
  const fs::path stats = tempDir() / "stats.json";
  fs::remove(stats);
  const test::CliRun r =
      test::runCli("render " + kScene + " " + options + " -o " + (tempDir() / "out.png").string() +
                       " --stats-json " + stats.string(),
                   tempDir());
  EXPECT_EQ(r.exitCode, 0) << options << "\n" << r.err;
  return fs::exists(stats) ? readJson(stats) : nlohmann::json::object();
}

TEST(CliDefaults, DeepAndOptimalPresetsCompositeHybridUnlessTold) {
  for (const char* method : {"dkb", "dkb-fill", "optimal", "optimal-greedy"}) {
    // 160KB: hybrid's per-pixel words leave fewer slots than fragments, kbuffer's do not
    const nlohmann::json own = renderStats(std::string("--method ") + method + " --budget 160KB");
    EXPECT_EQ(own["compositing"], "hybrid") << method;
    // the hybrid tail: 20 B per pixel (3 float colour sums, a float alpha sum, a count)
    EXPECT_EQ(own["bytes_by_category"]["tail"], 20 * kPixels) << method;
    const nlohmann::json told =
        renderStats(std::string("--method ") + method + " --budget 160KB --composite kbuffer");
    EXPECT_EQ(told["compositing"], "kbuffer") << method;
    EXPECT_FALSE(told["bytes_by_category"].contains("tail")) << method;
    // the deep k-buffer spends F(M) whole: the tail's bytes went to fragment nodes
    if (std::string(method).starts_with("dkb")) {
      EXPECT_GT(told["fragment_slots"].get<uint64_t>(), own["fragment_slots"].get<uint64_t>())
          << method;
    }
  }
}

TEST(CliDefaults, OtherPresetsCompositeKBufferUnlessTold) {
  for (const char* method : {"fkb", "kplus-dynamic", "vkb"}) {
    const nlohmann::json own = renderStats(std::string("--method ") + method + " --budget 400KB");
    EXPECT_EQ(own["compositing"], "kbuffer") << method;
    EXPECT_FALSE(own["bytes_by_category"].contains("tail")) << method;
    const nlohmann::json told =
        renderStats(std::string("--method ") + method + " --budget 400KB --composite hybrid");
    EXPECT_EQ(told["compositing"], "hybrid") << method;
    EXPECT_EQ(told["bytes_by_category"]["tail"], 20 * kPixels) << method;
  }
}

// The fair default (issue 48): every method that takes a rule runs under kbuffer and hybrid, the
// oracle too, each row labelled with its rule; --composite narrows it to the rules named.
TEST(CliDefaults, CompareRunsBothRulesUnlessTold) {
  const fs::path out = tempDir() / "compare";
  const std::string base =
      "compare " + kScene + " --budget 400KB --methods fkb,dkb,optimal,wboit --out ";
  test::CliRun r = test::runCli(base + out.string(), tempDir());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json j = readJson(out / "results.json");
  EXPECT_EQ(j["compositing"], "per-method");
  EXPECT_EQ(j["compositing_rules"], nlohmann::json({"kbuffer", "hybrid"}));
  ASSERT_EQ(j["methods"].size(), 7u);
  const char* labels[] = {"fkb-kbuffer",     "fkb-hybrid",     "dkb-kbuffer", "dkb-hybrid",
                          "optimal-kbuffer", "optimal-hybrid", "wboit"};
  const char* names[] = {"fkb", "fkb", "dkb", "dkb", "optimal", "optimal", "wboit"};
  for (size_t i = 0; i < 7; ++i) {
    const nlohmann::json& run = j["methods"][i];
    EXPECT_EQ(run["label"], labels[i]);
    EXPECT_EQ(run["name"], names[i]);
    const bool hybrid = std::string(labels[i]).ends_with("-hybrid");
    if (i < 6) {
      EXPECT_EQ(run["compositing"], hybrid ? "hybrid" : "kbuffer") << labels[i];
    }
    EXPECT_EQ(run["bytes_by_category"].contains("tail"), hybrid) << labels[i];
    EXPECT_EQ(run["image"], std::string(labels[i]) + "_400KB.png");
    EXPECT_TRUE(fs::exists(out / run["image"].get<std::string>())) << labels[i];
  }
  EXPECT_EQ(j["methods"][6]["compositing"],
            "weighted-blended");  // a peer method keeps its own rule
  // the console table says which rule each row ran
  std::string loud = base;  // without --quiet
  loud.erase(loud.find(" --quiet"), 8);
  r = test::runCli(loud + out.string(), tempDir());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* label : {"optimal-kbuffer", "optimal-hybrid"}) {
    const size_t at = r.err.find(std::string("  ") + label + " ");
    ASSERT_NE(at, std::string::npos) << r.err;
    std::istringstream row(r.err.substr(at));
    std::string name, rule;
    row >> name >> rule;
    EXPECT_EQ(rule, std::string(label).substr(8)) << r.err;
  }
  r = test::runCli(base + out.string() + " --composite kbuffer", tempDir());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  j = readJson(out / "results.json");
  EXPECT_EQ(j["compositing"], "kbuffer");
  ASSERT_EQ(j["methods"].size(), 4u);
  for (const nlohmann::json& run : j["methods"]) {
    EXPECT_EQ(run["label"], run["name"]);  // one rule: the preset's name
    if (run["name"] == "wboit") continue;
    EXPECT_EQ(run["compositing"], "kbuffer") << run["name"];
    EXPECT_FALSE(run["bytes_by_category"].contains("tail")) << run["name"];
  }
}

// One line on stderr naming `needle`, exit code 1, nothing written (render: the image; compare:
// the folder).
void expectRefused(const std::string& args, const std::string& needle) {
  const fs::path image = tempDir() / (args.starts_with("render") ? "never.png" : "never");
  fs::remove_all(image);
  const test::CliRun r = test::runCli(args + " -o " + image.string(), tempDir());
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
  EXPECT_FALSE(fs::exists(image)) << args;
}

TEST(CliDefaults, OptionsThatWouldBeIgnoredAreErrors) {
  const std::string render = "render " + kScene + " --budget 400KB";
  for (const char* method : {"vkb", "vkb-fill", "dkb", "dkb-fill", "optimal", "abuffer"})
    expectRefused(render + " --method " + method + " --k 4", "--k: does not apply to");
  expectRefused(render + " --method fkb --occupancy-d 2", "--occupancy-d: does not apply to fkb");
  expectRefused(render + " --method kplus-heap --noise 0.2", "--noise: does not apply");
  expectRefused(render + " --method dkb --periphery-d 2", "--periphery-d: does not apply");
  expectRefused(render + " --method fkb --no-fresnel-term", "--no-fresnel-term: does not apply");
  expectRefused(render + " --method kplus-sb --importance-map m.png", "--importance-map");
  expectRefused(render + " --method vkb --model x.mfrnn", "--model: does not apply to vkb");
  expectRefused(render + " --method fkb --view 0 --camera 0,0,5,0,0,0", "--view and --camera");
  expectRefused("compare " + kScene + " --budget 400KB --methods fkb,vkb --model x.mfrnn",
                "--model: none of the methods uses it");
}

TEST(CliDefaults, OptionsThatApplyAreHonoured) {
  // --k on the presets the table allows changes the recorded k
  for (const char* method : {"fkb", "kplus-heap", "kplus-sb", "kplus-dynamic"}) {
    const nlohmann::json s = renderStats(std::string("--method ") + method + " --k 2");
    EXPECT_EQ(s["k"], 2) << method;
  }
  // --occupancy-d with +occupancy: 12 + 4d bytes per pixel
  const nlohmann::json d3 = renderStats("--method fkb+occupancy --budget 400KB --occupancy-d 3");
  EXPECT_EQ(d3["bytes_by_category"]["occupancy"], (12 + 4 * 3) * kPixels);
}

TEST(CliDefaults, HelpListsTheTablesPresetsForEachOption) {
  const test::CliRun r = test::runCli("render --help", tempDir());
  ASSERT_EQ(r.exitCode, 0);
  std::string help = r.out;
  help.erase(std::remove(help.begin(), help.end(), '\n'), help.end());
  std::string squeezed;  // CLI11 wraps and indents: compare with runs of spaces folded
  for (char c : help)
    if (!(c == ' ' && !squeezed.empty() && squeezed.back() == ' ')) squeezed += c;
  for (MethodOption option : {MethodOption::K, MethodOption::OccupancyD, MethodOption::Model})
    EXPECT_NE(squeezed.find("applies to: " + presetsAccepting(option)), std::string::npos)
        << methodOptionRule(option).flags << "\n"
        << squeezed;
  EXPECT_EQ(presetsAccepting(MethodOption::K),
            "zbuffer, fkb, kplus-array, kplus-heap, kplus-sb, kplus-dynamic, mlab");
  EXPECT_EQ(presetsAccepting(MethodOption::Model), "dkb, dkb-fill, dkb-curve");
  for (const std::string& preset : presetNames())
    EXPECT_NE(squeezed.find(preset), std::string::npos) << preset;
}

// --engine's help states the command's own default, the one that runs: cpu for render, compare and
// info, gl for view (its help said cpu while it, docs/VIEWER.md and its panel used gl).
TEST(CliDefaults, EngineHelpStatesEachCommandsOwnDefault) {
  const auto engineHelp = [](const std::string& command) {
    const test::CliRun r = test::runCli(command + " --help", tempDir());
    EXPECT_EQ(r.exitCode, 0) << command << "\n" << r.err;
    std::string squeezed;
    for (char c : r.out) {
      if (c == '\n') c = ' ';
      if (!(c == ' ' && !squeezed.empty() && squeezed.back() == ' ')) squeezed += c;
    }
    const size_t at = squeezed.find("Engine that renders: ");
    if (at == std::string::npos) return std::string("(no --engine)");
    return squeezed.substr(at, squeezed.find(')', at) + 1 - at);
  };
  for (const char* command : {"render", "compare", "info"})
    EXPECT_TRUE(engineHelp(command).ends_with(" (default cpu)")) << engineHelp(command);
  EXPECT_EQ(renderStats("--method fkb --budget 400KB")["engine"], "cpu");
  // mfr view exists where the GL engine and the viewer are built
  if (test::runCli("--help", tempDir()).out.find(" view ") != std::string::npos) {
    EXPECT_TRUE(engineHelp("view").ends_with(" (default gl)")) << engineHelp("view");
  }
}

}  // namespace
}  // namespace mfr
