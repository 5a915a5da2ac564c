// mfr compare: the library comparison (runs, budgets, metrics against the ground truth, failures
// recorded per run), its JSON / CSV / HTML, and the command line end to end (files, results.json
// layout, metrics recomputed from the written PNGs, bad input).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "error_assertions.hpp"
#include "mfr/compare/compare.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/metrics/image_metrics.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/scene.hpp"
#include "test_paths.hpp"

namespace mfr {
namespace {

/// The fields of one CSV row: commas outside double quotes, plus one.
size_t csvFieldCount(const std::string& row) {
  size_t commas = 0;
  bool quoted = false;
  for (char c : row) {
    if (c == '"') quoted = !quoted;
    if (c == ',' && !quoted) ++commas;
  }
  return commas + 1;
}

namespace fs = std::filesystem;

// 200 strands at 96x96: ~32k fragments, depth complexity ~25; the exact A-buffer needs ~320 KiB,
// so it fails at 200 KiB and fits at 400 KiB.
const char* kScene = "procedural:hairball?strands=200";
constexpr int kSize = 96;
constexpr uint64_t kSmall = 200u << 10, kLarge = 400u << 10;
const std::vector<std::string> kMethods = {"fkb", "kplus-dynamic", "vkb", "vkb-fill", "abuffer"};

// ---- library -------------------------------------------------------------------------------

CpuEngine& engine() {
  static CpuEngine cpu(EngineOptions{2, 16});
  return cpu;
}

// The scene outlives every view of it (a view may point at its textures).
std::unique_ptr<PreparedView> makeView() {
  static const Scene scene = loadScene(kScene).value();
  const Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
  auto view = engine().prepare(View{&scene, camera, kSize, kSize});
  EXPECT_TRUE(view.ok());
  return std::move(view.value());
}

CompareOptions defaultOptions() {
  CompareOptions o;
  o.methods = kMethods;
  o.budgets = {kSmall, kLarge};
  o.scene = kScene;
  return o;
}

class CompareLibrary : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    view_ = makeView().release();
    int calls = 0, lastDone = -1, lastTotal = -1;
    CompareOptions o = defaultOptions();
    o.progress = [&](const std::string&, int done, int total) {
      ++calls;
      lastDone = done;
      lastTotal = total;
    };
    auto r = runComparison(engine(), *view_, o);
    ASSERT_TRUE(r.ok()) << r.error().message;
    result_ = new CompareResult(std::move(r.value()));
    EXPECT_GT(calls, 10);
    EXPECT_EQ(lastDone, lastTotal);
    EXPECT_EQ(lastTotal, 1 + static_cast<int>(kMethods.size()) * 2);
  }
  static void TearDownTestSuite() {
    delete result_;
    delete view_;
    result_ = nullptr;
    view_ = nullptr;
  }
  static const CompareRun& run(size_t budget, const std::string& method) {
    for (const CompareRun& r : result_->budgets.at(budget).runs)
      if (r.method == method) return r;
    throw std::runtime_error("no run " + method);
  }
  static PreparedView* view_;
  static CompareResult* result_;
};
PreparedView* CompareLibrary::view_ = nullptr;
CompareResult* CompareLibrary::result_ = nullptr;

TEST_F(CompareLibrary, EveryMethodAtEveryBudgetInOrder) {
  const CompareResult& r = *result_;
  EXPECT_EQ(r.width, kSize);
  EXPECT_EQ(r.height, kSize);
  EXPECT_EQ(r.scene, kScene);
  ASSERT_EQ(r.budgets.size(), 2u);
  EXPECT_EQ(r.budgets[0].budgetBytes, kSmall);
  EXPECT_EQ(r.budgets[0].label, "200KB");
  EXPECT_EQ(r.budgets[1].budgetBytes, kLarge);
  for (const CompareBudget& cb : r.budgets) {
    ASSERT_EQ(cb.runs.size(), kMethods.size());
    for (size_t i = 0; i < kMethods.size(); ++i) {
      EXPECT_EQ(cb.runs[i].method, kMethods[i]);
      EXPECT_EQ(cb.runs[i].budgetBytes, cb.budgetBytes);
    }
  }
}

TEST_F(CompareLibrary, GroundTruthIsTheExactAbuffer) {
  const CompareRun& gt = result_->groundTruth;
  ASSERT_TRUE(gt.ok());
  EXPECT_EQ(gt.method, "abuffer");
  EXPECT_FALSE(gt.budgetBytes);
  EXPECT_GT(gt.stats.fragmentsGenerated, 10000u);
  EXPECT_EQ(gt.stats.lost, 0u);
  EXPECT_EQ(gt.stats.captured, gt.stats.fragmentsGenerated);
  EXPECT_EQ(gt.image.width, kSize);
  EXPECT_EQ(result_->depthComplexityMap.width, kSize);
  EXPECT_GT(result_->depthComplexityMap.height, kSize);  // legend strip below
  EXPECT_EQ(gt.metrics.mseLinear, 0.0);
  EXPECT_TRUE(std::isinf(gt.metrics.psnrLinear));
}

