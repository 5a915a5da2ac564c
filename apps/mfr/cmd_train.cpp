// mfr train: trains the deep k-buffer's network (DHOIT sec. 3.1.3) on .mfrds datasets,
// deterministically from a seed, validating on held-out scenes; writes the model (.mfrnn), a
// per-epoch log (CSV) and a PNG loss curve.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/core/atomic_file.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/plot.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/dfaoit.hpp"

namespace mfr::cli {
namespace {

struct TrainArgs {
  std::vector<std::string> datasets;
  std::string out;
  std::string log;
  std::string lossCurve;
  std::vector<std::string> validationScenes;
  std::vector<std::string> validationFamilies;
  learn::TrainOptions train;
  bool quiet = false;
};

struct Split {
  Eigen::MatrixXf trainX, trainY, validX, validY;
  Compositing rule = Compositing::Hybrid;  // of every dataset's targets
  uint32_t targetCount = 1;  // 1: importance, kCurveOutputs: dkb-curve, kDfaoitTargetCount: dfaoit
  std::vector<std::string> trainScenes, validScenes;
  // per dataset, in order: its file name (not the folder, so the model's bytes do not depend on
  // where it was trained) and the FNV-1a 64 of its bytes
  nlohmann::json datasets = nlohmann::json::array();
};

// Loads every dataset and splits the samples by scene name.
Result<Split> loadSplit(const TrainArgs& a) {
  std::vector<learn::Dataset> sets;
  std::vector<std::string> order;  // scene names in order of appearance
  Split split;
  for (const std::string& path : a.datasets) {
    auto data = learn::readDataset(path);
    if (!data) return data.error();
    if (auto ok = learn::checkDatasetDefinitions(data.value(), path); !ok) return ok.error();
    auto rule = learn::datasetRule(data.value(), path);
    if (!rule) return rule.error();
    if (!sets.empty() && rule.value() != split.rule)
      return makeError("dataset " + echoPath(path) + ": targets for " + toString(rule.value()) +
                       " compositing, " + echoPath(a.datasets.front()) + " has " +
                       toString(split.rule) + " (one model per rule: train them separately)");
    split.rule = rule.value();
    if (!sets.empty() && data->targetCount != split.targetCount)
      return makeError("dataset " + echoPath(path) + ": " + std::to_string(data->targetCount) +
                       " targets per sample, " + echoPath(a.datasets.front()) + " has " +
                       std::to_string(split.targetCount) + " (importance and curve datasets " +
                       "train different networks)");
    split.targetCount = data->targetCount;
    split.datasets.push_back({{"file", std::filesystem::path(path).filename().string()},
                              {"fnv1a64", learn::hashHex(data->fileHash)}});
    for (const std::string& s : data->scenes)
      if (std::find(order.begin(), order.end(), s) == order.end()) order.push_back(s);
    sets.push_back(std::move(data.value()));
  }
  std::set<std::string> valid(a.validationScenes.begin(), a.validationScenes.end());
  if (valid.count("none"))
    valid.clear();
  else if (valid.empty() && a.validationFamilies.empty() && order.size() > 1)
    valid.insert(order.back());
  for (const std::string& v : valid)
    if (std::find(order.begin(), order.end(), v) == order.end())
      return makeError("--validation-scene " + quoteInput(v) + ": not in the datasets");
  // a validation split by family: every scene of procedural:NAME, whatever its parameters
  for (const std::string& family : a.validationFamilies) {
    const std::string prefix = "procedural:" + family;
    bool found = false;
    for (const std::string& s : order)
      if (s == prefix || s.starts_with(prefix + "?")) {
        valid.insert(s);
        found = true;
      }
    if (!found)
      return makeError("--validation-family " + quoteInput(family) + ": no " + prefix +
                       " scene in the datasets");
  }
  for (const std::string& s : order)
    (valid.count(s) ? split.validScenes : split.trainScenes).push_back(s);
  if (split.trainScenes.empty()) return makeError("--validation-scene: no scene left to train on");
  size_t trainCount = 0, validCount = 0;
  for (const learn::Dataset& d : sets)
    for (const learn::DatasetSample& s : d.samples)
      (valid.count(d.scenes[s.scene]) ? validCount : trainCount)++;
  if (trainCount == 0) return makeError("the datasets hold no training samples");
  split.trainX.resize(kDkbFeatureCount, static_cast<Eigen::Index>(trainCount));
  const Eigen::Index outputs = static_cast<Eigen::Index>(split.targetCount);
  split.trainY.resize(outputs, static_cast<Eigen::Index>(trainCount));
  split.validX.resize(kDkbFeatureCount, static_cast<Eigen::Index>(validCount));
  split.validY.resize(outputs, static_cast<Eigen::Index>(validCount));
  Eigen::Index t = 0, v = 0;
  for (const learn::Dataset& d : sets)
    for (const learn::DatasetSample& s : d.samples) {
      const bool isValid = valid.count(d.scenes[s.scene]) > 0;
      Eigen::MatrixXf& x = isValid ? split.validX : split.trainX;
      Eigen::MatrixXf& y = isValid ? split.validY : split.trainY;
      const Eigen::Index i = isValid ? v++ : t++;
      for (int c = 0; c < kDkbFeatureCount; ++c) x(c, i) = s.features[c];
      if (outputs == 1)
        y(0, i) = s.target;
      else if (split.targetCount == learn::kDfaoitTargetCount)
        for (Eigen::Index t = 0; t < outputs; ++t) y(t, i) = s.colour[static_cast<size_t>(t)];
      else
        for (Eigen::Index t = 0; t < outputs; ++t) y(t, i) = s.curve[static_cast<size_t>(t)];
    }
  return split;
}

Result<void> writeLossCurve(const std::string& path, const std::vector<learn::EpochLog>& logs,
                            const std::string& title) {
  PlotSeries train{"training MSE", {}, {}, glm::vec3(0.12f, 0.47f, 0.71f)};
  PlotSeries valid{"validation MSE (held-out scenes)", {}, {}, glm::vec3(0.85f, 0.37f, 0.0f)};
  for (const learn::EpochLog& e : logs) {
    train.x.push_back(e.epoch);
    train.y.push_back(e.trainLoss);
    valid.x.push_back(e.epoch);
    valid.y.push_back(e.validationLoss);
  }
  PlotOptions options;
  options.title = title;
  options.xLabel = "epoch";
  options.yLabel = "mean squared error";
  options.logY = true;
  std::vector<PlotSeries> series{train};
  if (std::isfinite(valid.y.front())) series.push_back(valid);
  auto image = plotLines(series, options);
  if (!image) return makeError("--loss-curve " + echoPath(path) + ": " + image.error().message);
  return writePng(path, image.value());
}

int runTrain(TrainArgs& a) {
  const learn::TrainOptions& o = a.train;
  if (o.epochs < 1 || o.epochs > 100000) return fail("--epochs: must be in [1, 100000]");
  if (o.batchSize < 1 || o.batchSize > (1 << 20)) return fail("--batch: must be in [1, 1048576]");
  if (!(o.learningRate > 0.0f && o.learningRate <= 10.0f))
    return fail("--learning-rate: must be in (0, 10]");
  if (!(o.momentum >= 0.0f && o.momentum < 1.0f)) return fail("--momentum: must be in [0, 1)");
  if (!(o.regularization.l1FirstHidden >= 0.0f && o.regularization.l2SecondHidden >= 0.0f))
    return fail("--l1/--l2: must be non-negative numbers");
  if (a.out.empty()) return fail("--out: empty path");
  if (a.log.empty()) a.log = a.out + ".log.csv";
  if (a.lossCurve.empty()) a.lossCurve = a.out + ".loss.png";
  std::vector<OutputFile> inputs;
  for (const std::string& dataset : a.datasets) inputs.push_back({"dataset", dataset});
  if (auto distinct = checkDistinctOutputs(
          {{"--out", a.out}, {"--log", a.log}, {"--loss-curve", a.lossCurve}}, inputs);
      !distinct)
    return fail(distinct.error().message);
  if (auto format = imageOutputFormat("--loss-curve", a.lossCurve, {OutputImageFormat::Png});
      !format)
    return fail(format.error().message);

  auto split = loadSplit(a);
  if (!split) return fail(split.error().message);
  const bool dfaoit = split->targetCount == learn::kDfaoitTargetCount;
  const bool curve = split->targetCount != 1 && !dfaoit;
  const std::vector<int>& layers = dfaoit  ? kDfaoitLayers
                                   : curve ? kDkbCurveLayers
                                           : learn::kDkbLayers;
  learn::Mlp net = learn::makeMlp(layers, o.seed);
  // the log is written (atomically, like every output, its folder made if missing) when
  // training ends; a path whose folder cannot be made fails now, not after the training
  const std::filesystem::path logFolder = std::filesystem::path(a.log).parent_path();
  if (std::error_code ec; !logFolder.empty() && !std::filesystem::is_directory(logFolder, ec) &&
                          !std::filesystem::create_directories(logFolder, ec))
    return fail("--log " + echoPath(a.log) + ": cannot create its folder (" + ec.message() + ")");
  std::ostringstream log;
  log << "epoch,train_mse,validation_mse,seconds\n";
  Progress progress(!a.quiet);
  const auto logs = learn::train(
      net, split->trainX, split->trainY, split->validX, split->validY, o,
      [&](const learn::EpochLog& e) {
        log << e.epoch << ',' << e.trainLoss << ',' << e.validationLoss << ',' << e.seconds << '\n';
        char text[128];
        std::snprintf(text, sizeof text, "training: train %.4g, validation %.4g", e.trainLoss,
                      e.validationLoss);
        progress.set(text, e.epoch, o.epochs);
      });
  progress.clear();
  if (auto written = writeFileAtomically(a.log, log.str()); !written)
    return fail("--log " + written.error().message);
  if (logs.empty() || !std::isfinite(logs.back().trainLoss))
    return fail("training diverged (non-finite loss); lower --learning-rate or --momentum");
  const learn::EpochLog& last = logs.back();
  nlohmann::json meta = {{"features", curve ? dkbCurveFeatureSet(split->rule) : kDkbFeatureSet},
                         {"feature_normalisation", "include/mfr/method/dkb_features.hpp"},
                         {"target", curve ? dkbCurveTarget(split->rule) : learn::kDkbTargetScaling},
                         {"composite", toString(split->rule)},
                         {"layers", layers},
                         {"activations", "relu, relu, sigmoid"},
                         {"training",
                          {{"datasets", split->datasets},
                           {"train_scenes", split->trainScenes},
                           {"validation_scenes", split->validScenes},
                           {"train_samples", split->trainX.cols()},
                           {"validation_samples", split->validX.cols()},
                           {"epochs", o.epochs},
                           {"batch", o.batchSize},
                           {"learning_rate", o.learningRate},
                           {"momentum", o.momentum},
                           {"l1_first_hidden", o.regularization.l1FirstHidden},
                           {"l2_second_hidden", o.regularization.l2SecondHidden},
                           {"seed", o.seed},
                           {"final_train_mse", last.trainLoss},
                           {"final_validation_mse", std::isfinite(last.validationLoss)
                                                        ? nlohmann::json(last.validationLoss)
                                                        : nlohmann::json(nullptr)}}}};
  if (dfaoit) {  // DFAOIT's network (mfr/method/dfaoit.hpp): no compositing rule of its own
    meta.erase("composite");
    meta["method"] = "dfaoit";
    meta["features"] = kDfaoitFeatureSet;
    meta["feature_normalisation"] = "include/mfr/method/method_math.h (dfaoitFeatures)";
    meta["target"] = kDfaoitTarget;
  }
  auto written = learn::writeModel(a.out, learn::Model{net, meta.dump(2)});
  if (!written) return fail(written.error().message);
  if (auto curve = writeLossCurve(a.lossCurve, logs,
                                  dfaoit ? "dfaoit training loss" : "deep k-buffer training loss");
      !curve)
    return fail(curve.error().message);
  if (!a.quiet)
    std::printf("%s: %d epochs, %lld training / %lld validation samples, MSE %.5g / %.5g\n",
                a.out.c_str(), last.epoch, static_cast<long long>(split->trainX.cols()),
                static_cast<long long>(split->validX.cols()), last.trainLoss, last.validationLoss);
  return 0;
}

}  // namespace

Runner addTrainCommand(CLI::App& app) {
  auto args = std::make_shared<TrainArgs>();
  CLI::App* cmd = app.add_subcommand(
      "train",
      "Train the deep k-buffer's (or, on --target dfaoit datasets, DFAOIT's) network on "
      "datasets from mfr dataset (deterministic)");
  cmd->add_option("datasets", args->datasets, "Datasets (.mfrds)")->required();
  cmd->add_option("--out,-o", args->out, "Output model (.mfrnn)")->required();
  cmd->add_option("--log", args->log, "Per-epoch CSV log (default: OUT.log.csv)");
  cmd->add_option("--loss-curve", args->lossCurve, "Loss curve PNG (default: OUT.loss.png)");
  cmd->add_option("--validation-scene", args->validationScenes,
                  "Scene held out for validation (repeatable; default: the last scene; 'none')");
  cmd->add_option("--validation-family", args->validationFamilies,
                  "Hold out every scene of the procedural family NAME (procedural:NAME[?...]) for "
                  "validation (repeatable): a validation split by family");
  cmd->add_option("--epochs", args->train.epochs, "Epochs (default 20)");
  cmd->add_option("--batch", args->train.batchSize, "Mini-batch size (default 512, the paper's)");
  cmd->add_option("--learning-rate", args->train.learningRate,
                  "SGD learning rate (default 1e-3, the paper's)");
  cmd->add_option("--momentum", args->train.momentum, "SGD momentum (default 0: plain SGD)");
  cmd->add_option("--l1", args->train.regularization.l1FirstHidden,
                  "L1 weight on the first hidden layer (default 1e-5)");
  cmd->add_option("--l2", args->train.regularization.l2SecondHidden,
                  "L2 weight on the second hidden layer (default 1e-4)");
  cmd->add_option("--seed", args->train.seed, "Seed of the initial weights and shuffling");
  cmd->add_flag("--quiet,-q", args->quiet, "No progress or summary");
  return [args] { return runTrain(*args); };
}

}  // namespace mfr::cli
