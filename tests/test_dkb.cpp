// Deep k-buffer: the 12 features against hand-computed values, the runtime importance against an
// independent feature pass + batch inference, the allocation's budget guarantees, the dataset
// (targets, sampling, file round trip and bad files) and model checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include <nlohmann/json.hpp>

#include "mfr/core/color.hpp"
#include "mfr/core/isa.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/cpu/optimal_oracle.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "mfr/scene/load.hpp"
#include "test_util.hpp"

namespace mfr {
namespace {

std::shared_ptr<const learn::Model> randomModel(uint64_t seed) {
  auto model = std::make_shared<learn::Model>();
  model->net = learn::makeMlp(learn::kDkbLayers, seed);
  model->metadata = nlohmann::json{{"features", kDkbFeatureSet}}.dump();
  return model;
}

// window depth of a point at eye distance d (near 0.1, far 10: the screen camera's planes)
double windowDepth(double d) {
  const double n = 0.1, f = 10.0;
  const double ndc = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * d);
  return 0.5 * ndc + 0.5;
}

TEST(DkbFeatures, MatchHandComputedValuesOnTwoOverlappingRectangles) {
  const int size = 8;
  auto tris = test::screenRect(0, 0, 4, 8, size, 0.0f, {1.0f, 0.0f, 0.0f, 0.5f});  // near
  const auto far = test::screenRect(2, 0, 8, 8, size, -1.0f, {0.0f, 0.0f, 1.0f, 1.0f});
  tris.insert(tris.end(), far.begin(), far.end());
  const Scene scene = test::makeScene(tris);
  auto frame = RasterFrame::build(scene, test::screenCamera(), RasterOptions{size, size, 16, 1});
  ASSERT_TRUE(frame);
  // independent record of each pixel's fragments
  std::vector<std::vector<Fragment>> frags(size * size);
  frame->forEachTile([&](int tile) {
    frame->rasterizeTile<ShadeMode::Full>(
        tile, EmitAll{[&](const Fragment& f) { frags[f.pixel].push_back(f); }});
  });
  const auto acc = accumulateFeatures(*frame);
  const ImageFeatureStats image = imageFeatureStats(acc);
  EXPECT_EQ(image.fragments, 80u);  // 4 x 8 + 6 x 8
  EXPECT_EQ(image.coveredPixels, 64u);
  EXPECT_NEAR(image.nearest, windowDepth(1.0), 1e-6);
  EXPECT_NEAR(image.farthest, windowDepth(2.0), 1e-6);
  const uint64_t slots = 100;  // more than the 80 fragments: share clamps at 1
  const auto premul = [](const Fragment& f, int c) {
    return decodeSrgb8(static_cast<uint8_t>(f.rgba >> (8 * c))) * (f.rgba >> 24) / 255.0;
  };
  struct Case {
    int x, y;
    double n, zn, zf;
  };
  for (const Case& c : {Case{1, 3, 1, 0, 0}, Case{3, 3, 2, 0, 1}, Case{6, 5, 1, 1, 1}}) {
    const uint32_t p = c.y * size + c.x;
    ASSERT_EQ(frags[p].size(), static_cast<size_t>(c.n));
    const PixelFeatures f = pixelFeatures(acc[p], image, slots);
    EXPECT_NEAR(f[0], std::log2(1.0 + c.n / 1.25), 1e-6);
    EXPECT_NEAR(f[1], c.zn, 1e-5);
    EXPECT_NEAR(f[2], c.zf, 1e-5);
    const Fragment& nearest = frags[p].front();  // red rectangle was submitted first
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_NEAR(f[3 + ch], premul(nearest, ch), 1e-6);
      double mean = 0.0;
      for (const Fragment& g : frags[p]) mean += premul(g, ch) / c.n;
      EXPECT_NEAR(f[6 + ch], mean, 1e-6);
    }
    EXPECT_EQ(f[9], 1.0f);
    EXPECT_NEAR(f[10], windowDepth(1.0), 1e-6);
    EXPECT_NEAR(f[11], windowDepth(2.0), 1e-6);
  }
  EXPECT_NEAR(pixelFeatures(acc[0], image, 40)[9], 0.5, 1e-7);                 // F / sum n below 1
  EXPECT_EQ(pixelFeatures(FeatureAccumulator{}, image, 40), PixelFeatures{});  // uncovered
}

struct HairballFrame {
  std::unique_ptr<Scene> scene;
  RasterFrame frame;
};

HairballFrame hairball(int threads = 2) {
  auto s = loadScene("procedural:hairball?strands=300");
  auto scene = std::make_unique<Scene>(std::move(s.value()));
  auto frame =
      RasterFrame::build(*scene, *scene->defaultCamera, RasterOptions{96, 96, 16, threads});
  return {std::move(scene), std::move(frame.value())};
}