TEST_F(CompareLibrary, BudgetsAreRespectedAndFragmentsAddUp) {
  for (const CompareBudget& cb : result_->budgets)
    for (const CompareRun& run : cb.runs) {
      if (!run.ok()) continue;
      SCOPED_TRACE(run.method + " at " + cb.label);
      EXPECT_LE(run.stats.bytesUsed, cb.budgetBytes);
      EXPECT_EQ(run.stats.captured + run.stats.lost, run.stats.fragmentsGenerated);
      EXPECT_EQ(run.stats.fragmentsGenerated, result_->groundTruth.stats.fragmentsGenerated);
      EXPECT_LE(run.stats.captured, run.budgetSlots);
      EXPECT_GT(run.budgetSlots, 0u);
      EXPECT_LE(run.budgetSlots * 8, cb.budgetBytes);
      EXPECT_LE(run.memoryUtilisation(), 1.0);
      EXPECT_GT(run.memoryUtilisation(), 0.0);
      EXPECT_LE(run.stats.kMin, run.stats.kMax);
      EXPECT_EQ(run.image.width, kSize);
      EXPECT_EQ(run.flipMap.width, kSize);
      EXPECT_EQ(run.flipMap.height, kSize);
      EXPECT_EQ(run.kMap.width, kSize);
      EXPECT_FALSE(run.stats.passes.empty());
      // importance maps for the variable k-buffer only
      const bool importance = run.method == "vkb" || run.method == "vkb-fill";
      EXPECT_EQ(!run.importanceFile.empty(), importance);
      EXPECT_EQ(!run.importanceMap.rgba.empty(), importance);
    }
  // more memory, fewer losses
  for (const char* m : {"fkb", "kplus-dynamic", "vkb-fill"})
    EXPECT_LE(run(1, m).stats.lost, run(0, m).stats.lost) << m;
}

TEST_F(CompareLibrary, FailingMethodIsRecordedAndTheRunContinues) {
  const CompareRun& small = run(0, "abuffer");
  ASSERT_FALSE(small.ok());
  EXPECT_NE(small.error->find("abuffer"), std::string::npos) << *small.error;
  EXPECT_TRUE(small.imageFile.empty());
  // the other methods at that budget, and the abuffer at the larger one, ran
  EXPECT_TRUE(run(0, "fkb").ok());
  EXPECT_TRUE(run(0, "vkb-fill").ok());
  const CompareRun& large = run(1, "abuffer");
  ASSERT_TRUE(large.ok()) << *large.error;
  EXPECT_EQ(large.metrics.mseLinear, 0.0);  // the abuffer against itself
  EXPECT_EQ(large.metrics.mseSrgb, 0.0);
  EXPECT_EQ(large.metrics.flipMean, 0.0);
  EXPECT_TRUE(std::isinf(large.metrics.psnrSrgb));
  EXPECT_EQ(large.stats.lost, 0u);
}

TEST_F(CompareLibrary, MetricsMatchTheMetricsApiOnTheImages) {
  for (const CompareBudget& cb : result_->budgets)
    for (const CompareRun& run : cb.runs) {
      if (!run.ok()) continue;
      SCOPED_TRACE(run.method + " at " + cb.label);
      auto e = compareImages(result_->groundTruth.image, run.image);
      ASSERT_TRUE(e.ok());
      EXPECT_DOUBLE_EQ(run.metrics.mseLinear, e->mseLinear);
      EXPECT_DOUBLE_EQ(run.metrics.mseSrgb, e->mseSrgb);
      auto flip = computeFlip(result_->groundTruth.image, run.image);
      ASSERT_TRUE(flip.ok());
      EXPECT_DOUBLE_EQ(run.metrics.flipMean, flip->mean);
      if (run.stats.lost == 0) {  // every fragment captured: the exact image
        EXPECT_EQ(run.metrics.mseLinear, 0.0);
        EXPECT_EQ(run.metrics.flipMean, 0.0);
      } else {
        EXPECT_GT(run.metrics.mseLinear, 0.0);
        EXPECT_GT(run.metrics.flipMean, 0.0);
        EXPECT_NEAR(run.metrics.psnrLinear, 10.0 * std::log10(1.0 / run.metrics.mseLinear), 1e-9);
      }
    }
}

TEST_F(CompareLibrary, KMapsShareOneScale) {
  uint32_t kMax = 1;
  for (const CompareBudget& cb : result_->budgets)
    for (const CompareRun& run : cb.runs)
      if (run.ok()) kMax = std::max(kMax, run.stats.kMax);
  EXPECT_EQ(result_->kMapScale, static_cast<float>(kMax));
}

TEST_F(CompareLibrary, JsonHasTheDocumentedLayout) {
  const nlohmann::json j = compareToJson(*result_, "0.1.0");
  EXPECT_EQ(j["mfr_version"], "0.1.0");
  EXPECT_EQ(j["scene"], kScene);
  EXPECT_EQ(j["width"], kSize);
  EXPECT_EQ(j["height"], kSize);
  EXPECT_EQ(j["budget_bytes"], kSmall);
  EXPECT_EQ(j["compositing"], "per-method");  // no override: each preset's own rule
  for (const nlohmann::json& run : j["methods"]) {
    const MethodDesc preset = methodPreset(run["name"].get<std::string>()).value();
    EXPECT_EQ(run["compositing"], toString(preset.compositing)) << run["name"];
  }
  EXPECT_EQ(j["ground_truth"]["image"], "ground_truth.png");
  EXPECT_EQ(j["ground_truth"]["depth_complexity_image"], "ground_truth_depth_complexity.png");
  EXPECT_EQ(j["ground_truth"]["mse"], 0.0);
  EXPECT_TRUE(j["ground_truth"]["psnr"].is_null());
  EXPECT_TRUE(j["ground_truth"]["fm_slots"].is_null());
  ASSERT_EQ(j["budgets"].size(), 2u);
  EXPECT_EQ(j["methods"], j["budgets"][0]["methods"]);
  EXPECT_EQ(j["budgets"][1]["budget_bytes"], kLarge);
  EXPECT_EQ(j["budgets"][1]["budget_label"], "400KB");
  const nlohmann::json& fkb = j["budgets"][1]["methods"][0];
  EXPECT_EQ(fkb["name"], "fkb");
  EXPECT_EQ(fkb["image"], "fkb_400KB.png");
  EXPECT_EQ(fkb["flip_image"], "fkb_400KB_flip.png");
  EXPECT_EQ(fkb["k_map_image"], "fkb_400KB_kmap.png");
  EXPECT_FALSE(fkb.contains("importance_image"));
  EXPECT_EQ(j["budgets"][1]["methods"][2]["importance_image"], "vkb_400KB_importance.png");
  EXPECT_EQ(fkb["mse"], fkb["mse_linear"]);
  EXPECT_EQ(fkb["psnr"], fkb["psnr_linear"]);
  EXPECT_TRUE(fkb["time_ms"].is_object());
  EXPECT_TRUE(fkb["time_ms"].contains("capture"));
  EXPECT_TRUE(fkb["total_ms"].is_number());
  const nlohmann::json& failed = j["budgets"][0]["methods"][4];
  EXPECT_EQ(failed["name"], "abuffer");
  EXPECT_TRUE(failed["error"].is_string());
  EXPECT_FALSE(failed.contains("mse"));
  EXPECT_FALSE(failed.contains("image"));
}

