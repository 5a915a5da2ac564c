// Random-configuration sweep under AddressSanitizer + UndefinedBehaviorSanitizer (mfr_asan_tests,
// built against mfr_asan; ctest sets ASAN_OPTIONS=detect_leaks=1, UBSAN_OPTIONS=halt_on_error=1
// and MFR_MAX_WORKERS=8).
//
// Each configuration draws, from a fixed seed: a procedural scene and its parameters (small enough
// to stay fast under the sanitizers), a view of its orbit, a size in 1..96 x 1..96, a preset of
// presetNames() or its +occupancy form, occupancy d, a budget from far too small to huge (or an
// explicit k, or none), kbuffer or hybrid compositing, tile or fragment-parallel capture, the
// variable k-buffer's importance parameters, and two thread counts in 1..8. Every run must either
// fail with a one-line error (the same at both thread counts) or succeed with
//   bytes_used <= budget, fragments generated = captured + lost (nothing lost without a bound),
//   a finite image, and the same output at both thread counts: byte-identical images, k-maps and
//   statistics, except that fragment-parallel capture with hybrid compositing may sum a pixel's
//   tail in a different order, so there the captured nodes, k-map and counts must be identical
//   and the image equal to within float rounding.
// A crash or a sanitizer report aborts the test. The sweep is split into shards so ctest can run
// them in parallel; each shard checks that both outcomes occurred, so it cannot pass vacuously.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "../test_util.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/mboit.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

constexpr int kShards = 8;
constexpr int kRunsPerShard = 100;  // 800 configurations in all
constexpr uint64_t kSweepSeed = 0x5eed2024;
/// Largest difference of a linear colour channel that summation order may cause: hybrid tails
/// and WBOIT's sums composite them directly; MBOIT (4, 6 or 8 moments) reconstructs transmittance
/// from its moments, which amplifies their rounding differences (2e-3 seen in this sweep).
constexpr float kRoundingTolerance = 1e-4f;
constexpr float kMomentRoundingTolerance = 1e-2f;

/// SplitMix64: the same stream on every platform (unlike std:: distributions).
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  /// Integer in [lo, hi].
  int64_t range(int64_t lo, int64_t hi) {
    return lo + static_cast<int64_t>(next() % static_cast<uint64_t>(hi - lo + 1));
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  bool chance(double p) { return uniform() < p; }
  template <class T>
  const T& pick(const std::vector<T>& items) {
    return items[static_cast<size_t>(range(0, static_cast<int64_t>(items.size()) - 1))];
  }

 private:
  uint64_t state_;
};

std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

/// A procedural spec with random, small parameters (a few thousand triangles at most).
std::string randomScene(Rng& rng) {
  const std::string name = rng.pick(proceduralSceneNames());
  std::string spec = "procedural:" + name + "?seed=" + std::to_string(rng.range(0, 1000));
  const auto add = [&](const char* key, const std::string& value) {
    if (rng.chance(0.8)) spec += std::string("&") + key + "=" + value;
  };
  add("alpha", num(rng.uniform(0.0, 1.0)));
  if (name == "layers") {
    add("k", std::to_string(rng.range(1, 16)));
    add("r", std::to_string(rng.range(1, 6)));
    add("pd", num(rng.uniform(0.01, 1.0)));
  } else if (name == "hairball") {
    spec += "&strands=" + std::to_string(rng.range(1, 80));
    add("segments", std::to_string(rng.range(1, 8)));
    add("sides", std::to_string(rng.range(3, 6)));
    add("radius", num(rng.uniform(0.002, 0.1)));
  } else if (name == "smoke") {
    spec += "&count=" + std::to_string(rng.range(1, 400));
    add("size", num(rng.uniform(0.01, 0.5)));
  } else if (name == "bottles") {
    spec += "&count=" + std::to_string(rng.range(1, 4));
    spec += "&segments=" + std::to_string(rng.range(3, 16));
  } else if (name == "spheres") {
    spec += "&count=" + std::to_string(rng.range(1, 24));
    spec += "&detail=" + std::to_string(rng.range(3, 10));
    add("scale", num(rng.uniform(0.1, 3.0)));
  }
  return spec;
}

/// Every preset and every +occupancy form the library accepts.
std::vector<std::string> allMethodNames() {
  std::vector<std::string> names;
  for (const std::string& preset : presetNames()) {
    names.push_back(preset);
    if (methodPreset(preset + "+occupancy").ok()) names.push_back(preset + "+occupancy");
  }
  return names;
}

