// "Did you mean": a mistyped method, engine or command gets one line naming the bad name and the
// closest known name(s) by edit distance, only when they are close (at most 2 edits, and at most a
// third of the name's length).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "mfr/core/suggest.hpp"
#include "mfr/engine/engine.hpp"
#include "mfr/method/method.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

fs::path tempDir() {
  static const fs::path dir = test::processTempDir("mfr_did_you_mean");
  return dir;
}

TEST(DidYouMean, EditDistanceCountsSwapsOfNeighboursAsOne) {
  EXPECT_EQ(editDistance("", ""), 0u);
  EXPECT_EQ(editDistance("abc", ""), 3u);
  EXPECT_EQ(editDistance("", "abc"), 3u);
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);  // 2 replacements, 1 insertion
  EXPECT_EQ(editDistance("kplsu", "kplus"), 1u);     // one swap
  EXPECT_EQ(editDistance("kplus-arary", "kplus-array"), 1u);
  EXPECT_EQ(editDistance("fkb", "fkb"), 0u);
  EXPECT_EQ(editDistance("fkb", "dkb-fill"), 6u);
}

TEST(DidYouMean, ClosestNamesOnlyWhenCloseEnoughToBeATypo) {
  const std::vector<std::string> known = presetNames();
  using Names = std::vector<std::string>;
  EXPECT_EQ(closestNames("kplus-arary", known), Names{"kplus-array"});
  EXPECT_EQ(closestNames("kplsu-heap", known), Names{"kplus-heap"});
  EXPECT_EQ(closestNames("dkb-cruve", known), Names{"dkb-curve"});
  EXPECT_EQ(closestNames("FKB", known), Names{"fkb"});  // compared in lower case
  // every name at the smallest distance, in the known order
  EXPECT_EQ(closestNames("xkb", known), (Names{"fkb", "vkb", "dkb"}));
  // too far: 2 edits in a 3-letter word, 3 in a long one, or nothing alike
  EXPECT_TRUE(closestNames("xyb", known).empty());
  EXPECT_TRUE(closestNames("kplus-xxxxx", known).empty());
  EXPECT_TRUE(closestNames("teapot", known).empty());
  EXPECT_TRUE(closestNames("", known).empty());
  EXPECT_TRUE(closestNames("fkb", known).empty());  // a known name is not a typo
  EXPECT_EQ(didYouMean("kplus-arary", known), "did you mean 'kplus-array'?");
  EXPECT_EQ(didYouMean("xkb", known), "did you mean 'fkb', 'vkb' or 'dkb'?");
  EXPECT_EQ(didYouMean("cpy", {"cpu", "gl"}), "did you mean 'cpu'?");
  EXPECT_EQ(didYouMean("teapot", known), "");
}

TEST(DidYouMean, UnknownMethodNamesTheClosestPreset) {
  const auto message = [](const std::string& name) { return methodPreset(name).error().message; };
  EXPECT_EQ(message("kplus-arary")
                .rfind("method 'kplus-arary': unknown; did you mean "
                       "'kplus-array'? (known: zbuffer, abuffer, fkb",
                       0),
            0u)
      << message("kplus-arary");
  // with the suffix: the suffixed names that run
  EXPECT_NE(message("kplus-arary+occupancy").find("did you mean 'kplus-array+occupancy'?"),
            std::string::npos);
  EXPECT_NE(message("fkb+ocupancy").find("did you mean 'fkb+occupancy'?"), std::string::npos);
  // nothing close: the list alone, as before
  EXPECT_EQ(message("teapot").rfind("method 'teapot': unknown (known: zbuffer, ", 0), 0u)
      << message("teapot");
  EXPECT_EQ(message("teapot").find("did you mean"), std::string::npos);
}

TEST(DidYouMean, UnknownEngineNamesTheClosest) {
  auto engine = makeEngine("cpy", EngineOptions{});
  ASSERT_FALSE(engine.ok());
  EXPECT_EQ(engine.error().message.rfind("--engine 'cpy': unknown engine; did you mean 'cpu'? "
                                         "(known: cpu",
                                         0),
            0u)
      << engine.error().message;
}

// one "mfr: error: ..." line with every needle, exit `code`
void expectOneLine(const std::string& args, int code, const std::vector<std::string>& needles) {
  const test::CliRun r = test::runCli(args, tempDir());
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, code) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("mfr: error: ", 0), 0u) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  for (const std::string& needle : needles)
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << needle << "\n" << r.err;
}

TEST(DidYouMean, CommandLineTyposGetOneLineWithTheClosestName) {
  const std::string scene = "procedural:layers --width 16 --height 16 -q ";
  const std::string out = (tempDir() / "never").string();
  expectOneLine("render " + scene + "--method kplus-arary -o " + out + ".png", 1,
                {"method 'kplus-arary': unknown; did you mean 'kplus-array'?"});
  expectOneLine("compare " + scene + "--methods fkb,kplsu-heap --budget 64KB --out " + out, 1,
                {"--methods: method 'kplsu-heap': unknown; did you mean 'kplus-heap'?"});
  expectOneLine("render " + scene + "--engine cpy -o " + out + ".png", 1,
                {"--engine 'cpy': unknown engine; did you mean 'cpu'?"});
  // an unknown command: a syntax error (exit 2), with the closest command
  expectOneLine("rendr " + scene, 2,
                {"unknown command 'rendr'; did you mean 'render'? (commands: render, "});
  expectOneLine("comapre " + scene, 2, {"unknown command 'comapre'; did you mean 'compare'?"});
  expectOneLine("frobnicate " + scene, 2, {"unknown command 'frobnicate' (commands: "});
  EXPECT_FALSE(fs::exists(out + ".png"));
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace mfr