TEST_F(CompareLibrary, CsvHasOneRowPerRunAndTheGroundTruthFirst) {
  const std::string csv = compareToCsv(*result_);
  std::istringstream in(csv);
  std::string header, line;
  std::getline(in, header);
  const size_t columns = static_cast<size_t>(std::count(header.begin(), header.end(), ',')) + 1;
  EXPECT_NE(header.find("mse_linear"), std::string::npos);
  EXPECT_NE(header.find("psnr_srgb"), std::string::npos);
  EXPECT_NE(header.find("time_capture_ms"), std::string::npos);
  std::vector<std::string> rows;
  while (std::getline(in, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 1 + kMethods.size() * 2);
  EXPECT_EQ(rows[0].rfind(",,abuffer,abuffer,kbuffer,ok,ground_truth.png,", 0), 0u) << rows[0];
  EXPECT_EQ(rows[1].rfind(std::to_string(kSmall) + ",200KB,fkb,fkb,", 0), 0u) << rows[1];
  for (const std::string& row : rows) {
    // no field of these rows is quoted except an error message
    EXPECT_EQ(csvFieldCount(row), columns) << row;
  }
  EXPECT_NE(rows[5].find(",abuffer,kbuffer,error,"), std::string::npos) << rows[5];
}

TEST_F(CompareLibrary, HtmlReportIsSelfContainedAndShowsEverything) {
  ReportInfo info;
  info.mfrVersion = "mfr 0.1.0";
  info.commandLine = "mfr compare '<scene>' & more";
  const std::string html = compareReportHtml(*result_, info);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("</html>"), std::string::npos);
  // one inline script (sortable tables, wipers), nothing loaded
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(html.find("<script"), html.rfind("<script"));
  // no external resource: the only URL is the SVG namespace
  std::string stripped = html;
  for (size_t p; (p = stripped.find("http://www.w3.org/2000/svg")) != std::string::npos;)
    stripped.erase(p, 26);
  EXPECT_EQ(stripped.find("http:"), std::string::npos);
  EXPECT_EQ(stripped.find("https:"), std::string::npos);
  EXPECT_EQ(stripped.find("url("), std::string::npos);
  EXPECT_NE(html.find("mfr compare &#39;&lt;scene&gt;&#39; &amp; more"), std::string::npos);
  EXPECT_NE(html.find("mfr 0.1.0"), std::string::npos);
  EXPECT_NE(html.find("<table class=\"results\""), std::string::npos);
  // every written image is shown
  std::set<std::string> files = {"ground_truth.png", "ground_truth_depth_complexity.png"};
  for (const CompareBudget& cb : result_->budgets)
    for (const CompareRun& run : cb.runs)
      for (const std::string* f :
           {&run.imageFile, &run.flipFile, &run.kMapFile, &run.importanceFile})
        if (!f->empty()) files.insert(*f);
  for (const std::string& f : files)
    EXPECT_NE(html.find("<img src=\"" + f + "\""), std::string::npos) << f;
  // several budgets: the two error-vs-budget plots, with axes, a legend entry per method
  size_t svgs = 0;
  for (size_t p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1)) ++svgs;
  EXPECT_GE(svgs, 2u);
  EXPECT_NE(html.find("Mean FLIP vs budget"), std::string::npos);
  EXPECT_NE(html.find("MSE (linear) vs budget"), std::string::npos);
  EXPECT_NE(html.find("memory budget M"), std::string::npos);
  // and every method's error against the bytes per pixel it was charged
  EXPECT_NE(html.find("Mean FLIP vs bytes per pixel"), std::string::npos);
  EXPECT_NE(html.find("bytes per pixel charged"), std::string::npos);
  // the failure is on the page, and the plots' legend names the method's minimum
  EXPECT_NE(html.find("abuffer at 200KB: needs at least"), std::string::npos);
  EXPECT_NE(html.find("abuffer (needs &#8805; "), std::string::npos);
}

TEST(CompareOptionsCheck, BadOptionsAreErrorsNamingTheInput) {
  static const std::unique_ptr<PreparedView> view = makeView();
  const auto error = [&](CompareOptions o) {
    auto r = runComparison(engine(), *view, o);
    return r.ok() ? std::string() : r.error().message;
  };
  CompareOptions o = defaultOptions();
  o.methods.clear();
  EXPECT_NE(error(o).find("empty"), std::string::npos);
  o = defaultOptions();
  o.methods = {"fkb", "kbuffer9"};
  EXPECT_NE(error(o).find("kbuffer9"), std::string::npos);
  o.methods = {"fkb", "fkb"};
  EXPECT_NE(error(o).find("twice"), std::string::npos);
  o = defaultOptions();
  o.budgets.clear();
  EXPECT_NE(error(o).find("budget"), std::string::npos);
  o.budgets = {kSmall, kSmall};
  EXPECT_NE(error(o).find("200KB"), std::string::npos);
}