struct Config {
  std::string describe;
  std::string scene;
  int width = 1, height = 1;
  int orbitViews = 0, orbitView = 0;
  MethodDesc method;
  std::optional<uint64_t> budget;
  CaptureMode capture = CaptureMode::TileOwned;
  int threadsA = 1, threadsB = 2;
};

Config randomConfig(Rng& rng, int index) {
  static const std::vector<std::string> methods = allMethodNames();
  Config c;
  c.scene = randomScene(rng);
  c.width = static_cast<int>(rng.range(1, 96));
  c.height = rng.chance(0.5) ? c.width : static_cast<int>(rng.range(1, 96));
  if (rng.chance(0.3)) {
    c.orbitViews = static_cast<int>(rng.range(2, 12));
    c.orbitView = static_cast<int>(rng.range(0, c.orbitViews - 1));
  }
  // every method in turn (each about 27 times over the sweep), the rest of the draw random
  const std::string& name = methods[static_cast<size_t>(index) % methods.size()];
  c.method = methodPreset(name).value();
  MethodDesc& m = c.method;
  if (kBufferFamilyRule(m.compositing) && rng.chance(0.5))  // the peer methods keep their own
    m.compositing = rng.chance(0.5) ? Compositing::KBuffer : Compositing::Hybrid;
  if (m.occupancyWords > 0)
    m.occupancyWords = static_cast<int>(rng.range(1, rng.chance(0.8) ? 8 : 64));
  const bool takesK = checkMethodOption(MethodOption::K, m).ok();
  const double kind = rng.uniform();
  if (takesK && kind < 0.2) {
    m.k = static_cast<uint32_t>(rng.range(1, 40));
    if (m.name.rfind("zbuffer", 0) == 0) m.k = 1;
  } else if (kind < 0.35) {
    // log-uniform from 16 B (too small for anything) to 64 MiB (everything fits)
    c.budget = static_cast<uint64_t>(std::exp2(rng.uniform(4.0, 26.0)));
  } else if (kind < 0.95) {
    // 4 to 1024 B per pixel: from below one fragment per pixel to ample, mostly with losses
    c.budget = static_cast<uint64_t>(static_cast<double>(c.width) * c.height *
                                     std::exp2(rng.uniform(2.0, 10.0)));
  }  // else no budget: the bounded presets must refuse
  if (m.allocation == AllocationPolicy::Importance &&
      m.importanceSource == ImportanceSource::Heuristic) {
    ImportanceParams& ip = m.importance;
    ip.alpha = static_cast<float>(rng.uniform(0.0, 1.0));
    ip.nLimit = static_cast<float>(rng.uniform(1.0, 64.0));
    ip.peripheryExponent = static_cast<float>(rng.uniform(0.05, 12.0));
    ip.noise = static_cast<float>(rng.uniform(0.0, 1.0));
    if (rng.chance(0.3)) ip.fovea = glm::vec2(rng.uniform(-50.0, 150.0), rng.uniform(-50.0, 150.0));
    ip.seed = rng.next();
    ip.useDepth = rng.chance(0.8);
    ip.usePeriphery = rng.chance(0.8);
    ip.useFresnel = rng.chance(0.8);
    ip.useNoise = rng.chance(0.8);
  }
  c.capture = rng.chance(0.35) ? CaptureMode::FragmentParallel : CaptureMode::TileOwned;
  c.threadsA = static_cast<int>(rng.range(1, 8));
  do c.threadsB = static_cast<int>(rng.range(1, 8));
  while (c.threadsB == c.threadsA);

  c.describe =
      "#" + std::to_string(index) + " " + c.scene + " " + std::to_string(c.width) + "x" +
      std::to_string(c.height) +
      (c.orbitViews ? " orbit " + std::to_string(c.orbitView) + "/" + std::to_string(c.orbitViews)
                    : std::string()) +
      " " + m.name + (m.occupancyWords ? " d=" + std::to_string(m.occupancyWords) : "") + " " +
      toString(m.compositing) +
      (c.capture == CaptureMode::FragmentParallel ? " parallel" : " tile") +
      (m.k ? " k=" + std::to_string(*m.k) : "") +
      (c.budget ? " budget=" + std::to_string(*c.budget) : " no-budget") + " threads " +
      std::to_string(c.threadsA) + "/" + std::to_string(c.threadsB);
  return c;
}

struct Outcome {
  std::optional<RenderOutput> output;
  std::string error;
};

