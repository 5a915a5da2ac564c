// dkb-curve (issue 14 sec. 4, mfr/method/dkb_curve.hpp): the curve representation round-trips
// the curves it can hold, the allocation over predicted curves never exceeds F(M) and equals the
// oracle's hull allocator (allocateOptimalHull) when fed the true curves, and the preset renders
// within its budget on both engines' shared allocation.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numeric>
#include <tuple>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/cpu/dkb_curve_pass.hpp"
#include "mfr/cpu/optimal_oracle.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/dkb_curve.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "mfr/scene/procedural.hpp"
#include "scene/procedural_internal.hpp"

namespace mfr {
namespace {

/// A decreasing curve err(k), k = 1..n, err(n) = 0, with random drops (and, beyond k = 9, the
/// linear tail the representation holds exactly).
std::vector<double> randomCurve(procedural::Rng& rng, uint32_t n) {
  std::vector<double> err(n, 0.0);
  if (n == 0) return err;
  const uint32_t tailStart = std::min<uint32_t>(n, kCurveOutputs);
  const double tail = n > kCurveOutputs ? rng.uniform(0.0f, 0.5f) : 0.0;
  for (uint32_t k = kCurveOutputs; k < n; ++k)
    err[k - 1] = tail * (n - k) / static_cast<double>(n - kCurveOutputs);
  double above = n > kCurveOutputs ? tail : 0.0;
  for (uint32_t k = tailStart - 1; k >= 1; --k) {
    const float u = rng.uniform();
    above += static_cast<double>(u * u * u);  // many small drops, some large, not convex
    err[k - 1] = above;
  }
  return err;
}

/// The targets of every curve as the network would ideally predict them (pixel-major).
std::vector<float> idealPredictions(const std::vector<std::vector<double>>& curves) {
  const double scale = curveScale(curves);
  std::vector<float> out;
  for (const auto& c : curves) {
    const CurveTargets t = curveTargets(c, scale);
    out.insert(out.end(), t.begin(), t.end());
  }
  return out;
}

TEST(DkbCurve, TargetsRoundTripTheCurvesTheRepresentationHolds) {
  procedural::Rng rng(4);
  for (uint32_t n : {1u, 2u, 5u, 9u, 10u, 17u, 40u}) {
    SCOPED_TRACE(n);
    const std::vector<double> curve = randomCurve(rng, n);
    const double scale = curveScale({curve});
    EXPECT_DOUBLE_EQ(scale, n > 1 ? curve.front() : 1.0);
    const CurveTargets t = curveTargets(curve, scale);
    for (float v : t) {
      EXPECT_GE(v, 0.0f);
      EXPECT_LE(v, 1.0f);
    }
    std::vector<double> rebuilt = curveFromPrediction(t.data(), n);
    ASSERT_EQ(rebuilt.size(), n);
    EXPECT_EQ(rebuilt.back(), 0.0);
    for (uint32_t k = 0; k < n; ++k)
      EXPECT_NEAR(rebuilt[k] * scale, curve[k], 1e-5 * std::max(1.0, curve.front())) << k;
  }
}

TEST(DkbCurve, RebuiltCurvesDecreaseToZeroWhateverThePrediction) {
  procedural::Rng rng(6);
  // from k = 1 (kbuffer; sqrt scale, values at most 1) and from k = 0 (hybrid; log scale, values
  // at most 3, and err(n - 1) = 0: a tail of one fragment is exact)
  for (uint32_t firstK : {1u, 0u}) {
    SCOPED_TRACE(firstK);
    for (int trial = 0; trial < 200; ++trial) {
      float p[kCurveOutputs];
      for (float& v : p) v = rng.uniform(-0.5f, 1.5f);
      if (trial % 7 == 0) p[rng.below(kCurveOutputs)] = std::numeric_limits<float>::quiet_NaN();
      const uint32_t n = 1 + rng.below(30);
      const std::vector<double> err = curveFromPrediction(p, n, firstK);
      ASSERT_EQ(err.size(), n + 1 - firstK);
      EXPECT_EQ(err.back(), 0.0);
      if (firstK == 0) {
        EXPECT_EQ(err[n - 1], 0.0) << "a tail of one fragment is exact";
      }
      for (size_t k = 1; k < err.size(); ++k) EXPECT_GE(err[k - 1], err[k]) << "non-increasing";
      const double top = firstK == 0 ? kCurveLogTop : 1.0;
      EXPECT_LE(err.front(), kCurveOutputs * top + 1e-12) << "each value at most " << top;
    }
  }
  EXPECT_TRUE(curveFromPrediction(nullptr, 0).empty());
}

TEST(DkbCurve, AllocationNeverExceedsTheBudgetAndGivesEveryCoveredPixelOneToNSlots) {
  procedural::Rng rng(8);
  for (int trial = 0; trial < 40; ++trial) {
    const size_t pixels = 50 + rng.below(200);
    std::vector<uint32_t> n(pixels);
    std::vector<float> predictions(pixels * kCurveOutputs);
    uint64_t covered = 0, fragments = 0;
    for (size_t p = 0; p < pixels; ++p) {
      n[p] = rng.below(4) == 0 ? 0 : 1 + rng.below(25);
      covered += n[p] > 0;
      fragments += n[p];
    }
    for (float& v : predictions) v = rng.uniform();
    for (uint64_t slots :
         {covered, covered + (fragments - covered) / 3, fragments - 1, fragments, fragments + 10}) {
      const std::vector<uint32_t> k = allocateByPredictedCurves(predictions, n, slots);
      ASSERT_EQ(k.size(), pixels);
      const uint64_t used = std::accumulate(k.begin(), k.end(), uint64_t{0});
      EXPECT_LE(used, slots) << "F(M) exceeded";
      for (size_t p = 0; p < pixels; ++p) {
        if (n[p] == 0) {
          EXPECT_EQ(k[p], 0u);
        } else {
          EXPECT_GE(k[p], 1u);
          EXPECT_LE(k[p], n[p]);
        }
      }
    }
  }
}

TEST(DkbCurve, FedTheTrueCurvesItEqualsTheHullAllocator) {
  procedural::Rng rng(10);
  for (int trial = 0; trial < 20; ++trial) {
    const size_t pixels = 100 + rng.below(100);
    std::vector<std::vector<double>> curves(pixels);
    std::vector<uint32_t> n(pixels);
    uint64_t covered = 0, fragments = 0;
    for (size_t p = 0; p < pixels; ++p) {
      // n <= 9: represented exactly, and random drops leave no ties between pixels' slopes
      n[p] = rng.below(5) == 0 ? 0 : 1 + rng.below(kCurveOutputs);
      curves[p] = randomCurve(rng, n[p]);
      covered += n[p] > 0;
      fragments += n[p];
    }
    const std::vector<float> predictions = idealPredictions(curves);
    for (int step = 0; step <= 4; ++step) {
      const uint64_t slots = covered + (fragments - covered) * step / 4;
      EXPECT_EQ(allocateByPredictedCurves(predictions, n, slots),
                allocateOptimalHull(curves, slots))
          << "trial " << trial << ", slots " << slots;
    }
  }
}

TEST(DkbCurve, OnARealFrameTheTrueCurvesGiveTheHullAllocation) {
  // the oracle's curves of a rendered view, through the representation (exact where n <= 9, the
  // tail linearised beyond): where every pixel has n(p) <= 9 the allocation is the oracle hull's
  auto scene = makeProceduralScene("procedural:city?rows=2&columns=2", 3);
  ASSERT_TRUE(scene);
  RasterOptions ro;
  ro.width = ro.height = 40;
  ro.threads = 1;
  auto frame = RasterFrame::build(*scene, *scene->defaultCamera, ro);
  ASSERT_TRUE(frame);
  auto oracle = frameErrorCurves(frame.value(), glm::vec3(1.0f), Compositing::Hybrid);
  ASSERT_TRUE(oracle);
  ASSERT_LE(*std::max_element(oracle->n.begin(), oracle->n.end()), 9u) << "4 closed boxes";
  const std::vector<float> predictions = idealPredictions(oracle->curves);
  for (int step = 0; step <= 3; ++step) {
    const uint64_t slots =
        oracle->coveredPixels + (oracle->fragments - oracle->coveredPixels) * step / 3;
    // real curves have exact ties (equal pixels, equal drops), broken by rounding here and by
    // order there: the allocations' true errors agree
    const std::vector<uint32_t> k = allocateByPredictedCurves(predictions, oracle->n, slots);
    const double hull = allocationError(oracle->curves, allocateOptimalHull(oracle->curves, slots));
    EXPECT_NEAR(allocationError(oracle->curves, k), hull, 1e-6 * std::max(hull, 1e-12));
    EXPECT_LE(std::accumulate(k.begin(), k.end(), uint64_t{0}), slots);
  }
}

TEST(DkbCurve, PresetRendersWithinItsBudgetUnderBothRules) {
  auto scene = makeProceduralScene("procedural:glassware?count=4&segments=16", 1);
  ASSERT_TRUE(scene);
  for (Compositing rule : {Compositing::Hybrid, Compositing::KBuffer}) {
    SCOPED_TRACE(toString(rule));
    MethodDesc m = methodPreset("dkb-curve").value();
    m.compositing = rule;
    RasterOptions ro;
    ro.width = ro.height = 48;
    auto frame = RasterFrame::build(*scene, *scene->defaultCamera, ro);
    ASSERT_TRUE(frame);
    RenderOptions o;
    o.budgetBytes = 200u << 10;
    auto out = render(frame.value(), m, o);
    ASSERT_TRUE(out) << out.error().message;
    EXPECT_LE(out->stats.bytesUsed, *o.budgetBytes);
    for (size_t p = 0; p < out->kMap.size(); ++p) EXPECT_LE(out->kMap[p], out->depthComplexity[p]);
  }
}

TEST(DkbCurve, ImportanceModelsAndModelsOfTheOtherRuleAreRefused) {
  MethodDesc m = methodPreset("dkb-curve").value();
  m.model = builtinDkbModel(Compositing::Hybrid).value();  // an importance model: 1 output
  auto wrong = dkbModelFor(m);
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.error().message.find("9 outputs"), std::string::npos) << wrong.error().message;
  m.model = builtinDkbCurveModel(Compositing::Hybrid).value();
  EXPECT_TRUE(dkbModelFor(m));
  m.compositing = Compositing::KBuffer;
  EXPECT_FALSE(dkbModelFor(m));
  m.model = nullptr;
  EXPECT_EQ(dkbModelFor(m).value(), builtinDkbCurveModel(Compositing::KBuffer).value());
}

TEST(DkbCurve, CurveDatasetTrainRenderOnTheCommandLine) {
  const std::filesystem::path dir = test::processTempDir("mfr_dkb_curve_cli");
  const auto run = [&](const std::string& args) { return test::runCli(args, dir); };
  const std::string data = (dir / "curve.mfrds").string(), model = (dir / "curve.mfrnn").string();
  auto r =
      run("dataset 'procedural:city?rows=2&columns=3' 'procedural:glassware?count=2&segments=12' "
          "--width 32 --height 32 --orbit 2 --quiet -o " +
          (dir / "importance.mfrds").string() + " --curve-out " + data);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  auto read = learn::readDataset(data);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->targetCount, static_cast<uint32_t>(kCurveOutputs));
  auto importance = learn::readDataset((dir / "importance.mfrds").string());
  ASSERT_TRUE(importance);
  EXPECT_EQ(importance->targetCount, 1u);
  ASSERT_EQ(importance->samples.size(), read->samples.size());
  // the same samples; under hybrid compositing (the default) with dkb-curve's own inputs
  for (size_t i = 0; i < read->samples.size(); ++i) {
    const learn::DatasetSample &a = importance->samples[i], &b = read->samples[i];
    ASSERT_EQ(std::tie(a.scene, a.view, a.budgetStep, a.pixel),
              std::tie(b.scene, b.view, b.budgetStep, b.pixel));
    const float n = std::exp2(4.0f * b.features[0]);  // feature 0 is log2(n(p)) / 4
    ASSERT_GE(n, 1.0f);
    ASSERT_NEAR(n, std::round(n), 1e-3f) << "a whole fragment count";
  }
  const auto declared = [](const learn::Dataset& d, const char* key) {
    return nlohmann::json::parse(d.metadata).at(key).get<std::string>();
  };
  EXPECT_EQ(declared(*read, "features"), kDkbCurveFeatureSet);
  EXPECT_EQ(declared(*read, "target"), kDkbCurveTailOnlyTargetScaling);
  EXPECT_EQ(declared(*importance, "features"), kDkbFeatureSet);
  // under kbuffer compositing the curve samples keep the deep k-buffer's inputs
  const std::string kbufferData = (dir / "curve-kbuffer.mfrds").string();
  r =
      run("dataset 'procedural:city?rows=2&columns=3' --width 32 --height 32 --composite kbuffer "
          "--quiet -o " +
          (dir / "importance-kbuffer.mfrds").string() + " --curve-out " + kbufferData);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  auto kbuffer = learn::readDataset(kbufferData);
  auto kbufferImportance = learn::readDataset((dir / "importance-kbuffer.mfrds").string());
  ASSERT_TRUE(kbuffer && kbufferImportance);
  ASSERT_EQ(kbuffer->samples.size(), kbufferImportance->samples.size());
  for (size_t i = 0; i < kbuffer->samples.size(); ++i)
    ASSERT_EQ(kbuffer->samples[i].features, kbufferImportance->samples[i].features);
  EXPECT_EQ(declared(*kbuffer, "features"), kDkbFeatureSet);
  EXPECT_EQ(declared(*kbuffer, "target"), kDkbCurveTargetScaling);
  r = run("train " + data + " " + (dir / "importance.mfrds").string() + " --epochs 1 --quiet -o " +
          model);
  EXPECT_EQ(r.exitCode, 1) << "importance and curve datasets mixed";
  r = run("train " + data + " --epochs 1 --seed 2 --quiet -o " + model);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  auto trained = learn::readModel(model);
  ASSERT_TRUE(trained);
  EXPECT_EQ(trained->net.sizes, kDkbCurveLayers);
  EXPECT_TRUE(checkDkbCurveModel(trained.value(), model));
  EXPECT_FALSE(checkDkbModel(trained.value(), model)) << "not an importance model";
  const std::string scene = "render 'procedural:city?rows=2&columns=3' --width 32 --height 32 ";
  r = run(scene + "-m dkb-curve -M 40KB --quiet --model " + model + " -o " +
          (dir / "c.png").string());
  EXPECT_EQ(r.exitCode, 0) << r.err;
  r = run(scene + "-m dkb -M 40KB --quiet --model " + model + " -o " + (dir / "d.png").string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("1 output"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mfr