// --repeat / --warmup: every run (and the ground truth) is timed `repeat` times; the statistics
// carry the median render's passes, so the total is the median, between the min and the max.
TEST(CompareOptionsCheck, RepeatedRunsReportTheMedianAndTheSpread) {
  static const std::unique_ptr<PreparedView> view = makeView();
  CompareOptions o;
  o.methods = {"fkb", "wboit"};
  o.budgets = {kLarge};
  o.scene = kScene;
  o.repeat = 3;
  o.warmup = 1;
  auto r = runComparison(engine(), *view, o);
  ASSERT_TRUE(r.ok()) << r.error().message;
  std::vector<const CompareRun*> runs = {&r->groundTruth};
  for (const CompareRun& run : r->budgets[0].runs) runs.push_back(&run);
  for (const CompareRun* run : runs) {
    SCOPED_TRACE(run->label);
    ASSERT_TRUE(run->ok());
    EXPECT_EQ(run->timing.repeats, 3);
    EXPECT_LE(run->timing.minMs, run->timing.medianMs);
    EXPECT_LE(run->timing.medianMs, run->timing.maxMs);
    EXPECT_NEAR(run->stats.totalMs(), run->timing.medianMs, 1e-9);
  }
  const nlohmann::json j = compareToJson(r.value());
  EXPECT_EQ(j["repeat"], 3);
  EXPECT_EQ(j["warmup"], 1);
  EXPECT_EQ(j["methods"][0]["repeats"], 3);
  EXPECT_EQ(j["methods"][0]["total_ms_max"], r->budgets[0].runs[0].timing.maxMs);
  // the report's time cell: the median, the range beside it
  const std::string html = compareReportHtml(r.value(), ReportInfo{});
  const RunTiming& t = r->budgets[0].runs[0].timing;
  char cell[96];
  std::snprintf(cell, sizeof cell, "%.1f<small> %.1f&ndash;%.1f</small>", t.medianMs, t.minMs,
                t.maxMs);
  EXPECT_NE(html.find(cell), std::string::npos) << cell;
  o.repeat = 0;  // the library refuses what the request check would
  EXPECT_FALSE(runComparison(engine(), *view, o).ok());
}

// An engine that renders like the CPU engine but refuses the A-buffer, as a GPU whose limits
// refuse the ground truth's node buffer does.
class RefusingEngine final : public Engine {
 public:
  std::string_view name() const override { return "refusing"; }
  std::map<std::string, std::string> describe() const override { return {}; }
  Result<std::unique_ptr<PreparedView>> prepare(const View& view) override {
    return cpu_.prepare(view);
  }
  using Engine::render;
  Result<RenderOutput> render(const PreparedView& view, const MethodDesc& method,
                              const RenderOptions& options) override {
    if (method.name == "abuffer") return makeError("node buffer above the device's limit");
    return cpu_.render(view, method, options);
  }
  Result<std::vector<uint32_t>> countFragments(const PreparedView& view) override {
    return cpu_.countFragments(view);
  }
  Result<std::vector<float>> nearestCosine(const PreparedView& view) override {
    return cpu_.nearestCosine(view);
  }

 private:
  CpuEngine cpu_{EngineOptions{2, 16}};
};

TEST(CompareTruthEngine, TheCpuEngineTakesOverTheTruthAGpuRefusesWithANote) {
  static const Scene scene = loadScene(kScene).value();
  const View v{&scene, frameBounds(sceneBounds(scene)), kSize, kSize, 1};
  CompareOptions o;
  o.methods = {"fkb"};
  o.budgets = {kLarge};
  o.scene = kScene;
  RefusingEngine gpu;
  {  // no truth engine: the comparison fails, naming the ground truth
    auto prepared = prepareComparedView(gpu, v, o);
    ASSERT_TRUE(prepared.ok());
    auto r = runComparison(gpu, *prepared->view, o);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message, "ground truth (abuffer): node buffer above the device's limit");
  }
  CpuEngine cpu(EngineOptions{2, 16});
  auto own = engine().prepare(v);
  ASSERT_TRUE(own.ok());
  auto reference = runComparison(engine(), **own, o);  // everything on the CPU engine
  ASSERT_TRUE(reference.ok()) << reference.error().message;
  for (const bool fallback : {true, false}) {
    SCOPED_TRACE(fallback ? "fallback" : "--truth-engine cpu");
    o.truthEngine = &cpu;
    o.truthFallback = fallback;
    auto prepared = prepareComparedView(gpu, v, o);
    ASSERT_TRUE(prepared.ok());
    ASSERT_TRUE(prepared->truth);
    EXPECT_FALSE(runComparison(gpu, *prepared->view, o).ok());  // the truth's view is required
    auto r = runComparison(gpu, *prepared->view, o, prepared->truth.get());
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->engine, "refusing");
    EXPECT_EQ(r->truthEngine, "cpu");
    EXPECT_EQ(r->truthNote, fallback ? "ground truth on the cpu engine: refusing: node buffer "
                                       "above the device's limit"
                                     : "");
    EXPECT_EQ(r->groundTruth.image.rgba, reference->groundTruth.image.rgba);
    EXPECT_EQ(r->budgets[0].runs[0].metrics.flipMean,
              reference->budgets[0].runs[0].metrics.flipMean);
    const nlohmann::json j = compareToJson(r.value());
    EXPECT_EQ(j["truth_engine"], "cpu");
    EXPECT_EQ(j.contains("truth_note"), fallback);
  }
}

TEST(CompareOptionsCheck, SingleBudgetHasNoPlotsAndHybridIsRecorded) {
  static const std::unique_ptr<PreparedView> view = makeView();
  CompareOptions o;
  o.methods = {"kplus-sb"};
  o.budgets = {1u << 20};
  o.rules = {Compositing::Hybrid};
  o.scene = kScene;
  auto r = runComparison(engine(), *view, o);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->budgets[0].runs[0].ok()) << *r->budgets[0].runs[0].error;
  EXPECT_EQ(r->budgets[0].label, "1MB");
  // the hybrid tail is charged: 20 B per pixel
  EXPECT_EQ(r->budgets[0].runs[0].stats.bytesByCategory.count("tail"), 1u);
  const nlohmann::json j = compareToJson(r.value());
  EXPECT_EQ(j["compositing"], "hybrid");
  EXPECT_EQ(j["methods"][0]["compositing"], "hybrid");
  EXPECT_EQ(j["ground_truth"]["compositing"], "kbuffer");
  const std::string html = compareReportHtml(r.value(), {});
  EXPECT_EQ(html.find("<svg"), std::string::npos);
}