RenderOutput renderDkb(const RasterFrame& frame, const char* preset, uint64_t budget,
                       uint64_t seed = 3) {
  MethodDesc m = methodPreset(preset).value();
  m.model = randomModel(seed);
  RenderOptions options;
  options.budgetBytes = budget;
  auto out = render(frame, m, options);
  EXPECT_TRUE(out) << (out ? "" : out.error().message);
  return std::move(out.value());
}

TEST(DeepKBuffer, ImportanceEqualsAnIndependentFeaturePassAndBatchInference) {
  const HairballFrame h = hairball();
  const uint64_t budget = 600000;
  const RenderOutput out = renderDkb(h.frame, "dkb", budget);
  const auto model = randomModel(3);
  const auto acc = accumulateFeatures(h.frame);
  const ImageFeatureStats image = imageFeatureStats(acc);
  const uint64_t slots =
      MemoryModel::of(methodPreset("dkb").value()).fragmentSlots(budget, 96 * 96);
  std::vector<float> rows;
  std::vector<size_t> covered;
  for (size_t p = 0; p < acc.size(); ++p) {
    if (acc[p].n == 0) {
      EXPECT_EQ(out.importance.importance[p], 0.0f);
      continue;
    }
    const PixelFeatures f = pixelFeatures(acc[p], image, slots);
    rows.insert(rows.end(), f.begin(), f.end());
    covered.push_back(p);
  }
  ASSERT_GT(covered.size(), 1000u);
  std::vector<float> predicted(covered.size());
  learn::predictRows(model->net, rows.data(), covered.size(), predicted.data());
  for (size_t i = 0; i < covered.size(); ++i)
    ASSERT_NEAR(out.importance.importance[covered[i]], predicted[i], 1e-5) << covered[i];
}

TEST(DeepKBuffer, WideAndScalarPathsPredictTheSameImportanceWithinFloatRounding) {
  if (detectedIsa() == Isa::Scalar) GTEST_SKIP() << "this CPU has neither AVX2 + FMA nor AVX-512";
  const HairballFrame h = hairball();
  const Isa before = activeIsa();
  setActiveIsa(Isa::Scalar);
  const RenderOutput scalar = renderDkb(h.frame, "dkb", 600000);
  setActiveIsa(detectedIsa());
  const RenderOutput wide = renderDkb(h.frame, "dkb", 600000);
  setActiveIsa(before);
  ASSERT_EQ(scalar.importance.importance.size(), wide.importance.importance.size());
  size_t covered = 0;
  for (size_t p = 0; p < wide.importance.importance.size(); ++p) {
    covered += scalar.importance.importance[p] > 0.0f;
    ASSERT_NEAR(wide.importance.importance[p], scalar.importance.importance[p], 1e-5) << p;
  }
  EXPECT_GT(covered, 1000u);
}

TEST(DeepKBuffer, SumOfKNeverExceedsTheBudgetAndFillKeepsOneWhereItCounts) {
  const HairballFrame h = hairball();
  for (const char* preset : {"dkb", "dkb-fill"})
    for (uint64_t budget : {500000ull, 800000ull, 2000000ull}) {
      const RenderOutput out = renderDkb(h.frame, preset, budget);
      const MemoryModel model = MemoryModel::of(methodPreset(preset).value());
      const uint64_t slots = model.fragmentSlots(budget, 96 * 96);
      ASSERT_EQ(out.kMap.size(), 96u * 96u);
      ASSERT_EQ(out.depthComplexity.size(), 96u * 96u);
      uint64_t sumK = 0, demand = 0;
      for (size_t p = 0; p < out.kMap.size(); ++p) {
        sumK += out.kMap[p];
        demand += out.depthComplexity[p];
      }
      ASSERT_GT(demand, 0u) << preset << " " << budget << ": an empty frame tests nothing";
      EXPECT_LE(sumK, slots) << preset << " " << budget;
      // counter, offset, lock, hybrid tail (20 B): no previous-frame normal
      EXPECT_EQ(out.stats.bytesUsed, 96u * 96u * 32u + sumK * 8u) << preset;
      EXPECT_LE(out.stats.bytesUsed, budget);
      if (std::string(preset) == "dkb-fill") {
        EXPECT_EQ(sumK, std::min(slots, demand)) << budget;
        for (size_t p = 0; p < out.kMap.size(); ++p) {
          EXPECT_LE(out.kMap[p], out.depthComplexity[p]);
          // (hybrid compositing: a tail of one fragment is exact, so a pixel of one fragment
          // needs no slot, issue 28)
          if (out.depthComplexity[p] > 1) {
            EXPECT_GE(out.kMap[p], 1u) << "every pixel of two or more fragments keeps one";
          }
        }
      }
    }
}

