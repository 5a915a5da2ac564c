// Temporal stability (mfr/compare/temporal.hpp): a constructed sequence whose flicker is known
// from FLIP between two fixed images; along a real orbit, a method that renders the ground truth
// (the A-buffer, kplus-dynamic with room for every fragment) has zero excess flicker; frames that
// do not match are refused; `mfr compare --orbit N` writes the frames, the measure and its plots.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/compare/temporal.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

Image8 pattern(int w, int h, uint8_t a, uint8_t b, int period) {
  Image8 im;
  im.width = w;
  im.height = h;
  im.rgba.resize(static_cast<size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &im.rgba[(static_cast<size_t>(y) * w + x) * 4];
      const uint8_t v = ((x / period + y / period) % 2) ? a : b;
      p[0] = v;
      p[1] = static_cast<uint8_t>(v / 2);
      p[2] = static_cast<uint8_t>(255 - v);
      p[3] = 255;
    }
  return im;
}

// independent of temporal.cpp: the mean over pixels and RGB of |(m1 - g1) - (m0 - g0)| / 255
double expectedErrorChange(const Image8& m0, const Image8& g0, const Image8& m1, const Image8& g1) {
  double sum = 0.0;
  int n = 0;
  for (size_t i = 0; i < m0.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    sum += std::fabs((double(m1.rgba[i]) - g1.rgba[i]) - (double(m0.rgba[i]) - g0.rgba[i]));
    ++n;
  }
  return sum / 255.0 / n;
}

CompareRun run(const std::string& method, const Image8& image, double flip) {
  CompareRun r;
  r.method = r.label = method;
  r.image = image;
  r.metrics.flipMean = flip;
  return r;
}

CompareResult frame(const Image8& truth, std::vector<CompareRun> runs) {
  CompareResult f;
  f.width = truth.width;
  f.height = truth.height;
  f.groundTruth.image = truth;
  CompareBudget& b = f.budgets.emplace_back();
  b.label = "50%";
  b.runs = std::move(runs);
  return f;
}

TEST(TemporalStability, ConstructedSequenceHasTheFlipOfItsAlternation) {
  const Image8 g0 = pattern(48, 40, 200, 40, 4), g1 = pattern(48, 40, 190, 50, 5);
  const Image8 a = pattern(48, 40, 120, 30, 3), b = pattern(48, 40, 30, 220, 6);
  const double gFlip = computeFlip(g0, g1).value().mean;
  const double abFlip = computeFlip(a, b).value().mean;
  ASSERT_GT(gFlip, 0.0);
  ASSERT_GT(abFlip, 0.0);
  TemporalStability t;
  // the truth alternates g0, g1; "exact" renders it; "alternating" a, b; "steady" always a;
  // "failing" fails on frame 2
  for (int i = 0; i < 4; ++i) {
    const Image8& g = i % 2 ? g1 : g0;
    CompareRun failing = run("failing", a, 0.1);
    if (i == 2) failing.error = "budget too small";
    ASSERT_TRUE(t.add(frame(g, {run("exact", g, 0.0), run("alternating", i % 2 ? b : a, 0.25 * i),
                                run("steady", a, 0.5), failing}))
                    .ok());
  }
  const TemporalResult r = t.result();
  EXPECT_EQ(r.frames, 4);
  ASSERT_EQ(r.groundTruthConsecutiveFlip.size(), 3u);
  EXPECT_DOUBLE_EQ(r.groundTruthFlicker, gFlip);
  ASSERT_EQ(r.series.size(), 4u);
  const TemporalSeries &exact = r.series[0], &alternating = r.series[1], &steady = r.series[2],
                       &failing = r.series[3];
  EXPECT_EQ(exact.budgetLabel, "50%");
  EXPECT_DOUBLE_EQ(exact.flicker, gFlip);
  EXPECT_EQ(exact.excessFlicker, 0.0);
  EXPECT_DOUBLE_EQ(alternating.flicker, abFlip);
  EXPECT_NEAR(alternating.excessFlicker, abFlip - gFlip, 1e-12);
  EXPECT_EQ(steady.flicker, 0.0);
  EXPECT_NEAR(steady.excessFlicker, -gFlip, 1e-12);
  EXPECT_EQ(alternating.errorFlip, (std::vector<double>{0.0, 0.25, 0.5, 0.75}));
  // the error change: none for the exact method; the steady one's error moves with the truth
  EXPECT_EQ(exact.meanErrorChange, 0.0);
  const double steadyChange = expectedErrorChange(a, g0, a, g1);
  ASSERT_GT(steadyChange, 0.0);
  EXPECT_NEAR(steady.meanErrorChange, steadyChange, 1e-12);
  ASSERT_EQ(alternating.errorChange.size(), 3u);
  EXPECT_NEAR(alternating.errorChange[0], expectedErrorChange(a, g0, b, g1), 1e-12);
  EXPECT_NEAR(alternating.errorChange[1], expectedErrorChange(b, g1, a, g0), 1e-12);
  EXPECT_GT(alternating.meanErrorChange, steady.meanErrorChange);
  EXPECT_TRUE(std::isnan(failing.meanErrorChange));
  EXPECT_TRUE(std::isnan(failing.consecutiveFlip[1]) && std::isnan(failing.consecutiveFlip[2]));
  EXPECT_EQ(failing.consecutiveFlip[0], 0.0);
  EXPECT_TRUE(std::isnan(failing.excessFlicker));
  const nlohmann::json j = temporalToJson(r);
  EXPECT_TRUE(j["series"][3]["excess_flicker"].is_null());
  EXPECT_DOUBLE_EQ(j["series"][1]["flicker"].get<double>(), abFlip);
  EXPECT_NEAR(j["series"][2]["mean_error_change"].get<double>(), steadyChange, 1e-12);
  EXPECT_TRUE(j["series"][3]["mean_error_change"].is_null());
  for (TemporalMeasure m : {TemporalMeasure::ExcessFlicker, TemporalMeasure::ErrorChange}) {
    auto plot = temporalPlot(r, "50%", m);
    ASSERT_TRUE(plot.ok()) << plot.error().message;
    EXPECT_GT(plot->width, 0);
  }
}