TEST(CompareBudgetLabel, WholeUnitsOrBytes) {
  EXPECT_EQ(budgetLabel(20u << 20), "20MB");
  EXPECT_EQ(budgetLabel(400u << 10), "400KB");
  EXPECT_EQ(budgetLabel(1536u << 20), "1536MB");
  EXPECT_EQ(budgetLabel(1000), "1000B");
}

// ---- command line ----------------------------------------------------------------------------

using CompareCliRun = mfr::test::CliRun;

fs::path tempDir() {
  static const fs::path dir = mfr::test::processTempDir("mfr_compare_test");
  return dir;
}

// removes the temporary folder after the last test of the process
class TempDirCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(tempDir(), ec);
  }
};
[[maybe_unused]] ::testing::Environment* const kCleanup =
    ::testing::AddGlobalTestEnvironment(new TempDirCleanup);

CompareCliRun runCli(const std::string& args) {
  return mfr::test::runCli(args, tempDir());
}

std::string sceneArgs() {
  std::string s = "'";
  s += kScene;
  s += "' --width ";
  s += std::to_string(kSize);
  s += " --height ";
  s += std::to_string(kSize);
  s += " --threads 2";
  return s;
}

class CompareCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(tempDir() / "out dir");  // a space in the path on purpose
    fs::remove_all(*dir_);
    run_ =
        new CompareCliRun(runCli("compare " + sceneArgs() +
                                 " --budget 200KB,400KB --methods fkb,kplus-dynamic,vkb,vkb-fill,"
                                 "abuffer --composite kbuffer --json --out '" +
                                 dir_->string() + "'"));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete run_;
    delete dir_;
  }
  static nlohmann::json results() {
    return nlohmann::json::parse(std::ifstream(*dir_ / "results.json"));
  }
  static fs::path* dir_;
  static CompareCliRun* run_;
};
fs::path* CompareCli::dir_ = nullptr;
CompareCliRun* CompareCli::run_ = nullptr;

TEST_F(CompareCli, WritesEveryFile) {
  ASSERT_EQ(run_->exitCode, 0) << run_->err;
  for (const char* f : {"results.json", "results.csv", "report.html", "ground_truth.png",
                        "ground_truth_depth_complexity.png", "fkb_200KB.png", "fkb_200KB_flip.png",
                        "fkb_200KB_kmap.png", "vkb_400KB_importance.png",
                        "vkb-fill_200KB_importance.png", "abuffer_400KB.png"})
    EXPECT_TRUE(fs::exists(*dir_ / f)) << f;
  EXPECT_FALSE(fs::exists(*dir_ / "abuffer_200KB.png"));  // failed at 200 KiB
  // every file the JSON names exists
  const nlohmann::json j = results();
  std::vector<nlohmann::json> runs = {j["ground_truth"]};
  for (const auto& b : j["budgets"])
    for (const auto& m : b["methods"]) runs.push_back(m);
  for (const auto& m : runs)
    for (const char* key :
         {"image", "flip_image", "k_map_image", "importance_image", "depth_complexity_image"})
      if (m.contains(key)) {
        EXPECT_TRUE(fs::exists(*dir_ / m[key].get<std::string>())) << m[key];
      }
}