Outcome runOnce(const Scene& scene, const Camera& camera, const Config& c, int threads) {
  RasterOptions ro;
  ro.width = c.width;
  ro.height = c.height;
  ro.threads = threads;
  auto frame = RasterFrame::build(scene, camera, ro);
  if (!frame) return {std::nullopt, frame.error().message};
  RenderOptions options;
  options.budgetBytes = c.budget;
  options.capture = c.capture;
  options.background = scene.background;
  options.keepStores = true;
  auto out = render(frame.value(), c.method, options);
  if (!out) return {std::nullopt, out.error().message};
  return {std::move(out.value()), {}};
}

/// Pixel p's captured nodes, sorted (stores leave them in arrival-dependent order); none for the
/// methods without fragment stores.
std::vector<uint64_t> sortedNodes(const RenderOutput& out, size_t p) {
  std::vector<uint64_t> nodes;
  if (out.nodes.empty() || out.offsets.size() <= p || out.counts.size() <= p) return nodes;
  const uint64_t end = std::min<uint64_t>(out.offsets[p] + out.counts[p], out.nodes.size());
  for (uint64_t i = out.offsets[p]; i < end; ++i) {
    uint64_t bits = 0;
    std::memcpy(&bits, &out.nodes[i], sizeof bits);
    nodes.push_back(bits);
  }
  std::sort(nodes.begin(), nodes.end());
  return nodes;
}

void expectValid(const Config& c, const RenderOutput& out) {
  const RenderStats& s = out.stats;
  EXPECT_EQ(s.fragmentsGenerated, s.captured + s.lost) << c.describe;
  if (c.budget) {
    EXPECT_LE(s.bytesUsed, *c.budget) << c.describe;
  }
  if (c.method.allocation == AllocationPolicy::Unbounded) {
    EXPECT_EQ(s.lost, 0u) << c.describe;
  }
  ASSERT_EQ(out.image.pixels.size(), static_cast<size_t>(c.width) * c.height) << c.describe;
  ASSERT_EQ(out.kMap.size(), out.image.pixels.size()) << c.describe;
  for (const glm::vec3& p : out.image.pixels)
    ASSERT_TRUE(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b)) << c.describe;
  if (c.method.store != StoreChoice::None && c.method.store != StoreChoice::MultiLayer) {
    uint64_t kept = 0;
    for (uint32_t n : out.counts) kept += n;
    EXPECT_EQ(kept, s.captured) << c.describe << ": stored nodes vs fragments_captured";
  }
}

/// How two runs of a configuration at different thread counts may differ. Tile-owned capture
/// delivers each pixel's fragments in primitive order: everything is byte-identical. Fragment-
/// parallel capture delivers them in any order: hybrid tails and the WBOIT / MBOIT sums differ
/// by float summation order only (docs/METHODS.md; MBOIT's reconstruction amplifies it),
/// MLAB's merges depend on the order by design once a pixel has more than k fragments.
enum class Sameness { Exact, RoundingOnly, OrderDependent };

Sameness expectedSameness(const Config& c) {
  if (c.capture == CaptureMode::TileOwned) return Sameness::Exact;
  switch (c.method.compositing) {
    case Compositing::KBuffer:
      return Sameness::Exact;
    case Compositing::MultiLayerAlpha:
    // AOIT's removals (beyond N + 1 fragments a pixel) follow the arrival order
    case Compositing::Adaptive4:
    case Compositing::Adaptive8:
    case Compositing::Adaptive16:
    // the 16-bit moments are re-rounded per fragment: the order decides the codes
    case Compositing::MomentBased16:
    case Compositing::MomentBased6_16:
    case Compositing::MomentBased8_16:
    case Compositing::MomentBasedTrig3_16:
    case Compositing::MomentBasedTrig4_16:
      return Sameness::OrderDependent;
    default:
      return Sameness::RoundingOnly;
  }
}

