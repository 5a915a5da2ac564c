// Multisampling (core/samples.hpp): the standard sample positions, the coverage the CPU rasterizer
// gives each fragment, the per-sample A-buffer against a supersampled reference computed here,
// both storage disciplines against it when nothing overflows, the budget at 2, 4 and 8 samples,
// the edge statistics and the command line's checks.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/core/samples.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/pass_plan.hpp"
#include "mfr/scene/procedural.hpp"
#include "quad_checks.hpp"
#include "reference_shading.hpp"
#include "test_util.hpp"

namespace {

using mfr::SampleStorage;
using mfr::test::screenRect;
using mfr::test::TestTriangle;

// The Vulkan specification's standard sample locations (table "Standard sample locations"), in
// [0, 1] of the pixel, y down: written here independently of the library's 1/16-pixel table.
const std::map<int, std::vector<glm::dvec2>> kVulkanLocations = {
    {1, {{0.5, 0.5}}},
    {2, {{0.75, 0.75}, {0.25, 0.25}}},
    {4, {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}}},
    {8,
     {{0.5625, 0.3125},
      {0.4375, 0.6875},
      {0.8125, 0.5625},
      {0.3125, 0.1875},
      {0.1875, 0.8125},
      {0.0625, 0.4375},
      {0.6875, 0.9375},
      {0.9375, 0.0625}}},
};

TEST(Samples, StandardPatternsAreVulkansLocations) {
  for (const auto& [count, locations] : kVulkanLocations) {
    const auto pattern = mfr::samplePattern(count);
    ASSERT_EQ(pattern.size(), locations.size()) << count;
    for (size_t s = 0; s < locations.size(); ++s) {
      EXPECT_EQ(0.5 + pattern[s].x / 16.0, locations[s].x) << count << " samples, sample " << s;
      EXPECT_EQ(0.5 + pattern[s].y / 16.0, locations[s].y) << count << " samples, sample " << s;
    }
  }
  for (int bad : {0, 3, 5, 16}) EXPECT_TRUE(mfr::samplePattern(bad).empty()) << bad;
  EXPECT_EQ(mfr::parseSamples("4", "--samples").value(), 4);
  auto three = mfr::parseSamples("3", "--samples");
  ASSERT_FALSE(three.ok());
  EXPECT_EQ(three.error().message, "--samples '3': expected 1, 2, 4 or 8");
  EXPECT_FALSE(mfr::parseSamples("", "--samples").ok());
  EXPECT_EQ(mfr::parseSampleStorage("sample", "--sample-storage").value(), SampleStorage::Sample);
  EXPECT_FALSE(mfr::parseSampleStorage("samples", "--sample-storage").ok());
}

TEST(Samples, CoverageMaskRidesInTheDepthsLowBits) {
  for (int samples : {2, 4, 8}) {
    const uint32_t full = (1u << samples) - 1u;
    for (float z : {0.0f, 1e-30f, 0.25f, 0.7f, 0.99999994f, 1.0f})
      for (uint32_t mask : {1u, full, full >> 1}) {
        const float d = mfr::withCoverage(z, mask, samples);
        EXPECT_EQ(mfr::coverageOf(d, samples), mask);
        EXPECT_LT(d, 1.0f);
        EXPECT_NEAR(d, z, 1e-4f);
      }
    // order of depths kept: a nearer depth stays nearer whatever the masks
    EXPECT_LT(mfr::withCoverage(0.5f, full, samples), mfr::withCoverage(0.5001f, 1u, samples));
  }
}

// Signed area test of point p against the triangle (a, b, c), in double.
double edge(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}
double distanceToSegmentLine(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p) {
  return std::abs(edge(a, b, p)) / glm::length(b - a);
}