TEST(TemporalStability, RefusesFramesThatDoNotMatch) {
  const Image8 g = pattern(32, 32, 10, 200, 4);
  TemporalStability t;
  ASSERT_TRUE(t.add(frame(g, {run("fkb", g, 0.0)})).ok());
  auto other = t.add(frame(g, {run("vkb", g, 0.0)}));
  ASSERT_FALSE(other.ok());
  EXPECT_NE(other.error().message.find("vkb"), std::string::npos);
  EXPECT_FALSE(t.add(frame(pattern(16, 32, 10, 200, 4), {run("fkb", g, 0.0)})).ok());
}

TEST(TemporalStability, ExactMethodsHaveNoExcessFlickerAlongAnOrbit) {
  const Scene scene = loadScene("procedural:hairball?strands=120").value();
  const Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
  CpuEngine engine(EngineOptions{2, 16});
  CompareOptions o;
  o.methods = {"abuffer", "kplus-dynamic", "vkb"};
  o.budgets = {BudgetSpec::relative(100.0)};
  o.rules = {Compositing::KBuffer};
  TemporalStability t;
  const std::vector<Camera> path = orbitPath(camera, 4, 6.0f);
  ASSERT_EQ(path.size(), 4u);
  EXPECT_EQ(path[0].eye, camera.eye);
  for (const Camera& c : path) {
    auto view = engine.prepare(View{&scene, c, 64, 64});
    ASSERT_TRUE(view.ok());
    auto r = runComparison(engine, **view, o);
    ASSERT_TRUE(r.ok()) << r.error().message;
    // room for every fragment: kplus-dynamic renders the ground truth; vkb (floor(P(p) F(M)))
    // does not
    ASSERT_TRUE(r->budgets[0].runs[1].ok());
    ASSERT_EQ(r->budgets[0].runs[1].stats.lost, 0u);
    ASSERT_EQ(r->budgets[0].runs[1].image.rgba, r->groundTruth.image.rgba);
    ASSERT_TRUE(t.add(r.value()).ok());
  }
  const TemporalResult r = t.result();
  ASSERT_EQ(r.series.size(), 3u);
  EXPECT_GT(r.groundTruthFlicker, 0.0);  // the camera moves
  EXPECT_EQ(r.series[0].excessFlicker, 0.0);
  EXPECT_EQ(r.series[1].excessFlicker, 0.0);
  EXPECT_EQ(r.series[0].meanErrorChange, 0.0);
  EXPECT_EQ(r.series[1].meanErrorChange, 0.0);
  EXPECT_TRUE(std::isfinite(r.series[2].excessFlicker));
  EXPECT_GT(r.series[2].meanErrorChange, 0.0);  // vkb loses fragments, and its error moves
  EXPECT_NE(r.series[2].flicker, r.groundTruthFlicker);
}