TEST_F(CompareCli, ResultsJsonHasTheDocumentedKeysAndStdoutIsTheSame) {
  ASSERT_EQ(run_->exitCode, 0) << run_->err;
  const nlohmann::json j = results();
  EXPECT_EQ(nlohmann::json::parse(run_->out), j);  // --json
  for (const char* key : {"scene", "width", "height", "budget_bytes", "ground_truth", "methods",
                          "budgets", "mfr_version"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["scene"], kScene);
  EXPECT_EQ(j["budget_bytes"], kSmall);
  EXPECT_EQ(j["ground_truth"]["name"], "abuffer");
  EXPECT_GT(j["ground_truth"]["fragments_captured"].get<uint64_t>(), 0u);
  EXPECT_EQ(j["ground_truth"]["fragments_lost"], 0);
  ASSERT_EQ(j["methods"].size(), 5u);
  ASSERT_EQ(j["budgets"].size(), 2u);
  for (const auto& b : j["budgets"]) {
    const uint64_t budget = b["budget_bytes"].get<uint64_t>();
    for (const auto& m : b["methods"]) {
      SCOPED_TRACE(m["name"].get<std::string>() + " at " + std::to_string(budget));
      EXPECT_EQ(m["budget_bytes"], budget);
      if (m.contains("error")) {
        EXPECT_FALSE(m.contains("mse"));
        continue;
      }
      for (const char* key : {"name",
                              "image",
                              "bytes_used",
                              "fm_slots",
                              "fragment_slots",
                              "memory_utilisation",
                              "fragments_generated",
                              "fragments_captured",
                              "fragments_lost",
                              "fragments_lost_percent",
                              "k_min",
                              "k_max",
                              "mse",
                              "psnr",
                              "mse_linear",
                              "psnr_linear",
                              "mse_srgb",
                              "psnr_srgb",
                              "flip_mean",
                              "time_ms",
                              "total_ms"})
        EXPECT_TRUE(m.contains(key)) << key;
      EXPECT_LE(m["bytes_used"].get<uint64_t>(), budget);
      EXPECT_EQ(m["fragments_captured"].get<uint64_t>() + m["fragments_lost"].get<uint64_t>(),
                m["fragments_generated"].get<uint64_t>());
      EXPECT_EQ(m["mse"], m["mse_linear"]);
    }
  }
  // the failure is recorded, and the abuffer against itself has no error
  EXPECT_EQ(j["methods"][4]["name"], "abuffer");
  EXPECT_NE(j["methods"][4]["error"].get<std::string>().find("abuffer"), std::string::npos);
  EXPECT_EQ(j["budgets"][1]["methods"][4]["mse"], 0.0);
  EXPECT_TRUE(j["budgets"][1]["methods"][4]["psnr"].is_null());
}

TEST_F(CompareCli, MetricsMatchTheWrittenPngs) {
  ASSERT_EQ(run_->exitCode, 0) << run_->err;
  const nlohmann::json j = results();
  auto truth = readPng((*dir_ / j["ground_truth"]["image"].get<std::string>()).string());
  ASSERT_TRUE(truth.ok());
  int checked = 0;
  for (const auto& b : j["budgets"])
    for (const auto& m : b["methods"]) {
      if (m.contains("error")) continue;
      auto image = readPng((*dir_ / m["image"].get<std::string>()).string());
      ASSERT_TRUE(image.ok());
      auto stats = compareImages(*truth, *image);
      ASSERT_TRUE(stats.ok());
      EXPECT_NEAR(m["mse_linear"].get<double>(), stats->mseLinear, 1e-12);
      EXPECT_NEAR(m["mse_srgb"].get<double>(), stats->mseSrgb, 1e-12);
      if (stats->mseLinear > 0.0) {
        EXPECT_NEAR(m["psnr_srgb"].get<double>(), stats->psnrSrgb, 1e-9);
      }
      auto flip = computeFlip(*truth, *image);
      ASSERT_TRUE(flip.ok());
      EXPECT_NEAR(m["flip_mean"].get<double>(), flip->mean, 1e-12);
      ++checked;
    }
  EXPECT_EQ(checked, 9);
}

TEST_F(CompareCli, SummaryAndReportPathOnStderrAndACsvRowPerRun) {
  ASSERT_EQ(run_->exitCode, 0) << run_->err;
  EXPECT_NE(run_->err.find("report.html"), std::string::npos) << run_->err;
  EXPECT_NE(run_->err.find("kplus-dynamic"), std::string::npos) << run_->err;
  std::ifstream csv(*dir_ / "results.csv");
  size_t lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, 1u + 1u + 10u);
  std::ifstream html(*dir_ / "report.html");
  std::stringstream s;
  s << html.rdbuf();
  EXPECT_NE(s.str().find("--budget 200KB,400KB"), std::string::npos);  // the command line
  // the legend: every method of the run with its summary from the preset table, no other
  for (const PresetInfo& p : presetTable()) {
    const bool inRun = results().dump().find("\"" + p.name + "\"") != std::string::npos;
    const std::string entry = "<dt><code>" + p.name + "</code></dt><dd>";
    EXPECT_EQ(s.str().find(entry) != std::string::npos, inRun) << p.name;
    if (inRun) {
      EXPECT_NE(s.str().find(entry + p.summary.substr(0, 20)), std::string::npos);
    }
  }
}

// results.csv's header: every column a snake_case identifier (a pass named "peel 1" made the
// column "time_peel 1_ms"), and budget_label beside budget_bytes with the budget as given.
TEST(CompareCsv, ColumnsAreSnakeCaseIdentifiersWithTheBudgetLabel) {
  CompareResult r;
  r.groundTruth.method = r.groundTruth.label = "abuffer";
  r.groundTruth.imageFile = "ground_truth.png";
  r.groundTruth.stats.passes = {{"capture", 1.0}, {"peel 1", 2.0}};
  const auto budget = [](uint64_t bytes, const std::string& label) {
    CompareBudget b;
    b.budgetBytes = bytes;
    b.label = label;
    CompareRun ok;
    ok.method = "peel";
    ok.label = "peel-hybrid";
    ok.compositing = Compositing::Hybrid;
    ok.timing = {3, 12.0, 11.5, 14.25};
    ok.budgetBytes = bytes;
    ok.imageFile = "peel_" + label + ".png";
    ok.stats.passes = {{"peel 1", 3.0}, {"Peel-1", 4.0}, {"dual peel 2 (far)", 5.0}};
    CompareRun failed;
    failed.method = failed.label = "fkb";
    failed.budgetBytes = bytes;
    failed.error = "too small, by far";
    b.runs = {ok, failed};
    return b;
  };
  r.budgets = {budget(123456, "25%"), budget(8u << 20, "8MB")};
  std::istringstream in(compareToCsv(r));
  std::string header;
  std::getline(in, header);
  std::vector<std::string> columns;
  for (std::istringstream h(header); std::getline(h, columns.emplace_back(), ',');) {
  }
  columns.pop_back();
  for (const std::string& c : columns) {
    EXPECT_FALSE(c.empty()) << header;
    EXPECT_TRUE(std::all_of(c.begin(), c.end(), [](char ch) {
      return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_';
    })) << c;
  }
  EXPECT_EQ(std::set<std::string>(columns.begin(), columns.end()).size(), columns.size()) << header;
  ASSERT_GE(columns.size(), 3u);
  EXPECT_EQ(columns[0], "budget_bytes");
  EXPECT_EQ(columns[1], "budget_label");
  EXPECT_EQ(columns[2], "method");
  EXPECT_EQ(columns[3], "label");
  EXPECT_EQ(columns[4], "compositing");
  EXPECT_EQ(columns.back(), "error");
  // the passes in order of first appearance; two names of one identifier get a suffix
  const std::vector<std::string> times = {"time_capture_ms", "time_peel_1_ms", "time_peel_1_ms_2",
                                          "time_dual_peel_2_far_ms"};
  EXPECT_NE(header.find(",total_ms,repeats,total_ms_min,total_ms_max," + times[0] + "," + times[1] +
                        "," + times[2] + "," + times[3] + ",error"),
            std::string::npos)
      << header;
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0].rfind(",,abuffer,abuffer,kbuffer,ok,ground_truth.png,", 0), 0u) << rows[0];
  EXPECT_EQ(rows[1].rfind("123456,25%,peel,peel-hybrid,hybrid,ok,peel_25%.png,", 0), 0u) << rows[1];
  EXPECT_EQ(rows[2].rfind("123456,25%,fkb,fkb,kbuffer,error,", 0), 0u) << rows[2];
  EXPECT_EQ(rows[3].rfind("8388608,8MB,peel,peel-hybrid,", 0), 0u) << rows[3];
  EXPECT_EQ(rows[4].rfind("8388608,8MB,fkb,fkb,kbuffer,error,", 0), 0u) << rows[4];
  // the median total (the passes' sum), then the number of timed renders and their spread
  EXPECT_NE(rows[1].find(",12.000,3,11.500,14.250,"), std::string::npos) << rows[1];
  // every row has the header's columns (the error message quoted: its comma is not a column)
  for (const std::string& row : rows) {
    EXPECT_EQ(csvFieldCount(row), columns.size()) << row;
  }
  EXPECT_NE(rows[2].find(",\"too small, by far\""), std::string::npos) << rows[2];
  // the pass times land in their own columns: peel 1 = 3, Peel-1 = 4, dual peel 2 (far) = 5
  EXPECT_NE(rows[1].find(",,3.000,4.000,5.000,"), std::string::npos) << rows[1];
}