struct ScreenTriangle {
  glm::dvec2 v[3];
  // inside: all three edge tests of one sign; ambiguous: within `margin` pixels of an edge line
  // (vertices are snapped to 1/256 pixel, so a sample that close may fall either way)
  bool covers(glm::dvec2 p) const {
    const double e0 = edge(v[0], v[1], p), e1 = edge(v[1], v[2], p), e2 = edge(v[2], v[0], p);
    return (e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0);
  }
  bool ambiguous(glm::dvec2 p, double margin = 0.01) const {
    for (int i = 0; i < 3; ++i)
      if (distanceToSegmentLine(v[i], v[(i + 1) % 3], p) < margin) return true;
    return false;
  }
};

glm::dvec2 samplePoint(int x, int y, int samples, int s) {
  const auto o = mfr::samplePattern(samples)[s];
  return {x + 0.5 + o.x / 16.0, y + 0.5 + o.y / 16.0};
}

TEST(Samples, CoverageOfAHandPlacedTriangle) {
  constexpr int kSize = 16;
  const ScreenTriangle tri{{{2.3, 1.7}, {13.9, 4.2}, {5.1, 14.6}}};
  const mfr::Scene scene =
      mfr::test::makeScene({{mfr::test::screenPoint(tri.v[0].x, tri.v[0].y, kSize),
                             mfr::test::screenPoint(tri.v[1].x, tri.v[1].y, kSize),
                             mfr::test::screenPoint(tri.v[2].x, tri.v[2].y, kSize)}});
  for (int samples : {1, 2, 4, 8})
    for (SampleStorage storage : {SampleStorage::Pixel, SampleStorage::Sample}) {
      mfr::RasterOptions ro{kSize, kSize, 16, 2};
      ro.samples = samples;
      ro.storage = storage;
      auto frame = mfr::RasterFrame::build(scene, mfr::test::screenCamera(), ro);
      ASSERT_TRUE(frame.ok()) << frame.error().message;
      // what the rasterizer says: per image pixel, the mask of covered samples
      std::vector<uint32_t> got(kSize * kSize, 0);
      std::vector<int> fragmentsPerStoragePixel(frame->pixelCount(), 0);
      const bool perPixel = storage == SampleStorage::Pixel || samples == 1;
      for (int tile = 0; tile < frame->tileCount(); ++tile)
        frame->rasterizeTile<mfr::ShadeMode::Full>(
            tile, mfr::EmitAll{[&](const mfr::Fragment& f) {
              ++fragmentsPerStoragePixel[f.pixel];
              if (samples == 1) {
                got[f.pixel] |= 1u;
              } else if (perPixel) {
                got[f.pixel] |= mfr::coverageOf(f.depth, samples);
              } else {
                got[f.pixel / samples] |= 1u << (f.pixel % samples);
              }
            }});
      int checked = 0;
      for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
          const int p = y * kSize + x;
          for (int s = 0; s < samples; ++s) {
            const glm::dvec2 q = samplePoint(x, y, samples, s);
            if (tri.ambiguous(q)) continue;
            ++checked;
            EXPECT_EQ((got[p] >> s) & 1u, tri.covers(q) ? 1u : 0u)
                << samples << " samples, " << mfr::toString(storage) << ": pixel (" << x << ", "
                << y << ") sample " << s;
          }
        }
      EXPECT_GT(checked, kSize * kSize * samples * 9 / 10);
      for (int n : fragmentsPerStoragePixel) EXPECT_LE(n, 1);  // one triangle: one fragment
    }
}

// Three overlapping rectangles at three depths, edges off the pixel grid, over a grey background.
struct Rect {
  double x0, y0, x1, y1;
  float z;
  glm::vec4 color;
};
const std::vector<Rect> kRects = {
    {3.3, 2.6, 20.7, 17.2, 0.0f, {0.9f, 0.2f, 0.1f, 0.5f}},
    {9.1, 8.4, 28.45, 29.3, -0.3f, {0.1f, 0.8f, 0.3f, 0.7f}},
    {1.2, 12.55, 15.8, 26.9, -0.6f, {0.2f, 0.3f, 0.95f, 0.6f}},
};
constexpr int kRectSize = 32;
const glm::dvec3 kGrey(0.5);

