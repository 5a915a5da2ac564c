// The preset table is the one list of methods: names, lookup, the README's table and the CLI help
// all agree with it.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "cli_runner.hpp"
#include "mfr/method/method.hpp"
#include "test_paths.hpp"

namespace mfr {
namespace {

TEST(PresetTable, NamesAreUniqueAndEveryRowResolves) {
  std::set<std::string> names;
  ASSERT_EQ(presetTable().size(), presetNames().size());
  for (size_t i = 0; i < presetTable().size(); ++i) {
    const PresetInfo& p = presetTable()[i];
    EXPECT_EQ(p.name, presetNames()[i]);
    EXPECT_TRUE(names.insert(p.name).second) << p.name;
    EXPECT_FALSE(p.paper.empty()) << p.name;
    EXPECT_FALSE(p.summary.empty()) << p.name;
    auto m = methodPreset(p.name);
    ASSERT_TRUE(m.ok()) << p.name;
    EXPECT_EQ(m->name, p.name);
  }
  EXPECT_FALSE(methodPreset("no-such-preset").ok());
}

TEST(PresetTable, TheReadmeCopyIsTheGeneratedTable) {
  std::ifstream in(std::string(MFR_SOURCE_DIR) + "/README.md");
  ASSERT_TRUE(in) << "README.md not found under " << MFR_SOURCE_DIR;
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string readme = buffer.str();
  const std::string begin = "<!-- presets:begin -->\n", end = "<!-- presets:end -->";
  const size_t b = readme.find(begin), e = readme.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  EXPECT_EQ(readme.substr(b + begin.size(), e - b - begin.size()), presetTableMarkdown())
      << "regenerate README's table with `mfr presets --format markdown`";
}

TEST(PresetTable, RenderHelpAndPresetsCommandListEveryPreset) {
  const auto scratch = test::processTempDir("preset_table");
  const test::CliRun help = test::runCli("render --help", scratch);
  const test::CliRun list = test::runCli("presets --format json", scratch);
  ASSERT_EQ(list.exitCode, 0) << list.err;
  for (const PresetInfo& p : presetTable()) {
    EXPECT_NE(help.out.find(p.name + ": " + p.summary), std::string::npos) << p.name;
    EXPECT_NE(list.out.find("\"name\": \"" + p.name + "\""), std::string::npos) << p.name;
  }
}

}  // namespace
}  // namespace mfr
