// mfr dataset: the deep k-buffer's training set (DHOIT sec. 3.1.1): scenes x views x budgets,
// per-pixel features and optimal-k-buffer targets, sampled, written as .mfrds (dataset.hpp).
#include <cstdio>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/dfaoit.hpp"

namespace mfr::cli {
namespace {

struct DatasetArgs {
  std::vector<std::string> scenes;
  SceneOptions scene;
  std::string out;
  int budgetSteps = 5;
  std::vector<std::string> budgets;  // relative shares ("25%"), instead of the steps
  double sample = 0.2;
  std::string composite = "hybrid";
  std::string curveOut;        // also dkb-curve's dataset of the same samples
  std::string target = "dkb";  // dkb: the deep k-buffer's samples; dfaoit: DFAOIT's
  const CLI::App* command = nullptr;
};

int runDataset(DatasetArgs& a) {
  if (a.budgetSteps < 1 || a.budgetSteps > 64)
    return fail("--budget-steps " + std::to_string(a.budgetSteps) + ": must be in [1, 64]");
  if (!(a.sample > 0.0 && a.sample <= 1.0)) return fail("--sample: must be in (0, 1]");
  if (a.out.empty()) return fail("--out: empty path");
  if (auto distinct = checkDistinctOutputs({{"--out", a.out}, {"--curve-out", a.curveOut}});
      !distinct)
    return fail(distinct.error().message);
  if (a.scene.samples != "1" || a.scene.sampleStorage != "pixel")
    return fail(
        "--samples / --sample-storage: mfr dataset samples one fragment set per pixel "
        "centre (the features and targets are single-sample)");
  if (a.target != "dkb" && a.target != "dfaoit")
    return fail("--target " + quoteInput(a.target) + ": expected dkb or dfaoit");
  const bool dfaoit = a.target == "dfaoit";
  if (dfaoit && (!a.budgets.empty() || a.command->count("--budget-steps") > 0 ||
                 a.command->count("--composite") > 0 || !a.curveOut.empty()))
    return fail(
        "--target dfaoit: --budget, --budget-steps, --composite and --curve-out do not "
        "apply (DFAOIT keeps no nodes)");
  learn::Dataset data;
  learn::ViewSamplingOptions sampling;
  sampling.budgetSteps = a.budgetSteps;
  if (!a.budgets.empty() && a.command->count("--budget-steps") > 0)
    return fail("--budget: give either --budget shares or --budget-steps, not both");
  for (const std::string& text : a.budgets) {
    auto spec = parseBudgetSpec(text);
    if (!spec) return fail("--budget: " + spec.error().message);
    if (!spec->isRelative())
      return fail("--budget " + quoteInput(text) +
                  ": mfr dataset takes shares of each view's A-buffer node bytes, e.g. 25%");
    sampling.budgetPercents.push_back(spec->percent);
  }
  sampling.sampleFraction = a.sample;
  sampling.seed = a.scene.seed;
  auto rule = parseCompositing(a.composite);
  if (!rule || !kBufferFamilyRule(rule.value()))
    return fail("--composite " + quoteInput(a.composite) + ": expected kbuffer or hybrid");
  sampling.compositing = rule.value();
  sampling.curveTargets = !a.curveOut.empty();
  // the file stores scene names as UTF-8 (learn::writeDataset refuses others): before any work
  for (const std::string& source : a.scenes)
    if (const size_t bad = invalidUtf8At(source); bad != std::string::npos)
      return fail(echoPath(source) + ": the scene name is not valid UTF-8 (at byte " +
                  std::to_string(bad) + "), which a dataset's scene names must be");
  Progress progress(!a.scene.quiet);
  nlohmann::json perScene = nlohmann::json::array();
  for (const std::string& source : a.scenes) {
    SceneOptions options = a.scene;
    options.source = source;
    progress.set("loading " + source);
    auto prepared = prepareScene(options);
    if (!prepared) return fail(prepared.error().message);
    sampling.background = prepared->scene.background;
    sampling.memoryLimitBytes = options.memoryLimitBytes().value();  // checked by prepareScene
    const uint32_t sceneIndex = static_cast<uint32_t>(data.scenes.size());
    data.scenes.push_back(source);
    const size_t before = data.samples.size();
    const int views = static_cast<int>(prepared->cameras.size());
    for (int v = 0; v < views; ++v) {
      progress.set(source, v, views);
      RasterOptions ro;
      ro.width = options.width;
      ro.height = options.height;
      ro.threads = options.threads;
      auto frame = RasterFrame::build(prepared->scene, prepared->cameras[v], ro);
      if (!frame) return fail(echoPath(source) + ": " + frame.error().message);
      if (dfaoit) {
        const auto samples =
            learn::sampleDfaoitView(frame.value(), sceneIndex, static_cast<uint32_t>(v), sampling);
        data.samples.insert(data.samples.end(), samples.begin(), samples.end());
        continue;
      }
      auto samples =
          learn::sampleView(frame.value(), sceneIndex, static_cast<uint32_t>(v), sampling);
      if (!samples) return fail(echoPath(source) + ": " + samples.error().message);
      data.samples.insert(data.samples.end(), samples->begin(), samples->end());
    }
    perScene.push_back(
        {{"scene", source}, {"views", views}, {"samples", data.samples.size() - before}});
  }
  progress.clear();
  nlohmann::json metadata =
      dfaoit
          ? nlohmann::json{{"generator", "mfr dataset"},    {"method", "dfaoit"},
                           {"features", kDfaoitFeatureSet}, {"target", kDfaoitTarget},
                           {"width", a.scene.width},        {"height", a.scene.height},
                           {"orbit", a.scene.orbit},        {"sample_fraction", a.sample},
                           {"seed", a.scene.seed},          {"scenes", perScene}}
          : nlohmann::json{{"generator", "mfr dataset"},
                           {"features", kDkbFeatureSet},
                           {"target", learn::kDkbTargetScaling},
                           {"composite", toString(sampling.compositing)},
                           {"width", a.scene.width},
                           {"height", a.scene.height},
                           {"orbit", a.scene.orbit},
                           {"budget_steps",
                            a.budgets.empty() ? a.budgetSteps : static_cast<int>(a.budgets.size())},
                           {"sample_fraction", a.sample},
                           {"seed", a.scene.seed},
                           {"scenes", perScene}};
  if (dfaoit) data.targetCount = learn::kDfaoitTargetCount;
  // shares only when given: a dataset made with --budget-steps keeps its bytes
  if (!sampling.budgetPercents.empty()) metadata["budget_percents"] = sampling.budgetPercents;
  data.metadata = metadata.dump();
  auto written = learn::writeDataset(a.out, data);
  if (!written) return fail(written.error().message);
  if (!a.curveOut.empty()) {  // the same samples with dkb-curve's targets
    auto meta = nlohmann::json::parse(data.metadata);
    meta["target"] = dkbCurveTarget(sampling.compositing);
    meta["features"] = dkbCurveFeatureSet(sampling.compositing);
    for (learn::DatasetSample& s : data.samples) s.features = s.curveFeatures;
    data.metadata = meta.dump();
    data.targetCount = kCurveOutputs;
    written = learn::writeDataset(a.curveOut, data);
    if (!written) return fail(written.error().message);
  }
  if (a.scene.json)
    std::printf(
        "%s\n",
        nlohmann::json{{"out", a.out}, {"samples", data.samples.size()}, {"scenes", perScene}}
            .dump(2)
            .c_str());
  else if (!a.scene.quiet)
    std::printf("%s: %zu samples from %zu scenes\n", a.out.c_str(), data.samples.size(),
                data.scenes.size());
  return 0;
}

}  // namespace

Runner addDatasetCommand(CLI::App& app) {
  auto args = std::make_shared<DatasetArgs>();
  args->scene.width = 256;
  args->scene.height = 256;
  CLI::App* cmd = app.add_subcommand(
      "dataset",
      "Build the deep k-buffer's training set: features and optimal targets over scenes x views "
      "(--orbit) x budgets, sampled");
  cmd->add_option("scenes", args->scenes,
                  "Scenes (files or procedural:NAME[?k=v&...]); each one's views are --orbit N "
                  "(or its --view / default camera)")
      ->required();
  args->scene.add(*cmd, false);
  cmd->add_option("--out,-o", args->out, "Output dataset (.mfrds)")->required();
  cmd->add_option("--budget-steps", args->budgetSteps,
                  "Budgets per view, from one fragment per covered pixel to all (default 5)");
  cmd->add_option("--budget,-M", args->budgets,
                  "Budgets as shares of each view's A-buffer node bytes, comma-separated (e.g. "
                  "25%,50%,75%), instead of --budget-steps")
      ->delimiter(',');
  cmd->add_option("--sample", args->sample,
                  "Fraction of covered pixels kept per view and budget (default 0.2)");
  cmd->add_option("--composite", args->composite,
                  "Compositing rule of the optimal targets: hybrid (default) or kbuffer; train "
                  "one model per rule");
  cmd->add_option("--curve-out", args->curveOut,
                  "Also write dkb-curve's dataset: the same samples with each pixel's error curve "
                  "(8 drops and a tail) as targets; under hybrid compositing the curve from k = 0 "
                  "and dkb-curve's own inputs");
  cmd->add_option("--target", args->target,
                  "Which network's samples: dkb (default; the deep k-buffer's features and "
                  "optimal targets) or dfaoit (DFAOIT's features and each pixel's A-buffer "
                  "colour; no budgets)");
  args->command = cmd;
  return [args] { return runDataset(*args); };
}

}  // namespace mfr::cli