TEST(TemporalStabilityCli, CompareOrbitWritesFramesMeasureAndPlots) {
  const fs::path dir = test::processTempDir("mfr_temporal") / "out";
  auto r = test::runCli(
      "compare 'procedural:hairball?strands=120' --width 64 --height 64 --quiet --orbit 3 "
      "--orbit-step 5 --methods abuffer,fkb,vkb-fill --composite kbuffer --budget 100%,60% "
      "--out " +
          dir.string(),
      dir.parent_path());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* f :
       {"frame_000/results.json", "frame_002/report.html", "report.html", "results.csv"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  EXPECT_FALSE(fs::exists(dir / "temporal_100pct.png"));  // the plots are in the page
  std::ifstream in(dir / "results.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["orbit"], 3);
  EXPECT_EQ(j["orbit_step_degrees"], 5.0);
  const nlohmann::json& t = j["temporal"];
  EXPECT_EQ(t["frames"], 3);
  ASSERT_EQ(t["series"].size(), 6u);
  EXPECT_EQ(t["series"][0]["method"], "abuffer");
  EXPECT_EQ(t["series"][0]["excess_flicker"], 0.0);
  EXPECT_EQ(t["series"][0]["mean_error_change"], 0.0);
  EXPECT_EQ(t["series"][2]["error_change"].size(), 2u);
  EXPECT_EQ(t["series"][4]["budget_label"], "60%");
  EXPECT_TRUE(t["series"][3]["excess_flicker"].is_null());  // the A-buffer needs 100%
  EXPECT_EQ(t["series"][2]["consecutive_flip"].size(), 2u);
  // each frame's error is its own report's
  std::ifstream f1(dir / "frame_001" / "results.json");
  const nlohmann::json frame1 = nlohmann::json::parse(f1);
  ASSERT_TRUE(frame1["budgets"][0]["methods"][2].contains("flip_mean"));
  EXPECT_EQ(t["series"][2]["error_flip"][1], frame1["budgets"][0]["methods"][2]["flip_mean"]);
  std::ifstream html(dir / "report.html");
  const std::string page((std::istreambuf_iterator<char>(html)), std::istreambuf_iterator<char>());
  EXPECT_NE(page.find("excess flicker"), std::string::npos);
  EXPECT_NE(page.find("error change"), std::string::npos);
  // in the one-view report's style: inline SVG plots per budget, the frames as images
  EXPECT_NE(page.find("aria-label=\"Excess flicker at 60%\""), std::string::npos);
  EXPECT_NE(page.find("aria-label=\"Error change at 100%\""), std::string::npos);
  EXPECT_NE(page.find("aria-label=\"Mean FLIP vs ground truth at 60%\""), std::string::npos);
  EXPECT_NE(page.find("<img src=\"frame_002/ground_truth.png\""), std::string::npos);
  EXPECT_NE(page.find("<img src=\"frame_001/" +
                      frame1["budgets"][1]["methods"][1]["image"].get<std::string>() + "\""),
            std::string::npos);
  EXPECT_NE(page.find("data-sortable"), std::string::npos);
  // mean_flip is the mean of error_flip; results.csv has its row per series
  const nlohmann::json& s2 = t["series"][2];
  double sum = 0.0;
  for (const nlohmann::json& v : s2["error_flip"]) sum += v.get<double>();
  EXPECT_NEAR(s2["mean_flip"].get<double>(), sum / 3.0, 1e-15);
  std::ifstream csvIn(dir / "results.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(csvIn, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 1u + 1u + 6u);
  EXPECT_EQ(rows[0],
            "method,budget_label,frames,mean_flip,flicker,excess_flicker,mean_error_change");
  EXPECT_EQ(rows[1].rfind("abuffer,,3,0,", 0), 0u) << rows[1];
  EXPECT_EQ(rows[5], "abuffer,60%,3,,,,") << "the A-buffer failed at 60%: empty fields";
  EXPECT_EQ(rows[4].rfind("vkb-fill,100%,3,", 0), 0u) << rows[4];

  auto one = test::runCli(
      "compare procedural:spheres --width 32 --height 32 --quiet --orbit 1 "
      "--budget 50% --out " +
          dir.string(),
      dir.parent_path());
  EXPECT_EQ(one.exitCode, 1);
  EXPECT_NE(one.err.find("--orbit 1"), std::string::npos) << one.err;
  auto step = test::runCli(
      "compare procedural:spheres --width 32 --height 32 --quiet "
      "--orbit-step 5 --budget 50% --out " +
          dir.string(),
      dir.parent_path());
  EXPECT_EQ(step.exitCode, 1);
  EXPECT_NE(step.err.find("--orbit-step"), std::string::npos) << step.err;
}

}  // namespace
}  // namespace mfr