TEST(DeepKBuffer, PaperRuleFollowsEquation3) {
  const HairballFrame h = hairball();
  const uint64_t budget = 800000;
  const RenderOutput out = renderDkb(h.frame, "dkb", budget);
  const uint64_t slots =
      MemoryModel::of(methodPreset("dkb").value()).fragmentSlots(budget, 96 * 96);
  ASSERT_EQ(out.kMap.size(), 96u * 96u);
  ASSERT_EQ(out.importance.importance.size(), 96u * 96u);
  double sum = 0.0;
  for (float i : out.importance.importance) sum += i;
  ASSERT_GT(sum, 0.0);
  for (size_t p = 0; p < out.kMap.size(); p += 5) {
    const double k = std::floor(out.importance.importance[p] / sum * static_cast<double>(slots));
    EXPECT_NEAR(out.kMap[p], k, 1.0) << p;  // floor of a float sum: off by one at most
  }
}

TEST(DeepKBuffer, UnlimitedBudgetEqualsTheABufferAndThreadsDoNotMatter) {
  const HairballFrame one = hairball(1), two = hairball(2);
  const RenderOutput a = *render(two.frame, methodPreset("abuffer").value(), {});
  const RenderOutput fill = renderDkb(two.frame, "dkb-fill", 1ull << 32);
  EXPECT_EQ(fill.stats.lost, 0u);
  EXPECT_EQ(encodeSrgb(fill.image).rgba, encodeSrgb(a.image).rgba);
  const RenderOutput x = renderDkb(one.frame, "dkb", 700000),
                     y = renderDkb(two.frame, "dkb", 700000);
  EXPECT_EQ(x.importance.importance, y.importance.importance);
  EXPECT_EQ(x.kMap, y.kMap);
}

TEST(DeepKBuffer, ReportsFeatureAndInferencePasses) {
  const HairballFrame h = hairball();
  const RenderOutput out = renderDkb(h.frame, "dkb", 800000);
  std::vector<std::string> names;
  for (const PassTime& p : out.stats.passes) names.push_back(p.name);
  EXPECT_NE(std::find(names.begin(), names.end(), "features"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "inference"), names.end());
}

TEST(DeepKBuffer, RejectsModelsThatDoNotFit) {
  learn::Model wrongShape{learn::makeMlp({12, 8, 2}, 1),
                          std::string(R"({"features":")") + kDkbFeatureSet + "\"}"};
  auto e = checkDkbModel(wrongShape, "m.mfrnn");
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message.find("m.mfrnn"), std::string::npos);
  EXPECT_NE(e.error().message.find("12 inputs and 1 output"), std::string::npos);
  learn::Model noFeatures{learn::makeMlp(learn::kDkbLayers, 1), "{}"};
  auto f = checkDkbModel(noFeatures, "x.mfrnn");
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("feature set"), std::string::npos);
  learn::Model notJson{learn::makeMlp(learn::kDkbLayers, 1), "not json"};
  EXPECT_FALSE(checkDkbModel(notJson, "y.mfrnn"));
  // a method given a bad model fails to render with that message
  const HairballFrame h = hairball();
  MethodDesc m = methodPreset("dkb").value();
  m.model = std::make_shared<learn::Model>(wrongShape);
  RenderOptions o;
  o.budgetBytes = 800000;
  EXPECT_FALSE(render(h.frame, m, o));
}

TEST(DkbDataset, BudgetStepsSpanOneFragmentPerPixelToAll) {
  EXPECT_EQ(learn::budgetStepSlots(100, 500, 0, 5), 100u);
  EXPECT_EQ(learn::budgetStepSlots(100, 500, 2, 5), 300u);
  EXPECT_EQ(learn::budgetStepSlots(100, 500, 4, 5), 500u);
  EXPECT_EQ(learn::budgetStepSlots(100, 500, 0, 1), 500u);
}