mfr::Scene rectScene() {
  std::vector<TestTriangle> triangles;
  for (const Rect& r : kRects)
    for (const TestTriangle& t : screenRect(r.x0, r.y0, r.x1, r.y1, kRectSize, r.z, r.color))
      triangles.push_back(t);
  return mfr::test::makeScene(triangles);
}

bool nearRectEdge(const Rect& r, glm::dvec2 p) {
  const double m = 0.02;
  const bool inY = p.y > r.y0 - m && p.y<r.y1 + m, inX = p.x> r.x0 - m && p.x < r.x1 + m;
  return (inY && (std::abs(p.x - r.x0) < m || std::abs(p.x - r.x1) < m)) ||
         (inX && (std::abs(p.y - r.y0) < m || std::abs(p.y - r.y1) < m)) ||
         ScreenTriangle{{{r.x0, r.y0}, {r.x1, r.y1}, {r.x1, r.y0}}}.ambiguous(p, m);
}

// The supersampled reference, computed here: per sample the rectangles covering it, nearest first
// (z = 0 is nearest), each fragment's colour base * (0.2 + 0.8 |n.v|) at the sample, quantised to
// sRGB8 and its alpha to 8 bits, composited front to back in double; the samples averaged. Pixels
// with a sample near an edge (snapping) are marked unsure.
glm::dvec3 referencePixel(int x, int y, int samples, bool& unsure) {
  glm::dvec3 sum(0.0);
  for (int s = 0; s < samples; ++s) {
    const glm::dvec2 q = samplePoint(x, y, samples, s);
    glm::dvec3 c(0.0);
    double t = 1.0;
    for (const Rect& r : kRects) {  // listed nearest first
      if (nearRectEdge(r, q)) unsure = true;
      if (!(q.x > r.x0 && q.x < r.x1 && q.y > r.y0 && q.y < r.y1)) continue;
      // screenCamera: fov 90, square image: view direction (2 qx / W - 1, 1 - 2 qy / H, -1)
      const double dx = 2.0 * q.x / kRectSize - 1.0, dy = 1.0 - 2.0 * q.y / kRectSize;
      const double cosine = 1.0 / std::sqrt(1.0 + dx * dx + dy * dy);
      const double light = 0.2 + 0.8 * cosine;
      const double a = std::round(r.color.a * 255.0) / 255.0;
      for (int ch = 0; ch < 3; ++ch) {
        const double code = mfr::test::refSrgbCode(r.color[ch] * light);
        c[ch] += t * a * mfr::test::refSrgbDecode(code / 255.0);
      }
      t *= 1.0 - a;
    }
    sum += c + t * kGrey;
  }
  return sum / static_cast<double>(samples);
}

mfr::RenderOutput renderRects(mfr::CpuEngine& engine, int samples, const std::string& preset,
                              SampleStorage storage, std::optional<uint32_t> k = {}) {
  static const mfr::Scene scene = rectScene();
  auto view =
      engine.prepare(mfr::View{&scene, mfr::test::screenCamera(), kRectSize, kRectSize, samples});
  EXPECT_TRUE(view.ok()) << view.error().message;
  mfr::MethodDesc m = mfr::methodPreset(preset).value();
  if (k) m.k = k;
  mfr::RenderOptions o;
  o.background = glm::vec3(kGrey);
  o.sampleStorage = storage;
  auto out = engine.render(**view, m, o);
  EXPECT_TRUE(out.ok()) << out.error().message;
  return std::move(out.value());
}

