// Stochastic transparency (stochastic, stochastic-strat; mfr/method/stochastic.hpp) and hashed
// alpha testing (hashed-alpha; hashed_alpha.hpp) against expectations computed here:
//   - the masks: each sample covered with probability alpha; the stratified count floor(a S) or
//     one more with mean a S; alpha 0 and 1 empty and full;
//   - exact cases: alphas of 0 and 1 give the nearest opaque fragment, one layer the over
//     composite;
//   - the expectation: per pixel the estimator's exact distribution is enumerated here from the
//     layers' alphas (the union of the masks in front of each fragment, layer by layer: binomial
//     for the unstratified masks, the two-point count and a hypergeometric overlap for the
//     stratified ones), and the mean over 128 x 128 pixels of the image minus that expectation
//     is within 5 standard errors of 0; the expectation's distance to the exact composite (the
//     ratio's bias) is printed and bounded;
//   - the stratified masks' variance below the unstratified ones', both measured on the same
//     layers and both as enumerated;
//   - hashed alpha: thresholds uniform (a fraction alpha of the points kept, at every blend of
//     the two cell scales), the kept fraction of a layer, the mean image against the composite,
//     the decisions unchanged when the camera moves sideways by whole pixels;
//   - memory as documented (52 and 8 B per pixel, + the lock in fragment-parallel capture), a
//     budget below it refused; the same image for 1 and 2 threads and both capture modes; the
//     command line's render and compare.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "abuffer_fragments.hpp"
#include "cli_runner.hpp"
#include "mfr/core/color.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/hashed_alpha.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/peer_method.hpp"
#include "mfr/method/stochastic.hpp"
#include "mfr/scene/load.hpp"
#include "test_util.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr {
namespace {

const glm::vec3 kBg(0.2f, 0.4f, 0.6f);

struct Layer {
  float z;  // world z of the full-screen plane (further away: more negative)
  glm::vec4 color;
};

RasterFrame frameOf(const std::vector<Layer>& layers, int size,
                    Camera camera = test::screenCamera(), int threads = 2) {
  std::vector<test::TestTriangle> tris;
  for (const Layer& l : layers) {
    // wide enough to cover the view of a camera moved sideways
    const auto r = test::screenRect(-size, -size, 2 * size, 2 * size, size, l.z, l.color);
    tris.insert(tris.end(), r.begin(), r.end());
  }
  return std::move(*test::buildFrame(test::makeScene(tris), camera, size, size, threads));
}

RenderOutput run(const RasterFrame& frame, const std::string& preset,
                 CaptureMode mode = CaptureMode::TileOwned) {
  MethodDesc m = methodPreset(preset).value();
  RenderOptions o;
  o.background = kBg;
  o.keepStores = true;
  o.capture = mode;
  if (m.allocation != AllocationPolicy::Unbounded) o.budgetBytes = 64u << 20;
  auto out = render(frame, m, o);
  EXPECT_TRUE(out.ok()) << preset << ": " << (out.ok() ? "" : out.error().message);
  return std::move(out.value());
}

// A pixel's fragments as the A-buffer captured them, nearest first: linear rgb and alpha.
using Frag = test::AbufferFragment;
std::vector<std::vector<Frag>> fragmentsOf(const RasterFrame& frame) {
  return test::abufferFragments(run(frame, "abuffer"));
}
glm::dvec3 overTruth(const std::vector<Frag>& f) {
  return test::overComposite(f, glm::dvec3(kBg));
}

// ---- the masks ---------------------------------------------------------------------------------

TEST(StochasticMask, EachSampleCoveredWithProbabilityAlpha) {
  constexpr int S = 8, N = 40000;
  for (uint32_t alpha8 : {0u, 1u, 37u, 128u, 200u, 254u, 255u}) {
    const double a = alpha8 / 255.0;
    for (bool stratified : {false, true}) {
      double covered = 0.0;
      std::vector<double> perSample(S, 0.0);
      for (uint32_t i = 0; i < N; ++i) {
        const uint32_t mask = stochasticMask(S, stratified, pcgHash(i * 7919u + 13u), alpha8);
        ASSERT_EQ(mask >> S, 0u);
        const int n = std::popcount(mask);
        covered += n;
        for (int j = 0; j < S; ++j) perSample[j] += (mask >> j) & 1u;
        if (alpha8 == 0) {
          ASSERT_EQ(mask, 0u);
        }
        if (alpha8 == 255) {
          ASSERT_EQ(mask, (1u << S) - 1u);
        }
        if (stratified) {
          // floor(a S) or one more, never another count
          const int low = static_cast<int>(alpha8 * S / 255);
          ASSERT_TRUE(n == low || n == low + 1) << alpha8 << ": " << n;
        }
      }
      // the mean count: binomial (variance S a (1 - a)) or two-point (frac (1 - frac))
      const double frac = a * S - std::floor(a * S);
      const double var = stratified ? frac * (1.0 - frac) : S * a * (1.0 - a);
      EXPECT_NEAR(covered / N, a * S, 5.0 * std::sqrt(var / N) + 1e-12)
          << alpha8 << (stratified ? " stratified" : "");
      for (int j = 0; j < S; ++j)
        EXPECT_NEAR(perSample[j] / N, a, 5.0 * std::sqrt(a * (1.0 - a) / N) + 1e-12)
            << alpha8 << " sample " << j << (stratified ? " stratified" : "");
    }
  }
}

// ---- exact cases -------------------------------------------------------------------------------

TEST(Stochastic, AlphasOfZeroAndOneAreExact) {
  // a clear layer in front, an opaque one, another opaque one behind: the middle one's colour
  const RasterFrame frame = frameOf({{0.0f, {0.9f, 0.1f, 0.1f, 0.0f}},
                                     {-0.3f, {0.1f, 0.8f, 0.2f, 1.0f}},
                                     {-0.6f, {0.1f, 0.2f, 0.9f, 1.0f}}},
                                    16);
  const auto frags = fragmentsOf(frame);
  // (hashed alpha too: alpha 0 is never kept, alpha 1 always)
  for (const char* preset : {"stochastic", "stochastic-strat", "hashed-alpha"}) {
    const RenderOutput out = run(frame, preset);
    for (size_t p = 0; p < frags.size(); ++p) {
      const glm::dvec3 d = glm::abs(glm::dvec3(out.image.pixels[p]) - overTruth(frags[p]));
      ASSERT_LT(std::max({d.x, d.y, d.z}), 1e-6) << preset << " pixel " << p;
    }
  }
  // only clear layers: the background
  const RasterFrame clear = frameOf({{0.0f, {0.9f, 0.1f, 0.1f, 0.0f}}}, 8);
  for (const char* preset : {"stochastic", "stochastic-strat", "hashed-alpha"})
    for (const glm::vec3& px : run(clear, preset).image.pixels) ASSERT_EQ(px, kBg) << preset;
}

TEST(Stochastic, OneLayerIsTheOverComposite) {
  const RasterFrame frame = frameOf({{-0.2f, {0.7f, 0.3f, 0.1f, 0.6f}}}, 16);
  const auto frags = fragmentsOf(frame);
  for (const char* preset : {"stochastic", "stochastic-strat"}) {
    const RenderOutput out = run(frame, preset);
    for (size_t p = 0; p < frags.size(); ++p) {
      ASSERT_EQ(frags[p].size(), 1u);
      const glm::dvec3 d = glm::abs(glm::dvec3(out.image.pixels[p]) - overTruth(frags[p]));
      ASSERT_LT(std::max({d.x, d.y, d.z}), 2e-6) << preset << " pixel " << p;
    }
  }
}

// ---- the expectation ---------------------------------------------------------------------------

double choose(int n, int k) {
  if (k < 0 || k > n) return 0.0;
  double c = 1.0;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
  return c;
}

// One outcome of the S samples over a pixel's layers: its probability and each layer's visibility.
struct Outcome {
  double p;
  std::vector<double> vis;
};

// Every outcome, enumerated layer by layer from the front: u samples are covered by the layers in
// front (vis = (S - u) / S); the next layer's mask adds the samples it covers outside them.
//   unstratified: each of the S - u free samples independently with probability a: binomial;
//   stratified: a uniformly random subset of n samples, n = floor(a S) + [with probability
//     frac(a S)], of which `overlap` fall among the u covered ones: hypergeometric.
std::vector<Outcome> outcomes(int S, bool stratified, const std::vector<double>& alphas) {
  std::vector<Outcome> out;
  std::function<void(size_t, int, double, std::vector<double>&)> walk =
      [&](size_t layer, int u, double p, std::vector<double>& vis) {
        if (p == 0.0) return;
        if (layer == alphas.size()) {
          out.push_back({p, vis});
          return;
        }
        vis.push_back(static_cast<double>(S - u) / S);
        const double a = alphas[layer];
        if (!stratified) {
          for (int k = 0; k <= S - u; ++k)
            walk(layer + 1, u + k,
                 p * choose(S - u, k) * std::pow(a, k) * std::pow(1 - a, S - u - k), vis);
        } else {
          const double frac = a * S - std::floor(a * S);
          const int low = static_cast<int>(std::floor(a * S));
          for (int n : {low, low + 1}) {
            const double pn = n == low ? 1.0 - frac : frac;
            if (n > S || pn == 0.0) continue;
            for (int o = 0; o <= std::min(n, u); ++o)
              walk(layer + 1, u + n - o,
                   p * pn * choose(u, o) * choose(S - u, n - o) / choose(S, n), vis);
          }
        }
        vis.pop_back();
      };
  std::vector<double> vis;
  walk(0, 0, 1.0, vis);
  return out;
}

// The estimator's mean and variance (summed over the channels) at a pixel with these fragments.
struct Moments {
  glm::dvec3 mean;
  double variance;
};
Moments estimatorMoments(const std::vector<Outcome>& all, const std::vector<Frag>& f) {
  double T = 1.0;
  for (const Frag& x : f) T *= 1.0 - x.a;
  glm::dvec3 m(0.0), m2(0.0);
  for (const Outcome& o : all) {
    glm::dvec3 C(0.0);
    double A = 0.0;
    for (size_t i = 0; i < f.size(); ++i) {
      C += o.vis[i] * f[i].a * f[i].c;
      A += o.vis[i] * f[i].a;
    }
    const glm::dvec3 x = A > 0.0 ? C / A * (1.0 - T) + T * glm::dvec3(kBg) : glm::dvec3(kBg);
    m += o.p * x;
    m2 += o.p * x * x;
  }
  const glm::dvec3 var = m2 - m * m;
  return {m, var.x + var.y + var.z};
}

struct Measured {
  double meanError;      // |mean over the pixels of (image - expectation)|, largest channel
  double standardError;  // the standard error of that mean
  double bias;           // largest channel of the mean (expectation - exact composite)
  double variance;       // measured per-pixel variance about the expectation, summed channels
  double predicted;      // the enumerated per-pixel variance, averaged
};

Measured measure(const RasterFrame& frame, const std::string& preset,
                 const std::vector<Outcome>& all) {
  const auto frags = fragmentsOf(frame);
  const RenderOutput out = run(frame, preset);
  glm::dvec3 err(0.0), bias(0.0);
  double var = 0.0, predicted = 0.0;
  for (size_t p = 0; p < frags.size(); ++p) {
    const Moments mo = estimatorMoments(all, frags[p]);
    const glm::dvec3 d = glm::dvec3(out.image.pixels[p]) - mo.mean;
    err += d;
    var += glm::dot(d, d);
    predicted += mo.variance;
    bias += mo.mean - overTruth(frags[p]);
  }
  const double n = static_cast<double>(frags.size());
  err /= n;
  bias /= n;
  return {std::max({std::abs(err.x), std::abs(err.y), std::abs(err.z)}),
          std::sqrt(predicted / n / n),
          std::max({std::abs(bias.x), std::abs(bias.y), std::abs(bias.z)}), var / n, predicted / n};
}

// two layers of the paper's Example 1 (alpha 0.45), a third behind
const std::vector<Layer> kThreeLayers = {{0.0f, {1.0f, 0.05f, 0.05f, 0.45f}},
                                         {-0.4f, {0.05f, 1.0f, 0.05f, 0.45f}},
                                         {-0.8f, {0.3f, 0.3f, 0.9f, 0.6f}}};

TEST(Stochastic, ExpectationConvergesToTheComposite) {
  for (size_t layers : {2u, 3u}) {
    const std::vector<Layer> ls(kThreeLayers.begin(), kThreeLayers.begin() + layers);
    const RasterFrame frame = frameOf(ls, 128);
    std::vector<double> alphas;
    const auto frags = fragmentsOf(frame);
    for (const Frag& f : frags[0]) alphas.push_back(f.a);
    ASSERT_EQ(alphas.size(), layers);
    for (bool stratified : {false, true}) {
      const std::string preset = stratified ? "stochastic-strat" : "stochastic";
      const Measured m = measure(frame, preset, outcomes(8, stratified, alphas));
      std::printf(
          "%s, %zu layers: mean error %.2e (standard error %.2e), bias of the expectation "
          "%.2e, variance %.3e (enumerated %.3e)\n",
          preset.c_str(), layers, m.meanError, m.standardError, m.bias, m.variance, m.predicted);
      // the image's mean is the estimator's expectation within 5 standard errors (plus float)
      EXPECT_LT(m.meanError, 5.0 * m.standardError + 1e-5) << preset << " " << layers;
      // the measured variance is the enumerated one (within 10%: 16384 pixels)
      EXPECT_NEAR(m.variance, m.predicted, 0.1 * m.predicted + 1e-9) << preset << " " << layers;
      // the ratio's bias (exact, from the enumeration): with two layers the front one is always
      // fully visible and the back one's visibility 1 - n/S, n the front's count, nearly constant
      // when stratified (measured: 4.8e-3 and 1.0e-2 unstratified, 5.5e-4 and 2.7e-3 stratified,
      // two and three layers)
      EXPECT_LT(m.bias, stratified ? 4e-3 : 1.5e-2) << preset << " " << layers;
    }
  }
}

TEST(Stochastic, StratifiedMasksHaveLowerVariance) {
  const RasterFrame frame = frameOf(kThreeLayers, 128);
  std::vector<double> alphas;
  const auto frags = fragmentsOf(frame);
  for (const Frag& f : frags[0]) alphas.push_back(f.a);
  const Measured plain = measure(frame, "stochastic", outcomes(8, false, alphas));
  const Measured strat = measure(frame, "stochastic-strat", outcomes(8, true, alphas));
  std::printf(
      "per-pixel variance (sum of channels), 3 layers, S = 8: unstratified %.3e, "
      "stratified %.3e (ratio %.2f)\n",
      plain.variance, strat.variance, plain.variance / strat.variance);
  EXPECT_LT(strat.variance, 0.5 * plain.variance);
  EXPECT_LT(strat.predicted, 0.5 * plain.predicted);
}

// ---- hashed alpha ------------------------------------------------------------------------------

TEST(HashedAlpha, ThresholdsAreUniformAtEveryBlendOfTheTwoScales) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coord(-100.0f, 100.0f);
  constexpr int N = 40000;
  for (float f : {0.0f, 0.25f, 0.5f, 0.9f}) {
    std::vector<float> h(N);
    for (int i = 0; i < N; ++i) {
      const glm::vec3 p(coord(rng), coord(rng), coord(rng));
      // a footprint whose level log2(1 / w) has fractional part f
      const float w = std::exp2(-(static_cast<float>(i % 7) + f));
      h[i] = hashedAlphaThreshold(static_cast<uint32_t>(i % 5), p, w);
      ASSERT_GE(h[i], kHashedAlphaMinThreshold);
      ASSERT_LE(h[i], 1.0f);
    }
    for (double a : {0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0}) {
      double kept = 0.0;
      for (float x : h) kept += static_cast<float>(a) >= x ? 1.0 : 0.0;
      EXPECT_NEAR(kept / N, a, 5.0 * std::sqrt(a * (1.0 - a) / N) + 1e-12)
          << "blend " << f << ", alpha " << a;
    }
  }
}

