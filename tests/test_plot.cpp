// Line and bar chart renderers: image size, where the series' pixels land, legend, and the rejected
// inputs.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "mfr/core/plot.hpp"

namespace {

using mfr::BarSeries;
using mfr::Image8;
using mfr::PlotOptions;
using mfr::PlotSeries;

const glm::vec3 kRed(0.9f, 0.1f, 0.1f), kBlue(0.1f, 0.3f, 0.9f);

// (x, y) of every pixel whose colour is exactly `c` (encoded as the renderer does).
std::vector<std::pair<int, int>> pixelsOf(const Image8& img, glm::vec3 c) {
  const auto code = [](float v) { return static_cast<uint8_t>(v * 255.0f + 0.5f); };
  std::vector<std::pair<int, int>> out;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = &img.rgba[(static_cast<size_t>(y) * img.width + x) * 4];
      if (p[0] == code(c.r) && p[1] == code(c.g) && p[2] == code(c.b)) out.push_back({x, y});
    }
  return out;
}

PlotSeries line(std::vector<double> y, glm::vec3 color, std::string label = "") {
  PlotSeries s{std::move(label), {}, std::move(y), color};
  for (size_t i = 0; i < s.y.size(); ++i) s.x.push_back(static_cast<double>(i));
  return s;
}

TEST(Plot, ImageHasTheRequestedSize) {
  PlotOptions o;
  o.width = 640;
  o.height = 360;
  o.title = "loss";
  auto img = mfr::plotLines({line({3, 2, 1.5, 1.2}, kRed, "train")}, o);
  ASSERT_TRUE(img.ok()) << img.error().message;
  EXPECT_EQ(img->width, 640);
  EXPECT_EQ(img->height, 360);
  EXPECT_EQ(img->rgba.size(), 640u * 360u * 4u);
}

TEST(Plot, ConstantSeriesIsAHorizontalLineAcrossThePlot) {
  auto img = mfr::plotLines({line(std::vector<double>(10, 0.5), kRed)}, PlotOptions{});
  ASSERT_TRUE(img.ok()) << img.error().message;
  const auto px = pixelsOf(*img, kRed);
  ASSERT_FALSE(px.empty());
  int x0 = img->width, x1 = -1, y0 = img->height, y1 = -1;
  for (auto [x, y] : px) {
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  EXPECT_GE(x1 - x0, img->width * 7 / 10);  // data spans 9 of the axis' 10 units
  EXPECT_GE(y1 - y0 + 1, 2);                // at least 2 px thick
  EXPECT_LE(y1 - y0 + 1, 5);
  // the range of constant data is centred on it: the line is mid-height (give or take margins)
  EXPECT_GT(y0, img->height * 3 / 10);
  EXPECT_LT(y1, img->height * 7 / 10);
}

TEST(Plot, HigherConstantIsDrawnHigher) {
  auto img = mfr::plotLines({line({1, 1, 1}, kRed), line({0, 0, 0}, kBlue)}, PlotOptions{});
  ASSERT_TRUE(img.ok());
  const auto red = pixelsOf(*img, kRed), blue = pixelsOf(*img, kBlue);
  ASSERT_FALSE(red.empty());
  ASSERT_FALSE(blue.empty());
  EXPECT_LT(red.back().second, blue.front().second);
}

TEST(Plot, TwoSeriesOfDifferentColoursBothAppearAndLabelsAddALegend) {
  const std::vector<double> a{4, 3, 2.5, 2.2}, b{4.5, 3.6, 3.3, 3.4};
  auto plain = mfr::plotLines({line(a, kRed), line(b, kBlue)}, PlotOptions{});
  auto labelled = mfr::plotLines({line(a, kRed, "train"), line(b, kBlue, "validation")}, {});
  ASSERT_TRUE(plain.ok() && labelled.ok());
  EXPECT_GT(pixelsOf(*plain, kRed).size(), 300u);
  EXPECT_GT(pixelsOf(*plain, kBlue).size(), 300u);
  // the legend's swatches add pixels of each colour, its labels dark ones
  EXPECT_GT(pixelsOf(*labelled, kRed).size(), pixelsOf(*plain, kRed).size() + 20);
  EXPECT_GT(pixelsOf(*labelled, kBlue).size(), pixelsOf(*plain, kBlue).size() + 20);
  EXPECT_GT(pixelsOf(*labelled, glm::vec3(0.1f)).size(), pixelsOf(*plain, glm::vec3(0.1f)).size());
}

TEST(Plot, IncreasingDataRisesFromLeftToRight) {
  for (bool logY : {false, true}) {
    PlotOptions o;
    o.logY = logY;
    std::vector<double> y;
    for (int i = 0; i < 20; ++i) y.push_back(std::pow(1.4, i));
    auto img = mfr::plotLines({line(y, kRed)}, o);
    ASSERT_TRUE(img.ok());
    // mean row of the coloured pixels per fifth of the image width
    double sum[5] = {}, count[5] = {};
    for (auto [x, r] : pixelsOf(*img, kRed)) {
      sum[x * 5 / img->width] += r;
      count[x * 5 / img->width] += 1;
    }
    double previous = img->height;
    int bands = 0;
    for (int b = 0; b < 5; ++b) {
      if (count[b] == 0) continue;  // the margins
      EXPECT_LT(sum[b] / count[b], previous) << "logY " << logY << " band " << b;
      previous = sum[b] / count[b];
      ++bands;
    }
    EXPECT_GE(bands, 4) << "logY " << logY << ": the line must cross most of the width";
  }
}

TEST(Plot, GapsAndLonePointsAreDrawnAndRenderingIsDeterministic) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<PlotSeries> s{line({1, 2, nan, 3, 4}, kRed), line({2.5}, kBlue)};
  auto a = mfr::plotLines(s, {}), b = mfr::plotLines(s, {});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->rgba, b->rgba);
  EXPECT_GT(pixelsOf(*a, kBlue).size(), 10u);  // the single point is a dot
  // no red between x = 1 and x = 3 (pixel columns around x = 2 stay free of the line)
  int minX = a->width, maxX = 0;
  for (auto [x, y] : pixelsOf(*a, kRed)) minX = std::min(minX, x), maxX = std::max(maxX, x);
  const double mid = minX + (maxX - minX) * 0.5;  // x = 2 of [0, 4]
  for (auto [x, y] : pixelsOf(*a, kRed)) EXPECT_GT(std::abs(x - mid), (maxX - minX) / 8.0);
}