void expectSameOutput(const Config& c, const RenderOutput& a, const RenderOutput& b) {
  const Sameness same = expectedSameness(c);
  const RenderStats &sa = a.stats, &sb = b.stats;
  EXPECT_EQ(sa.bytesUsed, sb.bytesUsed) << c.describe;
  EXPECT_EQ(sa.fragmentsGenerated, sb.fragmentsGenerated) << c.describe;
  EXPECT_EQ(sa.kMin, sb.kMin) << c.describe;
  EXPECT_EQ(sa.kMax, sb.kMax) << c.describe;
  EXPECT_TRUE(a.kMap == b.kMap) << c.describe << ": k-maps differ";
  if (same == Sameness::OrderDependent) return;
  EXPECT_EQ(sa.captured, sb.captured) << c.describe;
  EXPECT_EQ(sa.lost, sb.lost) << c.describe;
  ASSERT_EQ(a.counts.size(), b.counts.size()) << c.describe;
  for (size_t p = 0; p < a.counts.size(); ++p)
    ASSERT_EQ(sortedNodes(a, p), sortedNodes(b, p)) << c.describe << ": pixel " << p;
  ASSERT_EQ(a.image.pixels.size(), b.image.pixels.size()) << c.describe;
  if (same == Sameness::Exact) {
    EXPECT_EQ(std::memcmp(a.image.pixels.data(), b.image.pixels.data(),
                          a.image.pixels.size() * sizeof(glm::vec3)),
              0)
        << c.describe << ": images differ (largest difference "
        << test::largestDifference(a.image, b.image) << ")";
  } else {
    const float worst = test::largestDifference(a.image, b.image);
    std::fprintf(stderr, "  summation-order difference %g\n", worst);
    // every moment-based rule (mboit, mboit6, mboit8) reconstructs from its moments
    // (the trigonometric ones more: measured 2.5e-2 under a shuffled draw order, test_peer_methods)
    const float tolerance = mboitTrigonometric(c.method.compositing)      ? 5e-2f
                            : mboitMomentCount(c.method.compositing) != 0 ? kMomentRoundingTolerance
                                                                          : kRoundingTolerance;
    EXPECT_LE(worst, tolerance) << c.describe << ": differs beyond float rounding";
  }
}

/// The message with numbers replaced by N, cut at 70 characters: errors of one kind.
std::string errorKind(const std::string& message) {
  std::string kind;
  for (char ch : message) {
    if (std::isdigit(static_cast<unsigned char>(ch))) {
      if (kind.empty() || kind.back() != 'N') kind += 'N';
    } else {
      kind += ch;
    }
  }
  return kind.substr(0, 70);
}

struct Tally {
  int succeeded = 0;
  int failed = 0;
  std::map<std::string, int> errors;  // first words of the messages
};

void runConfig(const Config& c, Tally& tally) {
  std::fprintf(stderr, "%s\n", c.describe.c_str());
  auto scene = loadScene(c.scene);
  ASSERT_TRUE(scene.ok()) << c.describe << ": " << scene.error().message;
  Camera camera = scene->defaultCamera ? *scene->defaultCamera : frameBounds(sceneBounds(*scene));
  if (c.orbitViews > 0) camera = orbit(camera, c.orbitViews)[static_cast<size_t>(c.orbitView)];
  const Outcome a = runOnce(*scene, camera, c, c.threadsA);
  const Outcome b = runOnce(*scene, camera, c, c.threadsB);
  ASSERT_EQ(a.output.has_value(), b.output.has_value())
      << c.describe << ": one thread count failed: " << a.error << b.error;
  if (!a.output) {
    EXPECT_FALSE(a.error.empty()) << c.describe;
    EXPECT_EQ(a.error.find('\n'), std::string::npos) << c.describe << ": " << a.error;
    EXPECT_EQ(a.error, b.error) << c.describe;
    ++tally.failed;
    ++tally.errors[errorKind(a.error)];
    return;
  }
  ++tally.succeeded;
  expectValid(c, *a.output);
  expectValid(c, *b.output);
  expectSameOutput(c, *a.output, *b.output);
}

class Sweep : public ::testing::TestWithParam<int> {};

TEST_P(Sweep, EveryRunSucceedsWithinItsBudgetOrFailsWithOneLine) {
  ::setenv("MFR_MAX_WORKERS", "8", 0);  // ctest sets it; a direct run gets the same
  const int shard = GetParam();
  Rng rng(kSweepSeed + static_cast<uint64_t>(shard));
  Tally tally;
  for (int i = 0; i < kRunsPerShard; ++i) {
    const Config c = randomConfig(rng, shard * kRunsPerShard + i);
    runConfig(c, tally);
    if (HasFatalFailure()) return;
  }
  std::printf("shard %d: %d succeeded, %d failed with a one-line error\n", shard, tally.succeeded,
              tally.failed);
  for (const auto& [what, n] : tally.errors) std::printf("  %3d x %s\n", n, what.c_str());
  EXPECT_GE(tally.succeeded, kRunsPerShard / 3) << "the sweep hardly renders anything";
  EXPECT_GE(tally.failed, 1) << "no configuration exercised an error path";
}

INSTANTIATE_TEST_SUITE_P(Shards, Sweep, ::testing::Range(0, kShards));

}  // namespace
}  // namespace mfr