TEST(Samples, PerSampleAbufferIsTheSupersampledRender) {
  mfr::CpuEngine engine({.threads = 2});
  for (int samples : {1, 2, 4, 8}) {
    const mfr::RenderOutput out = renderRects(engine, samples, "abuffer", SampleStorage::Sample);
    ASSERT_EQ(out.image.width, kRectSize);
    ASSERT_EQ(out.image.height, kRectSize);
    EXPECT_EQ(out.stats.samples, samples);
    int wrong = 0, checked = 0, partial = 0;
    for (int y = 0; y < kRectSize; ++y)
      for (int x = 0; x < kRectSize; ++x) {
        bool unsure = false;
        const glm::dvec3 e = referencePixel(x, y, samples, unsure);
        if (unsure) continue;
        ++checked;
        const glm::vec3 got = out.image.pixels[static_cast<size_t>(y) * kRectSize + x];
        mfr::test::expectLinearPixel(got, e, x, y, wrong);
        // a pixel whose samples disagree: its value lies strictly between theirs
        if (samples > 1 && std::abs(e.r - referencePixel(x, y, 1, unsure).r) > 0.02) ++partial;
      }
    EXPECT_EQ(wrong, 0) << samples << " samples";
    EXPECT_GT(checked, kRectSize * kRectSize * 3 / 4);
    if (samples > 1) {
      EXPECT_GT(partial, 10) << "edges antialiased at " << samples << " samples";
    }
  }
}

TEST(Samples, BothStoragesEqualTheTruthWhenNothingOverflows) {
  mfr::CpuEngine engine({.threads = 2});
  for (int samples : {2, 4, 8}) {
    const mfr::RenderOutput truth = renderRects(engine, samples, "abuffer", SampleStorage::Sample);
    // per sample: every node-storing method that keeps all fragments gives the truth's bits
    for (const char* preset : {"kplus-heap", "kplus-array", "fkb", "linked-list"}) {
      const mfr::RenderOutput out =
          renderRects(engine, samples, preset, SampleStorage::Sample, uint32_t{8});
      EXPECT_EQ(mfr::test::largestDifference(out.image, truth.image), 0.0f)
          << preset << " per sample, " << samples << " samples";
      EXPECT_EQ(out.stats.lost, 0u) << preset;
    }
    // per pixel: one node per fragment with its mask, shaded at its first covered sample; the
    // depth order is the same here, so only the shading position differs (a fraction of a code)
    for (const char* preset : {"abuffer", "kplus-heap", "kplus-array", "fkb", "linked-list"}) {
      const mfr::RenderOutput out =
          renderRects(engine, samples, preset, SampleStorage::Pixel, uint32_t{8});
      EXPECT_EQ(out.stats.sampleStorage, SampleStorage::Pixel);
      EXPECT_LT(mfr::test::largestDifference(out.image, truth.image), 0.01f)
          << preset << " per pixel, " << samples << " samples";
      EXPECT_EQ(out.stats.lost, 0u) << preset;
    }
  }
}

TEST(Samples, FragmentParallelCaptureGivesTheTileOwnedImage) {
  static const mfr::Scene scene = rectScene();
  mfr::CpuEngine engine({.threads = 2});
  auto view = engine.prepare(mfr::View{&scene, mfr::test::screenCamera(), kRectSize, kRectSize, 4});
  ASSERT_TRUE(view.ok());
  mfr::MethodDesc m = mfr::methodPreset("kplus-heap").value();
  m.k = 2;  // the rectangles overlap 3 deep: nearest-two sets, any arrival order
  for (SampleStorage storage : {SampleStorage::Pixel, SampleStorage::Sample}) {
    mfr::RenderOptions o;
    o.sampleStorage = storage;
    auto tile = engine.render(**view, m, o);
    o.capture = mfr::CaptureMode::FragmentParallel;
    auto parallel = engine.render(**view, m, o);
    ASSERT_TRUE(tile.ok() && parallel.ok());
    EXPECT_GT(tile->stats.lost, 0u);
    EXPECT_EQ(mfr::test::largestDifference(tile->image, parallel->image), 0.0f)
        << mfr::toString(storage);
  }
}