TEST(HashedAlpha, KeepsAboutAlphaOfALayersFragments) {
  const glm::vec4 colour(0.7f, 0.3f, 0.1f, 0.3f);
  const RasterFrame frame = frameOf({{-0.2f, colour}}, 128);
  const RenderOutput out = run(frame, "hashed-alpha");
  const auto frags = fragmentsOf(frame);
  double kept = 0.0;
  for (size_t p = 0; p < frags.size(); ++p) {
    ASSERT_EQ(out.counts[p], 1u);  // the fragments tested
    // the layer's colour, opaque, or the background
    const glm::vec3 shown = out.image.pixels[p];
    if (shown != kBg) {
      ASSERT_EQ(glm::dvec3(shown), frags[p][0].c) << p;
      kept += 1.0;
    }
  }
  EXPECT_EQ(out.stats.lost, 0u);
  const double n = static_cast<double>(frags.size()), a = frags[0][0].a;
  // cells of one to two pixels: up to 4 pixels share a threshold
  EXPECT_NEAR(kept / n, a, 5.0 * std::sqrt(4.0 * a * (1.0 - a) / n));
  std::printf("hashed-alpha kept %.4f of the fragments, alpha %.4f\n", kept / n, a);
}

TEST(HashedAlpha, ExpectationIsTheComposite) {
  const RasterFrame frame = frameOf(kThreeLayers, 128);
  const auto frags = fragmentsOf(frame);
  const RenderOutput out = run(frame, "hashed-alpha");
  glm::dvec3 err(0.0);
  double var = 0.0;
  for (size_t p = 0; p < frags.size(); ++p) {
    const glm::dvec3 truth = overTruth(frags[p]);
    // what the pixel shows: layer i with probability a_i prod_{j < i} (1 - a_j), else background
    double T = 1.0;
    glm::dvec3 v(0.0);
    for (const Frag& f : frags[p]) {
      v += T * f.a * (f.c - truth) * (f.c - truth);
      T *= 1.0 - f.a;
    }
    v += T * (glm::dvec3(kBg) - truth) * (glm::dvec3(kBg) - truth);
    var += v.x + v.y + v.z;
    err += glm::dvec3(out.image.pixels[p]) - truth;
  }
  const double n = static_cast<double>(frags.size());
  err /= n;
  const double standardError = std::sqrt(4.0 * var / n / n);  // cells shared by up to 4 pixels
  const double worst = std::max({std::abs(err.x), std::abs(err.y), std::abs(err.z)});
  std::printf("hashed-alpha mean error %.2e (standard error %.2e)\n", worst, standardError);
  EXPECT_LT(worst, 5.0 * standardError);
}