// one line on stderr naming `needle`, exit code 1, nothing written
void expectCleanFailure(const std::string& args, const std::string& needle) {
  const fs::path out = tempDir() / "never";
  fs::remove_all(out);
  const bool outGiven = args.find("--out") != std::string::npos;
  const CompareCliRun r = runCli("compare " + args + (outGiven ? "" : " --out " + out.string()));
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("mfr: error: ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(out / "results.json")) << args;
}

TEST(CompareCliErrors, BadInputIsOneLineNamingIt) {
  const std::string scene = sceneArgs() + " -q";
  expectCleanFailure(scene + " --budget 200KB --methods fkb,kbuffer9", "kbuffer9");
  expectCleanFailure(scene + " --budget 200KB,12XB", "12XB");
  expectCleanFailure(scene + " --budget 200KB,,400KB", "--budget");
  expectCleanFailure(scene + " --budget 200KB --methods ''", "--methods");
  expectCleanFailure(scene + " --budget 200KB --methods ,", "--methods");
  expectCleanFailure(scene + " --budget 200KB --methods fkb,fkb", "fkb");
  expectCleanFailure(scene + " --budget 200KB --composite blend", "blend");
  expectCleanFailure("procedural:teapot -q --budget 200KB", "teapot");
  // the request's checks (compare_request.hpp), before any work
  expectCleanFailure(scene + " --budget 200KB --composite kbuffer,kbuffer",
                     "'kbuffer' listed twice");
  expectCleanFailure(scene + " --budget 200KB --composite weighted-blended",
                     "'weighted-blended': expected kbuffer or hybrid");
  expectCleanFailure(scene + " --budget 200KB --repeat 0", "--repeat 0: must be in [1, 1000]");
  expectCleanFailure(scene + " --budget 200KB --warmup -2", "--warmup -2: must be in [0, 1000]");
  expectCleanFailure(scene + " --budget auto,200KB", "--budget auto: picks every budget");
  expectCleanFailure(scene + " --budget 200KB --truth-engine vulkanish", "--truth-engine");
  expectCleanFailure(scene + " --budget 200KB --methods fkb --max-peels 2",
                     "--max-peels: none of the methods peels");
  // an output folder that cannot be created: a path below a regular file
  const fs::path file = tempDir() / "a_file";
  std::ofstream(file) << "x";
  const std::string dir = (file / "sub").string();
  expectCleanFailure(scene + " --budget 200KB --out " + dir, dir);
}

// A comparison where nothing ran exits 1 (a study's loop sees it), after writing the folder of
// refusals; its last line names the smallest budget that runs.
TEST(CompareCliErrors, NothingRanIsAnErrorAfterTheFolderIsWritten) {
  const fs::path out = tempDir() / "nothing ran";
  fs::remove_all(out);
  const CompareCliRun r = runCli("compare " + sceneArgs() +
                                 " --budget 8KB,16KB --methods fkb,kplus-dynamic --composite "
                                 "kbuffer --repeat 1 --warmup 0 --out '" +
                                 out.string() + "'");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  const size_t last = r.err.rfind("mfr: error: ");
  ASSERT_NE(last, std::string::npos) << r.err;
  const std::string line = r.err.substr(last);
  EXPECT_EQ(std::count(line.begin(), line.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(test::contains(line,
                             "no run succeeded: every method was refused at every budget (the "
                             "smallest budget that runs: fkb at "))
      << line;
  EXPECT_TRUE(test::contains(line, "the refusals are in ")) << line;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "results.json"));
  EXPECT_EQ(j["budgets"][1]["methods"][0]["minimum_bytes"], kSize * kSize * 12);
  fs::remove_all(out);
}

// Without a terminal (a log, CI), a long comparison still says what it does: plain progress
// lines at most every MFR_PROGRESS_SECONDS, none for a run shorter than that (the error tests'
// single line stays single).
TEST(CompareCliProgress, LinesGoToALogWhenStderrIsNoTerminal) {
  const fs::path out = tempDir() / "progress";
  const std::string env = "MFR_PROGRESS_SECONDS=0.2 " + std::string(MFR_CLI_PATH) + " ";
  const CompareCliRun r = mfr::test::runShell(
      env + "compare " + sceneArgs() +
          " --budget 200KB,400KB --methods fkb,kplus-dynamic,vkb --repeat 40 --warmup 0 --out " +
          out.string(),
      tempDir());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::istringstream lines(r.err);
  int progress = 0;
  for (std::string line; std::getline(lines, line);) {
    EXPECT_EQ(line.find('\r'), std::string::npos) << line;  // no redrawing in a log
    EXPECT_EQ(line.find('\033'), std::string::npos) << line;
    if (line.rfind("progress: ", 0) != 0) continue;
    ++progress;
    EXPECT_NE(line.find(" s)"), std::string::npos) << line;
  }
  EXPECT_GE(progress, 1) << r.err;
  EXPECT_NE(r.err.find("report: "), std::string::npos) << r.err;  // the summary follows
  const CompareCliRun quiet = mfr::test::runShell(
      env + "compare " + sceneArgs() + " --budget 200KB --methods fkb --repeat 40 --quiet --out " +
          out.string(),
      tempDir());
  ASSERT_EQ(quiet.exitCode, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
  fs::remove_all(out);
}

// ---- the output folder: one whole comparison, never a mix ----------------------------------

std::set<std::string> entriesOf(const fs::path& dir) {
  std::set<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(dir))
    names.insert(e.path().filename().string());
  return names;
}

/// The folders beside `dir` that a comparison stages into (".NAME.compare-tmp.*").
std::set<std::string> stagingBeside(const fs::path& dir) {
  std::set<std::string> left;
  std::string prefix = ".";  // appended piece by piece (GCC 12 warns on "." + string)
  prefix += dir.filename().string();
  prefix += ".compare-tmp.";
  for (const std::string& name : entriesOf(dir.parent_path()))
    if (name.rfind(prefix, 0) == 0) left.insert(name);
  return left;
}

std::string compareArgs(int size, const std::string& methods, const fs::path& out) {
  // double quotes: the tests wrap some commands in sh -c '...'
  return "compare \"" + std::string(kScene) + "\" --width " + std::to_string(size) + " --height " +
         std::to_string(size) + " --threads 2 --budget 200KB --methods " + methods +
         " --composite kbuffer -q --out \"" + out.string() + "\"";
}

/// Every file of `dir` and its bytes.
std::map<std::string, std::string> contentsOf(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const std::string& name : entriesOf(dir)) {
    std::ifstream in(dir / name, std::ios::binary);
    files[name] = std::string((std::istreambuf_iterator<char>(in)), {});
  }
  return files;
}

