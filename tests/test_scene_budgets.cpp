// Budgets from the scene (issue 48): each method's smallest budget, the budget at which it keeps
// every fragment, its fixed memory and the exact A-buffer's bytes. On stacked quads of known depth
// complexity the numbers are closed-form (recomputed here from the documented per-pixel words,
// docs/MEMORY.md, not from MemoryModel); on every preset, real renders through the CPU engine
// accept the minimum and refuse a byte less, and lose no fragment at the exact budget but some a
// byte below it.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "error_assertions.hpp"
#include "gltf_quads.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/engine/scene_budgets.hpp"
#include "mfr/method/peel.hpp"
#include "mfr/scene/load.hpp"
#include "quad_checks.hpp"

namespace mfr {
namespace {

using test::GltfQuad;

constexpr int kSize = 32;
constexpr uint64_t kPixels = uint64_t{kSize} * kSize;
// the stacked quads (x, y in [-1, 1] fill the view): the bottom half (512 pixels), its left half
// (256) and that half's left half (128): n = 3 on 128 pixels, 2 on 128, 1 on 256, 0 on 512
constexpr uint64_t kCovered = 512, kFragments = 512 + 256 + 128;
constexpr uint32_t kMaxN = 3;

CpuEngine& engine() {
  static CpuEngine cpu(EngineOptions{2, 16});
  return cpu;
}

const Scene& stackedQuads() {
  static const Scene scene = [] {
    const auto m = test::gltfMaterial({0.8, 0.4, 0.2, 0.5}, "BLEND");
    auto loaded =
        test::loadGltfText(test::gltfWithQuads({GltfQuad{-1.0f, -1.0f, 1.0f, 0.0f, -0.2f, m},
                                                GltfQuad{-1.0f, -1.0f, 0.0f, 0.0f, 0.0f, m},
                                                GltfQuad{-1.0f, -1.0f, -0.5f, 0.0f, 0.2f, m}}),
                           "scene_budgets_quads");
    EXPECT_TRUE(loaded.ok()) << loaded.error().message;
    return std::move(loaded.value());
  }();
  return scene;
}

std::unique_ptr<PreparedView> quadsView(int samples = 1) {
  auto view =
      engine().prepare(View{&stackedQuads(), test::headOnQuadCamera(), kSize, kSize, samples});
  EXPECT_TRUE(view.ok()) << view.error().message;
  return std::move(view.value());
}

std::unique_ptr<PreparedView> hairballView() {
  static const Scene scene = loadScene("procedural:hairball?strands=150").value();
  const Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
  return std::move(engine().prepare(View{&scene, camera, 40, 40}).value());
}

MethodDesc preset(const std::string& name) {
  auto m = methodPreset(name);
  EXPECT_TRUE(m.ok()) << name;
  return m.value();
}

Result<RenderOutput> renderAt(const PreparedView& view, const MethodDesc& method, uint64_t budget,
                              RenderOptions options = {}) {
  options.budgetBytes = budget;
  return engine().render(view, method, options);
}

MethodBudget rowOf(const PreparedView& view, const MethodDesc& method, RenderOptions options = {}) {
  auto row = methodBudget(engine(), view, method, options);
  EXPECT_TRUE(row.ok()) << row.error().message;
  return row.value();
}

TEST(SceneBudgets, ClosedFormOnStackedQuads) {
  const auto view = quadsView();
  auto table =
      sceneBudgets(engine(), *view,
                   {preset("abuffer"), preset("fkb"), preset("kplus-sb"), preset("kplus-dynamic"),
                    preset("wboit"), preset("zbuffer"), preset("linked-list"), preset("vkb-fill")},
                   RenderOptions{});
  ASSERT_TRUE(table.ok()) << table.error().message;
  EXPECT_EQ(table->counts.pixels, kPixels);
  EXPECT_EQ(table->counts.coveredPixels, kCovered);
  EXPECT_EQ(table->counts.fragments, kFragments);
  EXPECT_EQ(table->maxDepthComplexity, kMaxN);
  // the A-buffer: counter and offset per pixel, a node of 8 B per fragment
  EXPECT_EQ(table->abufferBytes, kPixels * 8 + kFragments * 8);
  const auto& rows = table->methods;
  ASSERT_EQ(rows.size(), 8u);
  // abuffer: needs every fragment, and that is its fixed memory
  EXPECT_EQ(rows[0].minimumBytes, table->abufferBytes);
  EXPECT_EQ(rows[0].exactBytes, table->abufferBytes);
  EXPECT_EQ(rows[0].fixedBytes, table->abufferBytes);
  // fkb: a counter per pixel; one node per pixel at least, max n(p) nodes per pixel to be exact
  EXPECT_EQ(rows[1].minimumBytes, kPixels * 4 + kPixels * 8);
  EXPECT_EQ(rows[1].exactBytes, kPixels * 4 + kPixels * kMaxN * 8);
  EXPECT_FALSE(rows[1].fixedBytes);
  // kplus-sb: counter, offset, lock; one node per covered pixel; exact once F(M) / |P| >= max n
  EXPECT_EQ(rows[2].minimumBytes, kPixels * 12 + kCovered * 8);
  EXPECT_EQ(rows[2].exactBytes, kPixels * 12 + kPixels * kMaxN * 8);
  // kplus-dynamic: the same words and the 4 KiB histogram; exact at N nodes (k = max n fits)
  EXPECT_EQ(rows[3].minimumBytes, kPixels * 12 + 4096 + kCovered * 8);
  EXPECT_EQ(rows[3].exactBytes, kPixels * 12 + 4096 + kFragments * 8);
  // wboit: 20 B of accumulators per pixel, whatever the budget, never exact
  EXPECT_EQ(rows[4].minimumBytes, kPixels * 20);
  EXPECT_EQ(rows[4].fixedBytes, kPixels * 20);
  EXPECT_FALSE(rows[4].exactBytes);
  EXPECT_TRUE(test::contains(rows[4].note, "never exact")) << rows[4].note;
  EXPECT_EQ(rows[4].minimumPercent, 0.0);  // any share
  // zbuffer: k = 1 fixed, so its memory is fixed and it is never exact here (max n = 3)
  EXPECT_EQ(rows[5].minimumBytes, kPixels * (4 + 4) + kPixels * 8);
  EXPECT_EQ(rows[5].fixedBytes, rows[5].minimumBytes);
  EXPECT_FALSE(rows[5].exactBytes);
  EXPECT_TRUE(test::contains(rows[5].note, "k = 1")) << rows[5].note;
  // linked-list: a head word per pixel, the pool counter, 12 B nodes: one node, or all N
  EXPECT_EQ(rows[6].minimumBytes, kPixels * 4 + 4 + 12);
  EXPECT_EQ(rows[6].exactBytes, kPixels * 4 + 4 + kFragments * 12);
  // vkb-fill: counter, offset, lock, previous |n.v|; exact at N nodes
  EXPECT_EQ(rows[7].minimumBytes, kPixels * 13 + kCovered * 8);
  EXPECT_EQ(rows[7].exactBytes, kPixels * 13 + kFragments * 8);
  // the smallest share: one node per covered pixel of the A-buffer's N nodes (fkb: per pixel)
  EXPECT_NEAR(*rows[1].minimumPercent, 100.0 * kPixels / kFragments, 0.011);
  EXPECT_NEAR(*rows[2].minimumPercent, 100.0 * kCovered / kFragments, 0.011);
}

// Under fragment-parallel capture fkb pays a lock word too; under hybrid compositing kplus-sb
// takes any budget down to its per-pixel words (a pixel without a slot keeps its tail).
TEST(SceneBudgets, FollowsCaptureAndCompositing) {
  const auto view = quadsView();
  RenderOptions parallel;
  parallel.capture = CaptureMode::FragmentParallel;
  const MethodBudget fkb = rowOf(*view, preset("fkb"), parallel);
  EXPECT_EQ(fkb.minimumBytes, kPixels * 8 + kPixels * 8);
  ASSERT_TRUE(renderAt(*view, preset("fkb"), *fkb.minimumBytes, parallel).ok());
  EXPECT_FALSE(renderAt(*view, preset("fkb"), *fkb.minimumBytes - 1, parallel).ok());

  MethodDesc hybrid = preset("kplus-sb");
  hybrid.compositing = Compositing::Hybrid;
  const MethodBudget sb = rowOf(*view, hybrid);
  EXPECT_EQ(sb.minimumBytes, kPixels * (12 + 20));
  EXPECT_EQ(sb.minimumPercent, 0.0);
  EXPECT_TRUE(renderAt(*view, hybrid, *sb.minimumBytes).ok());
  EXPECT_FALSE(renderAt(*view, hybrid, *sb.minimumBytes - 1).ok());
}

// Every preset on two scenes: the minimum renders and a byte less is refused; at the exact budget
// no fragment is lost and a byte less loses some (or is refused, where exact is the minimum).
void checkEveryPreset(const PreparedView& view, const std::string& sceneName) {
  for (const std::string& name : presetNames()) {
    SCOPED_TRACE(sceneName + " " + name);
    const MethodDesc method = preset(name);
    const MethodBudget row = rowOf(view, method);
    ASSERT_TRUE(row.minimumBytes) << row.note;
    auto at = renderAt(view, method, *row.minimumBytes);
    ASSERT_TRUE(at.ok()) << at.error().message;
    if (*row.minimumBytes > 0) {
      auto below = renderAt(view, method, *row.minimumBytes - 1);
      EXPECT_FALSE(below.ok()) << "a byte below the minimum rendered";
    }
    if (!row.exactBytes) {
      EXPECT_FALSE(row.note.empty()) << "no exact budget and no reason";
      continue;
    }
    auto exact = renderAt(view, method, *row.exactBytes);
    ASSERT_TRUE(exact.ok()) << exact.error().message;
    EXPECT_EQ(exact->stats.lost, 0u) << "at " << *row.exactBytes;
    if (*row.exactBytes > *row.minimumBytes) {
      auto short1 = renderAt(view, method, *row.exactBytes - 1);
      ASSERT_TRUE(short1.ok()) << short1.error().message;
      EXPECT_GT(short1->stats.lost, 0u) << "a byte below the exact budget kept every fragment";
    }
  }
}

TEST(SceneBudgets, EveryPresetOnStackedQuads) {
  checkEveryPreset(*quadsView(), "quads");
}

TEST(SceneBudgets, EveryPresetOnHairball) {
  checkEveryPreset(*hairballView(), "hairball");
}

// With +occupancy the words of the occupancy map come on top, and culling never drops a
// fragment once k >= n(p).
TEST(SceneBudgets, OccupancyVariants) {
  const auto view = hairballView();
  for (const char* name : {"fkb+occupancy", "kplus-sb+occupancy", "kplus-dynamic+occupancy"}) {
    SCOPED_TRACE(name);
    const MethodDesc method = preset(name);
    const MethodBudget row = rowOf(*view, method);
    ASSERT_TRUE(row.minimumBytes && row.exactBytes) << row.note;
    EXPECT_TRUE(renderAt(*view, method, *row.minimumBytes).ok());
    EXPECT_FALSE(renderAt(*view, method, *row.minimumBytes - 1).ok());
    auto exact = renderAt(*view, method, *row.exactBytes);
    ASSERT_TRUE(exact.ok());
    EXPECT_EQ(exact->stats.lost, 0u);
    auto below = renderAt(*view, method, *row.exactBytes - 1);
    ASSERT_TRUE(below.ok());
    EXPECT_GT(below->stats.lost, 0u);
  }
}

// Multisampled, per-sample storage: the minimum counts the per-sample words and covered samples.
TEST(SceneBudgets, PerSampleStorage) {
  const auto view = quadsView(4);
  RenderOptions perSample;
  perSample.sampleStorage = SampleStorage::Sample;
  for (const char* name : {"fkb", "kplus-sb", "abuffer"}) {
    SCOPED_TRACE(name);
    const MethodBudget row = rowOf(*view, preset(name), perSample);
    ASSERT_TRUE(row.minimumBytes) << row.note;
    EXPECT_TRUE(renderAt(*view, preset(name), *row.minimumBytes, perSample).ok());
    EXPECT_FALSE(renderAt(*view, preset(name), *row.minimumBytes - 1, perSample).ok());
    ASSERT_TRUE(row.exactBytes) << row.note;
    auto exact = renderAt(*view, preset(name), *row.exactBytes, perSample);
    ASSERT_TRUE(exact.ok());
    EXPECT_EQ(exact->stats.lost, 0u);
  }
  // fkb per sample: 4 samples per pixel, a counter and a node each
  EXPECT_EQ(rowOf(*view, preset("fkb"), perSample).minimumBytes, kPixels * 4 * (4 + 8));
}

TEST(SceneBudgets, AutoBudgetsAreLogSpacedAndTidy) {
  SceneBudgets t;
  t.abufferBytes = 40ull << 20;
  MethodBudget fkb, wboit, none;
  fkb.method = "fkb";
  fkb.minimumBytes = 3'000'000;
  wboit.method = "wboit";
  wboit.minimumBytes = wboit.fixedBytes = 1'000'000;  // fixed: not where the list starts
  none.method = "dfaoit";
  t.methods = {fkb, wboit, none};
  const std::vector<BudgetSpec> list = autoBudgets(t, 5);
  ASSERT_EQ(list.size(), 5u);
  EXPECT_GE(*list.front().bytes, 3'000'000u);
  EXPECT_LT(*list.front().bytes, 3'000'000u * 9 / 8 + 1024);
  EXPECT_EQ(*list.back().bytes, 40ull << 20);
  for (size_t i = 0; i < list.size(); ++i) {
    const uint64_t b = *list[i].bytes;
    EXPECT_EQ(b % std::max<uint64_t>(1024, std::bit_floor(b) / 8), 0u) << b;  // tidy
    EXPECT_EQ(list[i].label, budgetLabel(b));
    if (i > 0) {
      EXPECT_GT(b, *list[i - 1].bytes);
      // log-spaced: each step about (40 MiB / 3 MB)^(1/4) = 1.91, within the rounding
      const double r = static_cast<double>(b) / static_cast<double>(*list[i - 1].bytes);
      EXPECT_GT(r, 1.5);
      EXPECT_LT(r, 2.4);
    }
  }
  // the A-buffer below the smallest minimum: the minimum alone
  t.abufferBytes = 1'000'000;
  const std::vector<BudgetSpec> one = autoBudgets(t, 5);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_GE(*one.front().bytes, 3'000'000u);
  // nothing runs: no list
  t.methods = {none};
  EXPECT_TRUE(autoBudgets(t).empty());
}

TEST(SceneBudgets, AutoBudgetsOfARealFrameRender) {
  const auto view = hairballView();
  auto table = sceneBudgets(engine(), *view,
                            {preset("fkb"), preset("kplus-dynamic"), preset("vkb"), preset("mlab")},
                            RenderOptions{});
  ASSERT_TRUE(table.ok());
  const std::vector<BudgetSpec> list = autoBudgets(*table);
  ASSERT_GE(list.size(), 2u);
  EXPECT_GE(*list.back().bytes, table->abufferBytes);
  // the smallest budget runs the method with the smallest minimum
  uint64_t smallest = UINT64_MAX;
  std::string who;
  for (const MethodBudget& row : table->methods)
    if (row.minimumBytes && *row.minimumBytes < smallest) {
      smallest = *row.minimumBytes;
      who = row.method;
    }
  EXPECT_TRUE(renderAt(*view, preset(who), *list.front().bytes).ok()) << who;
}

TEST(SceneBudgets, BelowMinimumTextNamesTheMinimum) {
  MethodBudget row;
  row.method = "fkb";
  row.minimumBytes = 3u << 20;
  EXPECT_EQ(belowMinimumText(row, "700KB", "512x512"),
            "fkb at 700KB: needs at least 3.00 MiB (3145728 B) at 512x512");
  row.minimumBytes.reset();
  row.note = "refused at any budget: too big";
  EXPECT_EQ(belowMinimumText(row, "700KB", "512x512"),
            "fkb at 700KB: refused at any budget: too big");
}

// The dkb paper rule's exact budget is not a matter of one allocation (its network reads F(M)).
TEST(SceneBudgets, NotesSayWhyNoExactBudget) {
  const auto view = quadsView();
  EXPECT_TRUE(test::contains(rowOf(*view, preset("dkb")).note, "network"));
  EXPECT_TRUE(test::contains(rowOf(*view, preset("mboit")).note, "never exact"));
  MethodDesc peel = preset("peel");
  EXPECT_EQ(rowOf(*view, peel).exactBytes, rowOf(*view, peel).fixedBytes);
  peel.maxPeels = 1;
  EXPECT_FALSE(rowOf(*view, peel).exactBytes);
}

// `mfr info --methods`: the table and its JSON; bad lists are one-line errors.
std::filesystem::path tempDir() {
  return test::processTempDir("mfr_scene_budgets");
}

const std::string kInfoScene = "'procedural:layers?k=1&r=4&pd=0.25' --width 64 --height 64";

TEST(SceneBudgetsCli, InfoMethodsJson) {
  const test::CliRun r = test::runCli(
      "info " + kInfoScene + " --methods fkb,wboit,abuffer --composite kbuffer --json", tempDir());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& view = j["views"][0];
  const auto& b = view["budgets"];
  EXPECT_EQ(b["abuffer_bytes"], view["abuffer_bytes"]);
  const uint64_t pixels = 64 * 64;
  ASSERT_EQ(b["methods"].size(), 3u);
  EXPECT_EQ(b["methods"][0]["method"], "fkb");
  EXPECT_EQ(b["methods"][0]["minimum_bytes"], pixels * 12);
  EXPECT_TRUE(b["methods"][0]["fixed_bytes"].is_null());
  EXPECT_EQ(b["methods"][1]["fixed_bytes"], pixels * 20);
  EXPECT_TRUE(b["methods"][1]["exact_bytes"].is_null());
  EXPECT_EQ(b["methods"][2]["exact_bytes"], b["abuffer_bytes"]);
  // four layers on the covered pixels: fkb exact at 4 nodes per pixel
  EXPECT_EQ(b["methods"][0]["exact_bytes"], pixels * (4 + 4 * 8));
  ASSERT_TRUE(b["auto_budgets"].is_array());
  EXPECT_GE(b["auto_budgets"].size(), 2u);
}

// Without --composite the rows are compare's default runs: each method that takes a rule under
// both, labelled as compare labels them; hybrid's tail words raise the minimum by 20 B a pixel.
TEST(SceneBudgetsCli, InfoMethodsRowsAreComparesRuns) {
  const test::CliRun r =
      test::runCli("info " + kInfoScene + " --methods fkb,wboit,abuffer --json", tempDir());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& rows = j["views"][0]["budgets"]["methods"];
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0]["method"], "fkb-kbuffer");
  EXPECT_EQ(rows[1]["method"], "fkb-hybrid");
  EXPECT_EQ(rows[2]["method"], "wboit");
  EXPECT_EQ(rows[3]["method"], "abuffer");
  EXPECT_EQ(rows[1]["minimum_bytes"].get<uint64_t>() - rows[0]["minimum_bytes"].get<uint64_t>(),
            64u * 64u * 20u);
}