TEST(HashedAlpha, DecisionsStayOnTheSurfaceWhenTheCameraMoves) {
  // a layer at distance 1.3 seen head-on; the camera moves 3 pixels' width (at that distance)
  // to the right and 2 down: pixel (x, y) then shows the surface point pixel (x + 3, y + 2)
  // showed (decisions drawn independently would agree at about half the pixels)
  constexpr int size = 64, sx = 3, sy = 2;
  const float distance = 1.3f, pixel = distance * 2.0f / size;
  const RasterFrame before = frameOf({{1.0f - distance, {0.7f, 0.3f, 0.1f, 0.5f}}}, size);
  Camera moved = test::screenCamera();
  moved.eye += glm::vec3(sx * pixel, -sy * pixel, 0.0f);
  moved.target += glm::vec3(sx * pixel, -sy * pixel, 0.0f);
  const RasterFrame after = frameOf({{1.0f - distance, {0.7f, 0.3f, 0.1f, 0.5f}}}, size, moved);
  const RenderOutput a = run(before, "hashed-alpha"), b = run(after, "hashed-alpha");
  int same = 0, compared = 0, keptBefore = 0;
  for (int y = 0; y + sy < size; ++y)
    for (int x = 0; x + sx < size; ++x) {
      const bool k0 = a.image.pixels[static_cast<size_t>((y + sy) * size + x + sx)] != kBg;
      const bool k1 = b.image.pixels[static_cast<size_t>(y * size + x)] != kBg;
      same += k0 == k1 ? 1 : 0;
      keptBefore += k0 ? 1 : 0;
      ++compared;
    }
  std::printf("hashed-alpha after a (%d, %d)-pixel move: %d of %d decisions unchanged\n", sx, sy,
              same, compared);
  EXPECT_GE(same, compared * 99 / 100);
  EXPECT_GT(keptBefore, compared / 4);  // not trivially all dropped
  EXPECT_LT(keptBefore, compared * 3 / 4);
}