TEST(Samples, PerPixelNodesCostLessThanPerSampleNodes) {
  mfr::CpuEngine engine({.threads = 2});
  const mfr::RenderOutput perPixel = renderRects(engine, 4, "abuffer", SampleStorage::Pixel);
  const mfr::RenderOutput perSample = renderRects(engine, 4, "abuffer", SampleStorage::Sample);
  // interior fragments cover all 4 samples: one node instead of four
  EXPECT_LT(perPixel.stats.fragmentSlots * 3, perSample.stats.fragmentSlots);
  EXPECT_LT(perPixel.stats.bytesUsed * 3, perSample.stats.bytesUsed);
  // the per-sample storage's n(p), summed over the samples, is the per-sample A-buffer's nodes
  uint64_t sum = 0;
  for (uint32_t n : perSample.depthComplexity) sum += n;
  EXPECT_EQ(sum, perSample.stats.fragmentSlots);
}

TEST(Samples, EdgeStatisticsSplitTheLostFragments) {
  mfr::CpuEngine engine({.threads = 2});
  for (SampleStorage storage : {SampleStorage::Pixel, SampleStorage::Sample}) {
    const mfr::RenderOutput out = renderRects(engine, 4, "fkb", storage, uint32_t{1});
    const mfr::RenderStats& s = out.stats;
    EXPECT_GT(s.lost, 0u);
    EXPECT_EQ(s.lostAtEdges + s.lostInside, s.lost) << mfr::toString(storage);
    EXPECT_EQ(s.fragmentsAtEdges + s.fragmentsInside, s.fragmentsGenerated);
    uint64_t mapped = 0;
    for (uint32_t l : out.lostPerPixel) mapped += l;
    EXPECT_EQ(mapped, s.lost);
    // the edge pixels: those a triangle's edge crosses (a rectangle's border or its diagonal: a
    // triangle covers some of the samples, not all), counted here from the geometry; a sample
    // near an edge may fall either way
    uint64_t expected = 0, unsure = 0;
    for (int y = 0; y < kRectSize; ++y)
      for (int x = 0; x < kRectSize; ++x) {
        bool edge = false, near = false;
        for (const Rect& r : kRects)
          for (const ScreenTriangle& t :
               {ScreenTriangle{{{r.x0, r.y0}, {r.x1, r.y0}, {r.x1, r.y1}}},
                ScreenTriangle{{{r.x0, r.y0}, {r.x1, r.y1}, {r.x0, r.y1}}}}) {
            int in = 0;
            for (int smp = 0; smp < 4; ++smp) {
              const glm::dvec2 q = samplePoint(x, y, 4, smp);
              in += t.covers(q);
              near = near || t.ambiguous(q);
            }
            edge = edge || (in > 0 && in < 4);
          }
        if (near)
          ++unsure;
        else
          expected += edge;
      }
    EXPECT_GE(s.edgePixels, expected) << mfr::toString(storage);
    EXPECT_LE(s.edgePixels, expected + unsure) << mfr::toString(storage);
    EXPECT_GT(expected, 100u);
  }
}