int resultsWidth(const fs::path& dir) {
  return nlohmann::json::parse(std::ifstream(dir / "results.json"))["width"].get<int>();
}

TEST(CompareOutputFolder, AFailedCompareLeavesTheOldFolderWholeAndANewOneReplacesIt) {
  const fs::path root = tempDir() / "replace", dir = root / "out";
  fs::remove_all(root);
  fs::create_directories(root);
  ASSERT_EQ(runCli(compareArgs(16, "fkb,vkb", dir)).exitCode, 0);
  const std::map<std::string, std::string> first = contentsOf(dir);
  ASSERT_TRUE(first.count("vkb_200KB.png"));

  // a 64x64 compare whose larger files hit the file-size limit (the small ones fit): before, the
  // small new files landed beside the old 16x16 results.json
  const CompareCliRun cut = mfr::test::runShell(
      "sh -c 'ulimit -f 4; exec " + MFR_CLI_PATH + " " + compareArgs(64, "fkb", dir) + "'", root);
  EXPECT_EQ(cut.exitCode, 1) << cut.err;
  EXPECT_NE(cut.err.find("write error (File too large)"), std::string::npos) << cut.err;
  EXPECT_TRUE(contentsOf(dir) == first) << "the old folder was changed";
  EXPECT_TRUE(stagingBeside(dir).empty());

  // a complete one replaces the folder whole: no file of the old comparison is left
  ASSERT_EQ(runCli(compareArgs(24, "fkb", dir)).exitCode, 0);
  EXPECT_EQ(resultsWidth(dir), 24);
  EXPECT_FALSE(fs::exists(dir / "vkb_200KB.png"));
  EXPECT_TRUE(stagingBeside(dir).empty());
  fs::remove_all(root);
}

TEST(CompareOutputFolder, AFolderHoldingOtherFilesIsNeverReplaced) {
  const fs::path dir = tempDir() / "foreign";
  fs::remove_all(dir);
  fs::create_directories(dir / "frame_000");
  std::ofstream(dir / "frame_000" / "notes.txt") << "mine";
  const CompareCliRun r = runCli(compareArgs(16, "fkb", dir));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(r.err, "mfr: error: " + dir.string() +
                       ": holds 'frame_000/notes.txt', which a comparison does not write: not "
                       "replacing it (choose another folder)\n");
  EXPECT_TRUE(fs::exists(dir / "frame_000" / "notes.txt"));
  EXPECT_TRUE(stagingBeside(dir).empty());
  fs::remove_all(dir);
}

TEST(CompareOutputFolder, ConcurrentComparesIntoOneFolderLeaveOneWholeComparison) {
  const fs::path root = tempDir() / "concurrent", dir = root / "out";
  fs::remove_all(root);
  fs::create_directories(root);
  // a staging folder of a process that is gone (killed mid-compare) is cleaned up
  fs::create_directories(root / ".out.compare-tmp.999999999.0");
  const std::string a = MFR_CLI_PATH + " " + compareArgs(16, "fkb", dir);
  const std::string b = MFR_CLI_PATH + " " + compareArgs(24, "fkb,vkb", dir);
  const CompareCliRun r = mfr::test::runShell(
      "sh -c '" + a + " & a=$!; " + b + " & b=$!; wait $a && wait $b && echo both'", root);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, "both\n") << r.err;
  // the folder is one of the two, whole: its results.json, images and file set agree
  const int width = resultsWidth(dir);
  ASSERT_TRUE(width == 16 || width == 24) << width;
  auto truth = readPng((dir / "ground_truth.png").string());
  ASSERT_TRUE(truth.ok());
  EXPECT_EQ(truth->width, width);
  EXPECT_EQ(fs::exists(dir / "vkb_200KB.png"), width == 24);
  EXPECT_TRUE(stagingBeside(dir).empty());
  fs::remove_all(root);
}

}  // namespace
}  // namespace mfr