// ---- memory, determinism, the command line -----------------------------------------------------

TEST(StochasticPresets, MemoryIsTheDocumentedPerPixelState) {
  const Scene scene = loadScene("procedural:layers?k=4").value();
  for (auto [w, h] : {std::pair{16, 16}, std::pair{40, 24}}) {
    const auto frame = test::buildFrame(scene, *scene.defaultCamera, w, h, 2);
    ASSERT_TRUE(frame);
    const uint64_t P = static_cast<uint64_t>(w) * h;
    for (bool parallel : {false, true}) {
      const uint64_t lock = parallel ? 4 : 0;
      // documented: 8 float depths + T + C + A = 52 B; the z-buffer's depth and colour word 8 B
      const std::pair<const char*, uint64_t> fixed[] = {
          {"stochastic", 52 + lock}, {"stochastic-strat", 52 + lock}, {"hashed-alpha", 8 + lock}};
      for (uint64_t perPixelBudget : {7ull, 12ull, 55ull, 60ull, 200ull}) {
        const uint64_t M = perPixelBudget * P + 13;
        for (const auto& [preset, perPixel] : fixed) {
          const MethodDesc m = methodPreset(preset).value();
          EXPECT_EQ(MemoryModel::of(m, parallel).overhead(P), perPixel * P) << preset;
          RenderOptions o;
          o.budgetBytes = M;
          o.capture = parallel ? CaptureMode::FragmentParallel : CaptureMode::TileOwned;
          auto out = render(*frame, m, o);
          if (perPixel * P > M) {
            ASSERT_FALSE(out.ok()) << preset << " " << M;
            EXPECT_NE(out.error().message.find("too small for " + std::string(preset)),
                      std::string::npos)
                << out.error().message;
            continue;
          }
          ASSERT_TRUE(out.ok()) << preset << ": " << out.error().message;
          EXPECT_EQ(out->stats.bytesUsed, perPixel * P) << preset;
          EXPECT_LE(out->stats.bytesUsed, M) << preset;
          EXPECT_EQ(out->stats.lost, 0u) << preset;
        }
      }
    }
  }
}

