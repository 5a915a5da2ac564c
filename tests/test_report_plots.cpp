// The error-vs-budget plots of report.html read back against results.json: a small comparison
// with three budgets runs through the library, the inline SVG of each plot (mean FLIP, MSE,
// fragments lost) is parsed, and every plotted point is checked three ways against
// compareToJson's value for its method and budget:
//   - its exact value (the point's data-x / data-y attributes) equals the JSON number;
//   - its drawn position (the marker's centre), mapped back through the plot's axes (the frame's
//     data-x-* / data-y-* ranges, linear or log), equals the JSON value up to the 0.1 px rounding
//     of the SVG coordinates;
//   - the series' line passes through the markers, in budget order.
// Runs that failed (budget too small) must have no point; nothing else may be plotted. Error axes
// (FLIP, MSE) are log where their positive values span a decade, and then a zero error is drawn
// at the axis' floor (data-y-floor, the line marked "0 exact"); the fragments lost are linear.
// Two scenarios cover the axis mappings: budgets 4x apart (log x) with failed runs and zero
// errors (log MSE with its floor), and budgets 2x apart (linear x) whose MSE spans > 20x (log y,
// no zeros).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/compare/compare.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {
namespace {

// 200 strands at 64x64: ~14k fragments; the exact A-buffer needs ~142 KiB, kplus-dynamic and vkb
// need ~67 KiB for one fragment per covered pixel, fkb 48 KiB.
const char* kScene = "procedural:hairball?strands=200";
constexpr int kSize = 64;

// ---- a minimal SVG tag reader --------------------------------------------------------------

struct Tag {
  std::string name;  // "g", "/g", "circle", ...
  std::map<std::string, std::string> attrs;
};

// The tags of one SVG element (text between tags ignored). Attribute values are quoted with '"'
// (the report escapes '"' inside values).
std::vector<Tag> tagsOf(const std::string& svg) {
  std::vector<Tag> tags;
  for (size_t p = svg.find('<'); p != std::string::npos; p = svg.find('<', p + 1)) {
    const size_t end = svg.find('>', p);
    if (end == std::string::npos) break;
    const std::string body = svg.substr(p + 1, end - p - 1);
    Tag t;
    size_t i = 0;
    while (i < body.size() && !std::isspace(static_cast<unsigned char>(body[i])) && body[i] != '/')
      ++i;
    if (i == 0 && !body.empty() && body[0] == '/') {  // closing tag
      t.name = body;
    } else {
      t.name = body.substr(0, i);
    }
    while (i < body.size()) {
      const size_t eq = body.find("=\"", i);
      if (eq == std::string::npos) break;
      size_t nameStart = eq;
      while (nameStart > 0 && !std::isspace(static_cast<unsigned char>(body[nameStart - 1])))
        --nameStart;
      const size_t close = body.find('"', eq + 2);
      if (close == std::string::npos) break;
      t.attrs[body.substr(nameStart, eq - nameStart)] = body.substr(eq + 2, close - eq - 2);
      i = close + 1;
    }
    tags.push_back(std::move(t));
    p = end;
  }
  return tags;
}

double number(const std::map<std::string, std::string>& attrs, const std::string& key) {
  const auto it = attrs.find(key);
  if (it == attrs.end()) {
    ADD_FAILURE() << "missing attribute " << key;
    return NAN;
  }
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  EXPECT_EQ(*end, '\0') << key << "=\"" << it->second << "\"";
  return v;
}

// Numbers of an SVG path "M x y L x y ..." or a polygon's "x,y x,y ...".
std::vector<double> numbersIn(const std::string& s) {
  std::vector<double> out;
  const char* p = s.c_str();
  while (*p) {
    if (std::isdigit(static_cast<unsigned char>(*p)) || *p == '-' || *p == '.') {
      char* end = nullptr;
      out.push_back(std::strtod(p, &end));
      p = end;
    } else {
      ++p;
    }
  }
  return out;
}

struct Axis {
  bool log = false;
  double lo = 0, hi = 1;
  double floor = 0;       // log error axes: where 0 is drawn (data-y-floor)
  double p0 = 0, p1 = 1;  // pixel positions of lo and hi
  // A pixel position back to a value.
  double value(double pixel) const {
    const double t = (pixel - p0) / (p1 - p0);
    if (log) return std::pow(10.0, std::log10(lo) + t * (std::log10(hi) - std::log10(lo)));
    return lo + t * (hi - lo);
  }
  // |read-back - expected| allowed for a drawn position off by `pixels`: in value units (linear)
  // or as a difference of log10 (log).
  bool agrees(double readBack, double expected, double pixels) const {
    const double span = std::fabs(p1 - p0);
    if (log) {
      return expected > 0 && readBack > 0 &&
             std::fabs(std::log10(readBack) - std::log10(expected)) <=
                 pixels * (std::log10(hi) - std::log10(lo)) / span;
    }
    return std::fabs(readBack - expected) <= pixels * (hi - lo) / span + 1e-12;
  }
};

struct PlotPoint {
  double dataX = NAN, dataY = NAN;  // exact values
  double px = NAN, py = NAN;        // marker centre as drawn
};

struct PlotSeries {
  std::string name;
  std::vector<std::pair<double, double>> line;  // the path's vertices
  std::vector<PlotPoint> points;
};

struct Plot {
  Axis x, y;
  bool haveFrame = false;
  std::vector<PlotSeries> series;
};

// Centre of a marker as report_html.cpp's markerSvg draws it (circle, square, triangle, diamond,
// cross).
bool markerCentre(const Tag& t, double& cx, double& cy) {
  if (t.name == "circle") {
    cx = number(t.attrs, "cx");
    cy = number(t.attrs, "cy");
    return true;
  }
  if (t.name == "rect") {  // 8x8 square
    cx = number(t.attrs, "x") + 4.0;
    cy = number(t.attrs, "y") + 4.0;
    return true;
  }
  if (t.name == "polygon") {  // apex first: triangle 5 above the centre, diamond 5.5
    const std::vector<double> v = numbersIn(t.attrs.at("points"));
    if (v.size() != 6 && v.size() != 8) return false;
    cx = v[0];
    cy = v[1] + (v.size() == 6 ? 5.0 : 5.5);
    return true;
  }
  if (t.name == "path") {  // cross from (x - 4, y - 4)
    const std::vector<double> v = numbersIn(t.attrs.at("d"));
    if (v.size() < 2) return false;
    cx = v[0] + 4.0;
    cy = v[1] + 4.0;
    return true;
  }
  return false;
}

Plot parsePlot(const std::string& svg) {
  Plot plot;
  std::vector<std::string> open;  // classes of the open <g> elements
  bool pointHasMarker = false;
  for (const Tag& t : tagsOf(svg)) {
    const auto cls = t.attrs.find("class");
    if (t.name == "g") {
      const std::string c = cls == t.attrs.end() ? std::string() : cls->second;
      open.push_back(c);
      if (c == "series") {
        plot.series.emplace_back();
        plot.series.back().name = t.attrs.count("data-series") ? t.attrs.at("data-series") : "";
      } else if (c == "point") {
        EXPECT_FALSE(plot.series.empty()) << "point outside a series";
        if (plot.series.empty()) plot.series.emplace_back();
        PlotPoint p;
        p.dataX = number(t.attrs, "data-x");
        p.dataY = number(t.attrs, "data-y");
        plot.series.back().points.push_back(p);
        pointHasMarker = false;
      }
      continue;
    }
    if (t.name == "/g") {
      EXPECT_FALSE(open.empty()) << "unbalanced </g>";
      if (!open.empty()) {
        if (open.back() == "point") {
          EXPECT_TRUE(pointHasMarker) << "point without a marker";
        }
        open.pop_back();
      }
      continue;
    }
    const bool inPoint = !open.empty() && open.back() == "point";
    const bool inSeries = !open.empty() && open.back() == "series";
    if (t.name == "rect" && t.attrs.count("data-x-scale")) {
      EXPECT_FALSE(plot.haveFrame) << "two frames";
      plot.haveFrame = true;
      const double fx = number(t.attrs, "x"), fy = number(t.attrs, "y");
      const double fw = number(t.attrs, "width"), fh = number(t.attrs, "height");
      plot.x.log = t.attrs.at("data-x-scale") == "log";
      plot.x.lo = number(t.attrs, "data-x-lo");
      plot.x.hi = number(t.attrs, "data-x-hi");
      plot.x.p0 = fx;
      plot.x.p1 = fx + fw;
      plot.y.log = t.attrs.at("data-y-scale") == "log";
      plot.y.lo = number(t.attrs, "data-y-lo");
      plot.y.hi = number(t.attrs, "data-y-hi");
      if (t.attrs.count("data-y-floor")) plot.y.floor = number(t.attrs, "data-y-floor");
      plot.y.p0 = fy + fh;  // lo at the bottom
      plot.y.p1 = fy;
    } else if (inPoint) {
      double cx = 0, cy = 0;
      EXPECT_TRUE(markerCentre(t, cx, cy)) << "unexpected element <" << t.name << "> in a point";
      EXPECT_FALSE(pointHasMarker) << "two markers in one point";
      pointHasMarker = true;
      plot.series.back().points.back().px = cx;
      plot.series.back().points.back().py = cy;
    } else if (inSeries && t.name == "path") {
      EXPECT_TRUE(plot.series.back().line.empty()) << "two lines in one series";
      const std::vector<double> v = numbersIn(t.attrs.at("d"));
      EXPECT_EQ(v.size() % 2, 0u);
      for (size_t i = 0; i + 1 < v.size(); i += 2)
        plot.series.back().line.emplace_back(v[i], v[i + 1]);
    }
  }
  EXPECT_TRUE(open.empty()) << "unclosed <g>";
  return plot;
}

// The <svg> element whose aria-label is `title`.
std::string svgWithTitle(const std::string& html, const std::string& title) {
  const size_t label = html.find("aria-label=\"" + title + "\"");
  if (label == std::string::npos) return {};
  const size_t start = html.rfind("<svg", label);
  const size_t end = html.find("</svg>", label);
  if (start == std::string::npos || end == std::string::npos) return {};
  return html.substr(start, end + 6 - start);
}

// ---- the scenarios ---------------------------------------------------------------------------

struct Scenario {
  const char* name;
  std::vector<std::string> methods;
  std::vector<uint64_t> budgets;
  bool failures;  // some runs fail (budget too small): they must have no point
  // the axis mappings this scenario is meant to exercise (the report's choice, checked so that a
  // change of its heuristics cannot silently leave a mapping untested)
  bool logBudgets;  // x of every plot
  bool logMse;      // y of the MSE plot (the fragments-lost plot is always linear)
  bool zeroMse;     // some MSE is 0: drawn at the floor of the log axis
};

const std::vector<Scenario>& scenarios() {
  static const std::vector<Scenario> s = {
      // 64 KiB: only fkb fits; 128 KiB: all but the A-buffer; 256 KiB: all (kplus-dynamic and the
      // A-buffer exact, errors 0). Given out of order: the plot sorts budgets.
      {"LogBudgetsWithFailures",
       {"fkb", "kplus-dynamic", "vkb", "abuffer"},
       {128u << 10, 64u << 10, 256u << 10},
       /*failures=*/true,
       /*logBudgets=*/true,
       /*logMse=*/true,
       /*zeroMse=*/true},
      // all three methods fit everywhere; MSE from ~7e-2 down to ~2e-5
      {"LinearBudgetsLogMse",
       {"fkb", "kplus-dynamic", "vkb"},
       {72000, 110000, 150000},
       /*failures=*/false,
       /*logBudgets=*/false,
       /*logMse=*/true,
       /*zeroMse=*/false},
  };
  return s;
}

// The scene outlives every view of it (a view may point at its textures).
std::unique_ptr<PreparedView> makeView(Engine& engine) {
  static const Scene scene = loadScene(kScene).value();
  const Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
  auto view = engine.prepare(View{&scene, camera, kSize, kSize});
  EXPECT_TRUE(view.ok());
  return std::move(view.value());
}

struct PlotSpec {
  const char* title;
  const char* jsonKey;
};
const PlotSpec kPlots[] = {{"Mean FLIP vs budget", "flip_mean"},
                           {"MSE (linear) vs budget", "mse_linear"},
                           {"Fragments lost vs budget", "fragments_lost_percent"}};

// Drawn coordinates are printed with one decimal (0.05 px), and a marker's centre is recovered
// from a corner or apex printed the same way: 0.15 px covers both roundings and the frame's own.
constexpr double kPixelTolerance = 0.15;

// whether the positive values of `key` over every successful run span a factor of 10 or more
bool spansADecade(const nlohmann::json& budgets, const char* key) {
  double lo = INFINITY, hi = 0.0;
  for (const nlohmann::json& b : budgets)
    for (const nlohmann::json& run : b.at("methods"))
      if (!run.contains("error") && run.at(key).get<double>() > 0.0) {
        lo = std::min(lo, run.at(key).get<double>());
        hi = std::max(hi, run.at(key).get<double>());
      }
  return std::isfinite(lo) && hi >= 10.0 * lo;
}

bool hasZero(const nlohmann::json& budgets, const char* key) {
  for (const nlohmann::json& b : budgets)
    for (const nlohmann::json& run : b.at("methods"))
      if (!run.contains("error") && run.at(key).get<double>() == 0.0) return true;
  return false;
}

class ReportPlots : public ::testing::TestWithParam<size_t> {};

TEST_P(ReportPlots, EveryPlottedPointIsTheJsonValue) {
  const Scenario& sc = scenarios()[GetParam()];
  CpuEngine engine(EngineOptions{2, 16});
  const std::unique_ptr<PreparedView> view = makeView(engine);
  CompareOptions o;
  o.methods = sc.methods;
  o.budgets.assign(sc.budgets.begin(), sc.budgets.end());
  o.scene = kScene;
  o.rules = {Compositing::KBuffer};  // explicit: independent of the presets' defaults
  auto r = runComparison(engine, *view, o);
  ASSERT_TRUE(r.ok()) << r.error().message;
  const nlohmann::json j = compareToJson(r.value());
  const std::string html = compareReportHtml(r.value(), ReportInfo{});

  const nlohmann::json& budgets = j.at("budgets");
  ASSERT_EQ(budgets.size(), sc.budgets.size());
  size_t failedRuns = 0;
  for (const nlohmann::json& b : budgets)
    for (const nlohmann::json& run : b.at("methods")) failedRuns += run.contains("error");
  EXPECT_EQ(failedRuns > 0, sc.failures) << failedRuns << " failed runs";

  for (const PlotSpec& spec : kPlots) {
    SCOPED_TRACE(spec.title);
    const std::string svg = svgWithTitle(html, spec.title);
    ASSERT_FALSE(svg.empty()) << "no plot titled " << spec.title;
    const Plot plot = parsePlot(svg);
    ASSERT_TRUE(plot.haveFrame);
    EXPECT_EQ(plot.x.log, sc.logBudgets) << "the scenario no longer exercises this x mapping";
    // error axes are log where their positive values span a decade (zeros drawn at the floor);
    // the fragments lost always linear
    const bool errorAxis = std::string(spec.jsonKey) != "fragments_lost_percent";
    const bool expectLog = errorAxis && spansADecade(budgets, spec.jsonKey);
    EXPECT_EQ(plot.y.log, expectLog);
    if (std::string(spec.jsonKey) == "mse_linear") {
      EXPECT_EQ(plot.y.log, sc.logMse) << "the scenario no longer exercises this y mapping";
      EXPECT_EQ(plot.y.floor > 0.0, sc.zeroMse) << "the scenario no longer draws zeros on log";
    }
    const bool zeros = hasZero(budgets, spec.jsonKey);
    if (plot.y.log && zeros) {
      EXPECT_GT(plot.y.floor, 0.0) << "zeros on a log axis need a floor";
    } else {
      EXPECT_EQ(plot.y.floor, 0.0);
    }

    // one series per method, in the methods' order
    ASSERT_EQ(plot.series.size(), sc.methods.size());
    for (size_t m = 0; m < sc.methods.size(); ++m) {
      const PlotSeries& s = plot.series[m];
      SCOPED_TRACE(sc.methods[m]);
      EXPECT_EQ(s.name, sc.methods[m]);

      // the points this series must have: every successful run, by budget
      std::map<double, double> expected;  // budget bytes -> JSON value
      for (const nlohmann::json& b : budgets) {
        const nlohmann::json& run = b.at("methods").at(m);
        ASSERT_EQ(run.at("name"), sc.methods[m]);
        ASSERT_EQ(run.at("budget_bytes"), b.at("budget_bytes"));
        if (run.contains("error")) continue;
        expected[b.at("budget_bytes").get<double>()] = run.at(spec.jsonKey).get<double>();
      }
      ASSERT_EQ(s.points.size(), expected.size()) << "points vs successful runs";

      std::set<double> seenBudgets;
      for (const PlotPoint& p : s.points) {
        const auto e = expected.find(p.dataX);
        ASSERT_NE(e, expected.end()) << "a point at x = " << p.dataX << " has no successful run";
        EXPECT_TRUE(seenBudgets.insert(p.dataX).second) << "two points at " << p.dataX;
        // exact value
        EXPECT_EQ(p.dataY, e->second) << "budget " << p.dataX;
        // drawn position through the axes
        const double bx = plot.x.value(p.px), vy = plot.y.value(p.py);
        EXPECT_TRUE(plot.x.agrees(bx, p.dataX, kPixelTolerance))
            << "budget " << p.dataX << " drawn at x = " << p.px << " reads back as " << bx;
        // a zero on a log axis is drawn at its floor (the line marked "0 exact")
        const double drawn = plot.y.log && e->second == 0.0 ? plot.y.floor : e->second;
        EXPECT_TRUE(plot.y.agrees(vy, drawn, kPixelTolerance))
            << "budget " << p.dataX << ": JSON " << e->second << ", drawn at y = " << p.py
            << " reads back as " << vy << " (axis " << (plot.y.log ? "log " : "linear ")
            << plot.y.lo << " .. " << plot.y.hi << ")";
        // inside the frame
        EXPECT_GE(drawn, plot.y.lo);
        EXPECT_LE(drawn, plot.y.hi);
      }

      // the line joins the markers in budget order (no line for a single point)
      std::vector<PlotPoint> sorted = s.points;
      std::sort(sorted.begin(), sorted.end(),
                [](const PlotPoint& a, const PlotPoint& b) { return a.dataX < b.dataX; });
      if (sorted.size() < 2) {
        EXPECT_TRUE(s.line.empty());
      } else {
        ASSERT_EQ(s.line.size(), sorted.size());
        for (size_t i = 0; i < sorted.size(); ++i) {
          EXPECT_NEAR(s.line[i].first, sorted[i].px, 0.11) << "vertex " << i;
          EXPECT_NEAR(s.line[i].second, sorted[i].py, 0.11) << "vertex " << i;
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenarios, ReportPlots, ::testing::Range<size_t>(0, 2),
                         [](const ::testing::TestParamInfo<size_t>& info) {
                           return std::string(scenarios()[info.param].name);
                         });

}  // namespace
}  // namespace mfr