TEST(DkbDataset, TargetsAreTheOptimalAllocationOverItsMaximum) {
  const HairballFrame h = hairball();
  learn::ViewSamplingOptions o;
  o.sampleFraction = 1.0;
  auto samples = learn::sampleView(h.frame, 2, 7, o);
  ASSERT_TRUE(samples);
  auto oracle = frameErrorCurves(h.frame, o.background);
  ASSERT_TRUE(oracle);
  ASSERT_GT(oracle->coveredPixels, 0u);
  ASSERT_EQ(samples->size(), 5 * oracle->coveredPixels);  // every covered pixel, 5 budgets
  for (uint32_t step = 0; step < 5; ++step) {
    uint64_t checked = 0;
    const uint64_t slots =
        learn::budgetStepSlots(oracle->coveredPixels, oracle->fragments, step, 5);
    const auto k = allocateOptimalHull(oracle->curves, slots);
    const double kMax = *std::max_element(k.begin(), k.end());
    for (const learn::DatasetSample& s : *samples) {
      if (s.budgetStep != step) continue;
      ASSERT_EQ(s.scene, 2u);
      ASSERT_EQ(s.view, 7u);
      ASSERT_GT(oracle->n[s.pixel], 0u);
      ASSERT_FLOAT_EQ(s.target, static_cast<float>(k[s.pixel] / kMax));
      if (step == 0) {
        ASSERT_EQ(s.target, 1.0f);  // one fragment everywhere
      }
      if (step == 4) {
        ASSERT_EQ(k[s.pixel], oracle->n[s.pixel]);  // every fragment
      }
      ++checked;
    }
    EXPECT_EQ(checked, oracle->coveredPixels) << "step " << step << ": every covered pixel";
  }
}

TEST(DkbDataset, SamplesAboutTheRequestedFractionDeterministically) {
  const HairballFrame one = hairball(1), two = hairball(2);
  learn::ViewSamplingOptions o;
  auto a = learn::sampleView(one.frame, 0, 0, o), b = learn::sampleView(two.frame, 0, 0, o);
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->size(), b->size());
  for (size_t i = 0; i < a->size(); ++i) {
    ASSERT_EQ((*a)[i].pixel, (*b)[i].pixel);
    ASSERT_EQ((*a)[i].features, (*b)[i].features);
    ASSERT_EQ((*a)[i].target, (*b)[i].target);
  }
  auto all = learn::sampleView(one.frame, 0, 0, [] {
    learn::ViewSamplingOptions x;
    x.sampleFraction = 1.0;
    return x;
  }());
  const double fraction = static_cast<double>(a->size()) / all->size();
  EXPECT_NEAR(fraction, 0.2, 0.02);
}

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "mfr_dkb_" + name;
}

learn::Dataset smallDataset() {
  learn::Dataset d;
  d.scenes = {"procedural:layers", "procedural:smoke"};
  d.metadata = R"({"generator":"test"})";
  for (uint32_t i = 0; i < 10; ++i) {
    learn::DatasetSample s;
    s.scene = i % 2;
    s.view = i;
    s.budgetStep = i % 5;
    s.pixel = 1000 + i;
    for (int c = 0; c < kDkbFeatureCount; ++c) s.features[c] = 0.1f * c + i;
    s.target = 0.05f * i;
    d.samples.push_back(s);
  }
  return d;
}

std::string readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(DkbDataset, FileRoundTripsExactly) {
  const learn::Dataset d = smallDataset();
  const std::string path = tempPath("roundtrip.mfrds");
  ASSERT_TRUE(learn::writeDataset(path, d));
  EXPECT_EQ(readBytes(path).size(), 8 + 16 + 4 + 17 + 4 + 16 + 4 + 20 + 8 + 10 * 68u);
  auto back = learn::readDataset(path);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->scenes, d.scenes);
  EXPECT_EQ(back->metadata, d.metadata);
  ASSERT_EQ(back->samples.size(), d.samples.size());
  for (size_t i = 0; i < d.samples.size(); ++i) {
    EXPECT_EQ(back->samples[i].pixel, d.samples[i].pixel);
    EXPECT_EQ(back->samples[i].features, d.samples[i].features);
    EXPECT_EQ(back->samples[i].target, d.samples[i].target);
  }
}

TEST(DkbDataset, BadFilesAreRejectedWithTheirName) {
  const std::string good = tempPath("good.mfrds");
  ASSERT_TRUE(learn::writeDataset(good, smallDataset()));
  const std::string bytes = readBytes(good);
  const std::string bad = tempPath("bad.mfrds");
  auto expectError = [&](const std::string& content, const std::string& word) {
    writeBytes(bad, content);
    auto r = learn::readDataset(bad);
    ASSERT_FALSE(r) << word;
    EXPECT_NE(r.error().message.find(bad), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(word), std::string::npos) << r.error().message;
  };
  expectError("hello", "magic");
  std::string v = bytes;
  v[8] = 9;
  expectError(v, "version 9");
  for (size_t cut : {10ul, 20ul, 40ul, 70ul, bytes.size() - 1, bytes.size() - 68})
    expectError(bytes.substr(0, cut), "truncated");
  expectError(bytes + "x", "trailing");
  std::string nan = bytes;
  const float qnan = std::nanf("");
  std::memcpy(nan.data() + bytes.size() - 8, &qnan, 4);  // last sample's last feature
  expectError(nan, "not a finite number");
  auto missing = learn::readDataset(tempPath("does-not-exist.mfrds"));
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("does-not-exist"), std::string::npos);
}

}  // namespace
}  // namespace mfr
