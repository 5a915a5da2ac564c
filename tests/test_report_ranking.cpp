// What the comparison report concludes (mfr/compare/report_ranking.hpp), on hand-made results
// whose answers are known: the ranking by FLIP with ties broken by time, the winner's margin,
// Pareto front membership, the log-axis choice with its floor for zeros, the worst window of a
// FLIP map with a known hot spot, FLIP values read back from the magma image, and the methods
// whose memory the budget does not move; then the same conclusions on the report page.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "mfr/compare/compare.hpp"
#include "mfr/compare/report_ranking.hpp"
#include "mfr/metrics/flip.hpp"

namespace mfr {
namespace {

CompareRun run(const std::string& method, double flip, double ms, uint64_t bytes = 1000) {
  CompareRun r;
  r.method = r.label = method;
  r.budgetBytes = 1u << 20;
  r.metrics.flipMean = flip;
  r.metrics.mseLinear = flip * flip;
  r.stats.passes = {{"capture", ms}};
  r.stats.bytesUsed = bytes;
  return r;
}

CompareRun failed(const std::string& method) {
  CompareRun r;
  r.method = r.label = method;
  r.error = "budget too small for " + method;
  return r;
}

TEST(ReportRanking, RanksByFlipThenTimeWithoutFailedRuns) {
  CompareBudget cb;
  cb.runs = {run("a", 0.2, 10), run("b", 0.1, 50), run("c", 0.1, 20), failed("d"),
             run("e", 0.0, 100)};
  // e has the least error; b and c tie on FLIP and c is faster; d failed
  EXPECT_EQ(rankRuns(cb), (std::vector<size_t>{4, 2, 1, 0}));
  cb.runs[2].stats.passes = {{"capture", 60}};  // now b is faster
  EXPECT_EQ(rankRuns(cb), (std::vector<size_t>{4, 1, 2, 0}));
}

TEST(ReportRanking, WinnerMarginOverTheRunnerUp) {
  CompareBudget cb;
  cb.runs = {run("slow-exact", 0.0, 100), run("fast", 0.04, 20), run("worst", 0.3, 1)};
  Recommendation r = recommend(cb);
  ASSERT_TRUE(r.winner && r.runnerUp);
  EXPECT_EQ(*r.winner, 0u);
  EXPECT_EQ(*r.runnerUp, 1u);
  EXPECT_DOUBLE_EQ(r.flipMargin, 0.04);
  EXPECT_DOUBLE_EQ(r.relativeMargin, 1.0);  // 100 % below the runner-up
  EXPECT_DOUBLE_EQ(r.timeMarginMs, -80.0);  // the winner is 80 ms slower

  cb.runs = {run("x", 0.05, 30), run("y", 0.05, 10), run("z", 0.08, 5)};
  r = recommend(cb);
  ASSERT_TRUE(r.winner && r.runnerUp);
  EXPECT_EQ(*r.winner, 1u);  // a tie on FLIP: the faster
  EXPECT_EQ(*r.runnerUp, 0u);
  EXPECT_EQ(r.flipMargin, 0.0);
  EXPECT_DOUBLE_EQ(r.timeMarginMs, 20.0);

  cb.runs = {failed("p"), run("q", 0.5, 3)};
  r = recommend(cb);
  ASSERT_TRUE(r.winner);
  EXPECT_EQ(*r.winner, 1u);
  EXPECT_FALSE(r.runnerUp);
  cb.runs = {failed("p")};
  EXPECT_FALSE(recommend(cb).winner);
}

TEST(ReportRanking, ParetoFrontOfKnownPoints) {
  const std::vector<FrontPoint> points = {
      {0.1, 10},   // front
      {0.05, 20},  // front
      {0.05, 30},  // dominated by the one above (same error, more cost)
      {0.2, 5},    // front: the cheapest
      {0.2, 15},   // dominated by {0.1, 10}
      {0.0, 40},   // front: exact
      {0.0, 40},   // its twin: equal points do not dominate each other
      {0.3, 50},   // dominated by everything
  };
  EXPECT_EQ(paretoFront(points),
            (std::vector<bool>{true, true, false, true, false, true, true, false}));
  EXPECT_TRUE(paretoFront({}).empty());
  EXPECT_EQ(paretoFront({{1.0, 1.0}}), std::vector<bool>{true});
}

TEST(ReportRanking, LogAxisWhereTheValuesSpanADecade) {
  AxisScale s = chooseAxisScale({0.0, 3e-4, 0.05});
  EXPECT_TRUE(s.log);
  EXPECT_DOUBLE_EQ(s.floor, 1e-5);    // the decade below 3e-4's
  s = chooseAxisScale({1e-3, 1e-2});  // exactly one decade
  EXPECT_TRUE(s.log);
  EXPECT_DOUBLE_EQ(s.floor, 1e-4);
  s = chooseAxisScale({0.02, 0.1, 0.19});  // under a decade
  EXPECT_FALSE(s.log);
  EXPECT_EQ(s.floor, 0.0);
  EXPECT_FALSE(chooseAxisScale({0.0, 0.0, 0.5}).log);  // one positive value
  EXPECT_FALSE(chooseAxisScale({}).log);
  s = chooseAxisScale({NAN, INFINITY, 2.0, 400.0});  // non-finite values ignored
  EXPECT_TRUE(s.log);
  EXPECT_DOUBLE_EQ(s.floor, 0.1);
}

TEST(ReportRanking, WorstWindowFindsTheHotSpot) {
  const int w = 100, h = 80;
  std::vector<float> map(static_cast<size_t>(w) * h, 0.05f);
  // a 10x10 hot spot at (70, 20) and a wider, cooler patch elsewhere
  for (int y = 20; y < 30; ++y)
    for (int x = 70; x < 80; ++x) map[static_cast<size_t>(y) * w + x] = 1.0f;
  for (int y = 50; y < 80; ++y)
    for (int x = 0; x < 30; ++x) map[static_cast<size_t>(y) * w + x] = 0.3f;
  const ImageWindow win = worstWindow(map, w, h, 16);
  // windows holding the whole spot start at x 64..70, y 14..20: the topmost, leftmost
  EXPECT_EQ(win.x, 64);
  EXPECT_EQ(win.y, 14);
  EXPECT_EQ(win.size, 16);
  EXPECT_NEAR(win.mean, (100 * 1.0 + 156 * 0.05) / 256.0, 1e-6);
  // a window larger than the image is clamped to it
  const ImageWindow all = worstWindow(map, w, h, 500);
  EXPECT_EQ(all.size, 80);
  EXPECT_EQ(worstWindow({}, 0, 0, 16).size, 0);
  EXPECT_EQ(worstWindowSize(256, 256), 64);
  EXPECT_EQ(worstWindowSize(96, 96), 48);
  EXPECT_EQ(worstWindowSize(24, 20), 10);
  EXPECT_EQ(worstWindowSize(4, 6), 4);
}

TEST(ReportRanking, FlipValuesReadBackFromTheMagmaImage) {
  FlipResult f;
  f.width = 5;
  f.height = 1;
  f.errorMap = {0.0f, 0.25f, 0.5f, 0.999f, 1.0f};
  const std::vector<float> back = flipValuesOfImage(flipErrorImage(f));
  ASSERT_EQ(back.size(), f.errorMap.size());
  for (size_t i = 0; i < back.size(); ++i)
    EXPECT_NEAR(back[i], f.errorMap[i], 0.5 / 255.0 + 1e-6) << i;
}

CompareResult handMade() {
  CompareResult r;
  r.scene = "hand-made";
  r.width = r.height = 10;
  r.groundTruth = run("abuffer", 0.0, 5, 5000);
  CompareBudget small, large;
  small.budgetBytes = 1000;
  small.label = "1000B";
  large.budgetBytes = 4000;
  large.label = "4000B";
  small.runs = {run("fkb", 0.20, 10, 900), run("wboit", 0.10, 8, 700), failed("mboit"),
                run("vkb", 0.15, 30, 950)};
  large.runs = {run("fkb", 0.01, 12, 3900), run("wboit", 0.10, 8, 700), run("mboit", 0.05, 9, 800),
                run("vkb", 0.01, 35, 3950)};
  r.budgets = {small, large};
  return r;
}

TEST(ReportRanking, FixedMemoryMethodsFromTheirBytes) {
  CompareResult r = handMade();
  // wboit: 700 B at both; mboit ran once only; fkb and vkb follow the budget
  EXPECT_EQ(fixedMemoryMethods(r), std::vector<std::string>{"wboit"});
  r.budgets[0].runs[2] = run("mboit", 0.05, 9, 800);
  EXPECT_EQ(fixedMemoryMethods(r), (std::vector<std::string>{"wboit", "mboit"}));
  // an exact k-buffer that used the same bytes at both budgets: its node pool (F(M)) grew with
  // the budget, so the budget does move it
  CompareRun exactSmall = run("kplus-dynamic", 0.0, 5, 500), exactLarge = exactSmall;
  exactSmall.budgetSlots = 100;
  exactLarge.budgetSlots = 400;
  r.budgets[0].runs.push_back(exactSmall);
  r.budgets[1].runs.push_back(exactLarge);
  EXPECT_EQ(fixedMemoryMethods(r), (std::vector<std::string>{"wboit", "mboit"}));
  r.budgets.pop_back();  // one budget: nothing to say
  EXPECT_TRUE(fixedMemoryMethods(r).empty());
}

size_t count(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

// the section between `from` and the next <h2>
std::string section(const std::string& html, const std::string& from) {
  const size_t a = html.find(from);
  if (a == std::string::npos) return {};
  const size_t b = html.find("<h2", a + 1);
  return html.substr(a, b == std::string::npos ? std::string::npos : b - a);
}

TEST(ReportRanking, ThePageNamesTheWinnersTheFrontsAndTheFixedMethods) {
  const std::string html = compareReportHtml(handMade(), ReportInfo{});
  const std::string rec = section(html, "id=\"recommendation\"");
  ASSERT_FALSE(rec.empty());
  // 1000B: wboit 0.10 beats vkb 0.15 by 0.05 (33 %), and is 22 ms faster
  EXPECT_NE(rec.find("<strong class=\"winner\">wboit</strong> wins with FLIP 0.1000, 0.0500 below "
                     "the runner-up vkb (0.1500; 33&#8201;% lower), and is faster by "
                     "22.0&#8201;ms"),
            std::string::npos)
      << rec.substr(0, 2000);
  // 4000B: fkb and vkb tie on 0.01; fkb is 23 ms faster
  EXPECT_NE(rec.find("<strong class=\"winner\">fkb</strong> and vkb tie on FLIP (0.0100); fkb is "
                     "faster by 23.0&#8201;ms"),
            std::string::npos);
  EXPECT_NE(rec.find("id=\"fixed-memory\""), std::string::npos);
  EXPECT_NE(rec.find("<li><code>wboit</code>: 700 B"), std::string::npos) << rec;
  // bytes front (FLIP, bytes): wboit 700 (0.10, twice), mboit 800 (0.05), fkb 3900 (0.01);
  // time front (FLIP, ms): wboit 8 (twice), mboit 9, fkb 12: four ringed points in each plot
  const size_t bytesPlot = rec.find("aria-label=\"Mean FLIP vs bytes per pixel\"");
  const size_t timePlot = rec.find("aria-label=\"Mean FLIP vs time\"");
  ASSERT_NE(bytesPlot, std::string::npos);
  ASSERT_NE(timePlot, std::string::npos);
  EXPECT_EQ(count(rec.substr(bytesPlot, timePlot - bytesPlot), "class=\"point front\""), 4u);
  EXPECT_EQ(
      count(rec.substr(timePlot, rec.find("</svg>", timePlot) - timePlot), "class=\"point front\""),
      4u);
  // the rankings: wboit first at 1000B, mboit failed last
  const size_t ranking = rec.find("Ranking at M = ");
  ASSERT_NE(ranking, std::string::npos);
  const std::string first = rec.substr(ranking, rec.find("</table>", ranking) - ranking);
  EXPECT_LT(first.find("<code>wboit</code>"), first.find("<code>vkb</code>"));
  EXPECT_LT(first.find("<code>vkb</code>"), first.find("<code>fkb</code>"));
  EXPECT_LT(first.find("<code>fkb</code>"), first.find("failed: budget too small for mboit"));
  // sortable tables, and the script that sorts them
  EXPECT_EQ(count(html, "data-sortable>"), 4u);  // two rankings, two results tables
  EXPECT_NE(html.find("<script>"), std::string::npos);
}

}  // namespace
}  // namespace mfr