TEST(Samples, BudgetNeverExceededAtTwoFourAndEightSamples) {
  auto scene = mfr::makeProceduralScene("layers?k=6&r=2&pd=0.55", 1);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  const mfr::Camera camera =
      scene->defaultCamera ? *scene->defaultCamera : mfr::test::screenCamera();
  mfr::CpuEngine engine({.threads = 2});
  for (int samples : {2, 4, 8}) {
    auto view = engine.prepare(mfr::View{&*scene, camera, 48, 40, samples});
    ASSERT_TRUE(view.ok()) << view.error().message;
    auto n = engine.countFragments(**view);
    ASSERT_TRUE(n.ok());
    const mfr::FrameCounts counts = mfr::FrameCounts::of(n.value());
    for (SampleStorage storage : {SampleStorage::Pixel, SampleStorage::Sample})
      for (const char* preset : {"fkb", "kplus-array", "kplus-heap", "kplus-sb", "kplus-dynamic",
                                 "vkb", "dkb", "dkb-curve", "optimal", "linked-list", "mlab"}) {
        const mfr::MethodDesc m = mfr::methodPreset(preset).value();
        mfr::RenderOptions o;
        o.sampleStorage = storage;
        mfr::FrameCounts c = counts;
        c.pixels = (*view)->storagePixels(mfr::sampleStorageOf(m, o));
        auto budget = mfr::resolveBudget(mfr::parseBudgetSpec("60%").value(), m,
                                         engine.memoryModel(m, o), c, "48x40");
        ASSERT_TRUE(budget.ok()) << preset << ": " << budget.error().message;
        o.budgetBytes = budget.value();
        auto out = engine.render(**view, m, o);
        ASSERT_TRUE(out.ok()) << preset << ": " << out.error().message;
        EXPECT_LE(out->stats.bytesUsed, budget.value())
            << preset << ", " << samples << " samples, " << mfr::toString(storage);
        EXPECT_EQ(out->image.width, 48);
        EXPECT_EQ(out->stats.samples, samples);
      }
  }
}

TEST(Samples, PeersAndTheOracleStorePerSample) {
  mfr::CpuEngine engine({.threads = 2});
  mfr::RenderOptions pixel;  // per-pixel storage asked for
  EXPECT_EQ(mfr::sampleStorageOf(mfr::methodPreset("optimal").value(), pixel),
            SampleStorage::Sample);
  EXPECT_EQ(mfr::sampleStorageOf(mfr::methodPreset("dkb-curve").value(), pixel),
            SampleStorage::Pixel);
  EXPECT_EQ(mfr::sampleStorageOf(mfr::methodPreset("kplus-heap").value(), pixel),
            SampleStorage::Pixel);
  for (const char* preset : {"wboit", "mlab", "peel"}) {
    const mfr::RenderOutput out =
        renderRects(engine, 4, preset, SampleStorage::Pixel,
                    std::string(preset) == "mlab" ? std::optional<uint32_t>(8) : std::nullopt);
    EXPECT_EQ(out.stats.sampleStorage, SampleStorage::Sample) << preset;
  }
  // per sample, wboit of one layer is exact: compare it with the truth where one layer covers
  const mfr::RenderOutput truth = renderRects(engine, 4, "abuffer", SampleStorage::Sample);
  const mfr::RenderOutput peel = renderRects(engine, 4, "peel", SampleStorage::Pixel);
  EXPECT_LT(mfr::test::largestDifference(peel.image, truth.image), 1e-5f);
}

// Each (arguments, message) after `common`: exit code 1 and the message on one line of stderr.
void expectOneLineErrors(const std::string& common,
                         std::span<const std::pair<std::string, std::string>> bad,
                         const std::filesystem::path& dir) {
  for (const auto& [args, message] : bad) {
    const mfr::test::CliRun r = mfr::test::runCli(common + args, dir);
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  }
}