TEST(SceneBudgetsCli, InfoMethodsTable) {
  const test::CliRun r = test::runCli("info " + kInfoScene + " --methods fkb,mboit", tempDir());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(test::contains(r.out, "minimum")) << r.out;
  EXPECT_TRUE(test::contains(r.out, "exact at")) << r.out;
  EXPECT_TRUE(test::contains(r.out, "fkb")) << r.out;
  EXPECT_TRUE(test::contains(r.out, "never exact")) << r.out;
  EXPECT_TRUE(test::contains(r.out, "auto budgets")) << r.out;
  const test::CliRun all = test::runCli("info " + kInfoScene + " --methods all", tempDir());
  ASSERT_EQ(all.exitCode, 0) << all.err;
  for (const std::string& name : presetNames())
    EXPECT_TRUE(test::contains(all.out, name + " ") || test::contains(all.out, name + "-kbuffer "))
        << name;
}

TEST(SceneBudgetsCli, InfoMethodsBadInput) {
  test::CliRun r = test::runCli("info " + kInfoScene + " --methods fkb,kplus-arary", tempDir());
  EXPECT_TRUE(test::cleanError(r, {"kplus-arary", "did you mean 'kplus-array'"}));
  r = test::runCli("info " + kInfoScene + " --methods fkb,,wboit", tempDir());
  EXPECT_TRUE(test::cleanError(r, {"--methods", "empty"}));
  r = test::runCli("info " + kInfoScene + " --methods fkb,fkb", tempDir());
  EXPECT_TRUE(test::cleanError(r, {"--methods", "fkb", "twice"}));
  r = test::runCli("info " + kInfoScene + " --methods ''", tempDir());
  EXPECT_TRUE(test::cleanError(r, {"--methods"}));
  r = test::runCli("info " + kInfoScene + " --methods fkb --composite sideways", tempDir());
  EXPECT_TRUE(test::cleanError(r, {"--composite", "sideways"}));
  r = test::runCli("info " + kInfoScene + " --composite hybrid", tempDir());
  EXPECT_TRUE(test::cleanError(r, {"--composite", "--methods"}));
}

}  // namespace
}  // namespace mfr