TEST(PlotErrors, RejectsBadSizesAndData) {
  const auto ok = std::vector<PlotSeries>{line({1, 2}, kRed)};
  for (auto [w, h] : {std::pair{99, 500}, {800, 99}, {8193, 500}, {800, 8193}, {0, 0}}) {
    PlotOptions o;
    o.width = w;
    o.height = h;
    EXPECT_FALSE(mfr::plotLines(ok, o).ok()) << w << "x" << h;
  }
  PlotOptions o;
  o.width = o.height = 100;
  EXPECT_TRUE(mfr::plotLines(ok, o).ok());
  const double nan = std::numeric_limits<double>::quiet_NaN(),
               inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(mfr::plotLines({}, {}).ok());
  EXPECT_FALSE(mfr::plotLines({line({nan, inf, -inf}, kRed)}, {}).ok());
  PlotSeries mismatched = line({1, 2, 3}, kRed);
  mismatched.x.pop_back();
  EXPECT_FALSE(mfr::plotLines({mismatched}, {}).ok());
  PlotOptions log;
  log.logY = true;
  EXPECT_FALSE(mfr::plotLines({line({0, -1, -2}, kRed)}, log).ok());
  EXPECT_TRUE(mfr::plotLines({line({0, -1, 2}, kRed)}, log).ok());  // one positive point: a dot
}

// Grouped bars: per category one bar per series, left to right in the series' order; a taller value
// is a taller bar on a linear and on a log axis; a missing value draws no bar.
TEST(PlotBars, BarsStandSideBySideWithHeightsInTheValuesOrder) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (bool logY : {false, true}) {
    PlotOptions o;
    o.logY = logY;
    o.title = "frame time";
    o.yLabel = "ms";
    const std::vector<BarSeries> bars{{"", {100, 30}, kRed}, {"", {1000, nan}, kBlue}};
    auto img = mfr::plotBars({"layers", "hairball"}, bars, o);
    ASSERT_TRUE(img.ok()) << img.error().message;
    auto again = mfr::plotBars({"layers", "hairball"}, bars, o);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(img->rgba, again->rgba);
    // where each colour is in the image's left and right halves: x range, top row, pixels
    const auto extent = [&](glm::vec3 c, bool right) {
      int x0 = img->width, x1 = -1, top = img->height, count = 0;
      for (auto [x, y] : pixelsOf(*img, c))
        if ((x >= img->width / 2) == right) {
          x0 = std::min(x0, x), x1 = std::max(x1, x), top = std::min(top, y), ++count;
        }
      return std::array<int, 4>{x0, x1, top, count};
    };
    const auto redLeft = extent(kRed, false), blueLeft = extent(kBlue, false);
    const auto redRight = extent(kRed, true), blueRight = extent(kBlue, true);
    ASSERT_GT(redLeft[3], 200) << "logY " << logY;
    ASSERT_GT(blueLeft[3], 200) << "logY " << logY;
    EXPECT_LT(redLeft[1], blueLeft[0]) << "cpu's bar left of gl's";
    EXPECT_LT(blueLeft[2], redLeft[2]) << "1000 stands above 100";
    EXPECT_LT(redLeft[2], redRight[2]) << "100 stands above 30";
    EXPECT_GT(redRight[3], 200);
    EXPECT_EQ(blueRight[3], 0) << "no bar for the missing value";
    // labels add a legend row above the plot: a box of each colour above the unlabelled chart's
    // tallest bar (the plot moves down by the row)
    auto labelled = mfr::plotBars({"layers", "hairball"},
                                  {{"cpu", {100, 30}, kRed}, {"gl", {1000, nan}, kBlue}}, o);
    ASSERT_TRUE(labelled.ok());
    const auto topOf = [](const Image8& image, glm::vec3 c) {
      int top = image.height;
      for (auto [x, y] : pixelsOf(image, c)) top = std::min(top, y);
      return top;
    };
    EXPECT_LT(topOf(*labelled, kRed), topOf(*img, kBlue));
    EXPECT_LT(topOf(*labelled, kBlue), topOf(*img, kBlue));
  }
}

TEST(PlotBarsErrors, RejectsBadCategoriesAndData) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(mfr::plotBars({"a"}, {{"s", {2}, kRed}}, {}).ok());
  EXPECT_FALSE(mfr::plotBars({}, {{"s", {}, kRed}}, {}).ok());
  EXPECT_FALSE(mfr::plotBars({"a", "b"}, {{"s", {1}, kRed}}, {}).ok());
  EXPECT_FALSE(mfr::plotBars({"a"}, {{"s", {nan}, kRed}}, {}).ok());
  PlotOptions log;
  log.logY = true;
  EXPECT_FALSE(mfr::plotBars({"a"}, {{"s", {-1}, kRed}}, log).ok());
  PlotOptions tiny;
  tiny.width = 50;
  EXPECT_FALSE(mfr::plotBars({"a"}, {{"s", {1}, kRed}}, tiny).ok());
}

}  // namespace