TEST(Samples, TheCommandLineChecksItsSampleOptions) {
  const std::filesystem::path dir = mfr::test::processTempDir("mfr_samples");
  const std::string out = (dir / "ms.png").string(), stats = (dir / "ms.json").string();
  const std::string common =
      "render procedural:layers --width 24 --height 20 -q -o " + out + " --stats-json " + stats;
  const mfr::test::CliRun ok = mfr::test::runCli(
      common + " --samples 4 --method kplus-heap --k 2 --composite hybrid --overflow-map " +
          (dir / "overflow.png").string(),
      dir);
  ASSERT_EQ(ok.exitCode, 0) << ok.err;
  std::ifstream in(stats);
  const nlohmann::json parsed = nlohmann::json::parse(in);
  const nlohmann::json& j = parsed.is_array() ? parsed[0] : parsed;
  EXPECT_EQ(j["samples"], 4);
  EXPECT_EQ(j["sample_storage"], "pixel");
  EXPECT_TRUE(std::filesystem::exists(dir / "overflow.png"));
  const std::pair<std::string, std::string> bad[] = {
      {" --samples 3", "--samples '3': expected 1, 2, 4 or 8"},
      {" --samples 2 --sample-storage node", "--sample-storage 'node': expected pixel or sample"},
      {" --overflow-map x.png", "--overflow-map: needs --samples 2, 4 or 8"},
  };
  expectOneLineErrors(common, bad, dir);
  const mfr::test::CliRun dataset =
      mfr::test::runCli("dataset procedural:layers --width 16 --height 16 --samples 4 -q --out " +
                            (dir / "d.mfrds").string(),
                        dir);
  EXPECT_EQ(dataset.exitCode, 1);
  EXPECT_NE(dataset.err.find("--samples / --sample-storage: mfr dataset samples"),
            std::string::npos)
      << dataset.err;
  std::filesystem::remove_all(dir);
}

// compare --sample-counts: every method at each count against that count's own truth, in
// results.json and as the report's error-vs-bytes-per-pixel figure; bad lists are one line.
TEST(Samples, CompareRunsEverySampleCountAndPlotsThem) {
  const std::filesystem::path dir = mfr::test::processTempDir("mfr_sample_counts");
  const std::string common =
      "compare procedural:bottles?count=3 --width 32 --height 24 -q "
      "-m kplus-heap,abuffer -M 40KB,80KB --composite kbuffer -o " +
      (dir / "out").string();
  const mfr::test::CliRun ok = mfr::test::runCli(common + " --sample-counts 1,4", dir);
  ASSERT_EQ(ok.exitCode, 0) << ok.err;
  std::ifstream in(dir / "out" / "results.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["sample_counts"].size(), 2u);
  EXPECT_EQ(j["sample_counts"][0]["samples"], 1);
  EXPECT_EQ(j["sample_counts"][1]["samples"], 4);
  // the 1-sample entry is the main comparison's runs (--samples 1)
  EXPECT_EQ(j["sample_counts"][0]["budgets"][1]["methods"][0]["flip_mean"],
            j["budgets"][1]["methods"][0]["flip_mean"]);
  for (const nlohmann::json& count : j["sample_counts"]) {
    ASSERT_EQ(count["budgets"].size(), 2u);
    const nlohmann::json& heap = count["budgets"][1]["methods"][0];
    ASSERT_EQ(heap["name"], "kplus-heap");
    ASSERT_FALSE(heap.contains("error")) << heap;
    EXPECT_LE(heap["bytes_used"].get<uint64_t>(), 80u << 10);
    EXPECT_EQ(heap["samples"], count["samples"]);
  }
  // per-pixel masks at 4 samples: a triangle's fragment in every pixel it covers a sample of, a
  // superset of the pixels whose centre it covers
  const uint64_t one = j["sample_counts"][0]["budgets"][1]["methods"][0]["fragments_generated"];
  const uint64_t four = j["sample_counts"][1]["budgets"][1]["methods"][0]["fragments_generated"];
  EXPECT_GT(four, one);
  std::ifstream page(dir / "out" / "report.html");
  const std::string html((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("Mean FLIP vs bytes per pixel at 1, 4 samples"), std::string::npos);
  EXPECT_NE(html.find("data-series=\"kplus-heap, 4 samples\""), std::string::npos);
  const std::pair<std::string, std::string> bad[] = {
      {" --sample-counts 1,3", "--sample-counts '3': expected 1, 2, 4 or 8"},
      {" --sample-counts 4,4", "--sample-counts '4,4': 4 listed twice"},
      {" --sample-counts 1,4 --orbit 3", "--sample-counts: not with a temporal comparison"},
  };
  expectOneLineErrors(common, bad, dir);
  std::filesystem::remove_all(dir);
}

}  // namespace