TEST(StochasticPresets, SameImageForOneAndTwoThreadsAndEitherCapture) {
  const Scene scene = loadScene("procedural:layers").value();
  const auto one = test::buildFrame(scene, *scene.defaultCamera, 48, 40, 1);
  const auto two = test::buildFrame(scene, *scene.defaultCamera, 48, 40, 2);
  ASSERT_TRUE(one && two);
  for (const char* preset : {"stochastic", "stochastic-strat", "hashed-alpha"}) {
    const RenderOutput a = run(*one, preset), b = run(*two, preset);
    EXPECT_TRUE(a.image.pixels == b.image.pixels) << preset;
    // fragment-parallel: the masks, the depth minima and the z-buffer do not depend on the
    // arrival order; only the stochastic sums' float rounding does
    const RenderOutput c = run(*two, preset, CaptureMode::FragmentParallel);
    float worst = 0.0f;
    for (size_t p = 0; p < a.image.pixels.size(); ++p) {
      const glm::vec3 d = glm::abs(a.image.pixels[p] - c.image.pixels[p]);
      worst = std::max({worst, d.x, d.y, d.z});
    }
    EXPECT_LE(worst, std::string(preset) == "hashed-alpha" ? 0.0f : 1e-5f) << preset;
  }
}

TEST(StochasticPresets, CommandLineRendersAndCompares) {
  const std::filesystem::path dir = test::processTempDir("mfr_stochastic_cli");
  for (const char* preset : {"stochastic", "stochastic-strat", "hashed-alpha"}) {
    const test::CliRun r = test::runCli(
        std::string("render procedural:layers --quiet --width 32 --height 32 --budget 1MB ") +
            "--method " + preset + " -o " + (dir / (std::string(preset) + ".png")).string(),
        dir);
    EXPECT_EQ(r.exitCode, 0) << preset << ": " << r.err;
  }
  const test::CliRun c = test::runCli(
      "compare procedural:layers --quiet --width 32 --height 32 --budget 1MB --methods "
      "stochastic,stochastic-strat,hashed-alpha --out " +
          (dir / "compare").string(),
      dir);
  ASSERT_EQ(c.exitCode, 0) << c.err;
  std::ifstream results(dir / "compare" / "results.json");
  const std::string text((std::istreambuf_iterator<char>(results)), {});
  for (const char* preset : {"\"stochastic\"", "\"stochastic-strat\"", "\"hashed-alpha\""})
    EXPECT_NE(text.find(preset), std::string::npos) << preset;
}

}  // namespace
}  // namespace mfr
