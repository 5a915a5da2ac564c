// The GL engine behind the Engine seam (mfr/gl/gl_render_engine.hpp) against the CPU engine
// through the same interface: the statistics both report (bytes_used, fragments generated,
// captured and lost, k range) identical, the images identical for kbuffer compositing and within
// float rounding for hybrid; methods not in the GL engine are one-line errors; `mfr compare
// --engine gl` writes its results. Without a GL 4.5 context the tests skip (fail under CI=true).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "gl_engine_or_skip.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/gl/gl_render_engine.hpp"
#include "mfr/gl/gl_technique.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/scene/load.hpp"
#include "test_paths.hpp"

namespace mfr::gl {
namespace {

// MFR_GL_ENGINE(name): --gl-raster exact, the CPU engine's raster, so the statistics and images are
// the CPU engine's bit for bit (test_gl_native.cpp checks the native pipeline's agreement)
#define MFR_GL_ENGINE(name) MFR_GL_ENGINE_OR_SKIP(name, "auto", "exact")

struct SeamCase {
  const char* scene;
  const char* method;
  Compositing compositing;
  uint64_t budget;
};

class GlSeam : public ::testing::TestWithParam<SeamCase> {};

TEST_P(GlSeam, SameStatisticsAndImageAsTheCpuEngine) {
  MFR_GL_ENGINE(gl);
  const SeamCase& c = GetParam();
  const Scene scene = loadScene(c.scene).value();
  const Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
  const View view{&scene, camera, 96, 80};
  CpuEngine cpu(EngineOptions{2, 16});
  MethodDesc method = methodPreset(c.method).value();
  method.compositing = c.compositing;
  RenderOptions options;
  options.budgetBytes = c.budget;
  options.background = glm::vec3(0.2f, 0.4f, 0.6f);
  // the GL k-buffer stores (fixed or variable k) take a per-pixel lock, like the CPU engine's
  // fragment-parallel capture (the A-buffer appends with atomics: no lock word on either engine in
  // tile-owned mode)
  RenderOptions cpuOptions = options;
  // (mlab charges its lock in either mode: the CPU reference merges in primitive order)
  if (method.allocation != AllocationPolicy::Unbounded && method.store != StoreChoice::MultiLayer)
    cpuOptions.capture = CaptureMode::FragmentParallel;
  auto g = gl->render(view, method, options);
  auto r = cpu.render(view, method, cpuOptions);
  ASSERT_TRUE(g.ok()) << g.error().message;
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(g->stats.engine, "gl");
  EXPECT_EQ(g->stats.bytesUsed, r->stats.bytesUsed);
  EXPECT_EQ(g->stats.bytesByCategory, r->stats.bytesByCategory);
  EXPECT_LE(g->stats.bytesUsed, c.budget);
  EXPECT_EQ(g->stats.fragmentsGenerated, r->stats.fragmentsGenerated);
  EXPECT_EQ(g->stats.captured, r->stats.captured);
  EXPECT_EQ(g->stats.lost, r->stats.lost);
  EXPECT_EQ(g->stats.coveredPixels, r->stats.coveredPixels);
  EXPECT_EQ(g->stats.kMin, r->stats.kMin);
  EXPECT_EQ(g->stats.kMax, r->stats.kMax);
  EXPECT_EQ(g->kMap, r->kMap);
  ASSERT_EQ(g->image.pixels.size(), r->image.pixels.size());
  // kbuffer: the same captured sets, composited operation for operation; hybrid: GLSL pow in the
  // tail; wboit, mboit, mlab: float sums and merges in the fragments' arrival order under the lock
  // (not primitive order), mboit's exp and log in float
  const float tolerance = c.compositing == Compositing::KBuffer  ? 0.0f
                          : c.compositing == Compositing::Hybrid ? 1e-6f
                                                                 : 1.0f / 255.0f;
  size_t worse = 0;
  float maxDiff = 0.0f;
  for (size_t p = 0; p < g->image.pixels.size(); ++p)
    for (int ch = 0; ch < 3; ++ch) {
      const float d = std::abs(g->image.pixels[p][ch] - r->image.pixels[p][ch]);
      worse += d > tolerance;
      maxDiff = std::max(maxDiff, d);
    }
  EXPECT_EQ(worse, 0u) << "channels differing by more than " << tolerance;
  RecordProperty("max_abs_diff", std::to_string(maxDiff));
  RecordProperty("captured_lost",
                 std::to_string(g->stats.captured) + " " + std::to_string(g->stats.lost) + " k " +
                     std::to_string(g->stats.kMin) + ".." + std::to_string(g->stats.kMax));
  std::string timings;
  for (const PassTime& t : g->stats.passes) timings += " " + t.name + " " + std::to_string(t.ms);
  RecordProperty("gl_pass_ms", timings);
}

INSTANTIATE_TEST_SUITE_P(
    Presets, GlSeam,
    ::testing::Values(
        SeamCase{"procedural:layers", "abuffer", Compositing::KBuffer, 4u << 20},
        SeamCase{"procedural:layers", "fkb", Compositing::KBuffer, 160u << 10},
        SeamCase{"procedural:hairball?strands=150", "kplus-array", Compositing::KBuffer,
                 200u << 10},
        SeamCase{"procedural:bottles?count=4", "kplus-heap", Compositing::Hybrid, 400u << 10},
        SeamCase{"procedural:layers", "kplus-array+occupancy", Compositing::KBuffer, 300u << 10},
        SeamCase{"procedural:bottles?count=4", "zbuffer", Compositing::KBuffer, 200u << 10},
        // variable k: n(p) (and |n.v| or the CPU oracle's k(p)) measured, the shared allocate()
        SeamCase{"procedural:layers", "kplus-sb", Compositing::KBuffer, 300u << 10},
        SeamCase{"procedural:hairball?strands=150", "kplus-sb", Compositing::Hybrid, 400u << 10},
        SeamCase{"procedural:layers", "kplus-dynamic", Compositing::KBuffer, 200u << 10},
        SeamCase{"procedural:bottles?count=4", "kplus-dynamic", Compositing::KBuffer, 150u << 10},
        SeamCase{"procedural:layers", "vkb", Compositing::KBuffer, 200u << 10},
        SeamCase{"procedural:layers", "kplus-sb+occupancy", Compositing::KBuffer, 300u << 10},
        SeamCase{"procedural:hairball?strands=150", "vkb+occupancy", Compositing::Hybrid,
                 400u << 10},
        SeamCase{"procedural:hairball?strands=150", "vkb-fill", Compositing::KBuffer, 200u << 10},
        SeamCase{"procedural:bottles?count=4", "vkb", Compositing::Hybrid, 300u << 10},
        SeamCase{"procedural:layers", "optimal", Compositing::Hybrid, 400u << 10},
        // dkb-curve: k(p) from the CPU passes (features, network, hull) on the view's CPU frame
        SeamCase{"procedural:bottles?count=4", "dkb-curve", Compositing::Hybrid, 300u << 10},
        SeamCase{"procedural:layers", "dkb-curve", Compositing::KBuffer, 300u << 10},
        SeamCase{"procedural:hairball?strands=150", "optimal-greedy", Compositing::Hybrid,
                 300u << 10},
        SeamCase{"procedural:layers", "wboit", Compositing::WeightedBlended, 400u << 10},
        SeamCase{"procedural:bottles?count=4", "wboit", Compositing::WeightedBlended, 400u << 10},
        SeamCase{"procedural:layers", "mboit", Compositing::MomentBased, 600u << 10},
        SeamCase{"procedural:hairball?strands=150", "mboit", Compositing::MomentBased, 600u << 10},
        SeamCase{"procedural:hairball?strands=150", "mboit-trig4", Compositing::MomentBasedTrig4,
                 600u << 10},
        SeamCase{"procedural:bottles?count=4", "mboit6-q16", Compositing::MomentBased6_16,
                 600u << 10},
        SeamCase{"procedural:layers", "mlab", Compositing::MultiLayerAlpha, 600u << 10},
        SeamCase{"procedural:bottles?count=4", "mlab", Compositing::MultiLayerAlpha, 300u << 10},
        // linked lists with a pool that holds every fragment: the same sorted lists (the atomic
        // counter's node order is GL's own, the resolve sorts); overflow: test_gl_linked_list.cpp
        SeamCase{"procedural:hairball?strands=150", "linked-list", Compositing::KBuffer, 4u << 20},
        SeamCase{"procedural:bottles?count=4", "linked-list", Compositing::Hybrid, 4u << 20}),
    [](const auto& info) {
      std::string name = std::string(info.param.method) + "_" +
                         std::string(toString(info.param.compositing)) + "_" +
                         std::to_string(info.index);
      for (char& ch : name)
        if (ch == '-' || ch == '+') ch = '_';
      return name;
    });

// Every preset (and its +occupancy form) on both engines: every shared statistic (what
// fillSharedStats defines for both) identical. The deep k-buffer's importance is float rounding
// apart on the two engines (see GlSeamDeep below), so its k(p) may differ at a few pixels: its
// counts and bytes are compared within those pixels' slots.
TEST(GlSeamEveryPreset, SharedStatisticsEqualTheCpuEngines) {
  MFR_GL_ENGINE(gl);
  const Scene scene = loadScene("procedural:bottles?count=3").value();
  const View view{&scene, *scene.defaultCamera, 48, 40};
  CpuEngine cpu(EngineOptions{2, 16});
  int checked = 0;
  for (const std::string& base : presetNames())
    for (const std::string& name : {base, base + "+occupancy"}) {
      auto preset = methodPreset(name);
      if (!preset || !gl::classifyGl(preset.value()).ok()) continue;
      SCOPED_TRACE(name);
      const MethodDesc& method = preset.value();
      RenderOptions options;
      // (at least the method's fixed per-pixel words with the lock: aoit16 144 B per pixel)
      options.budgetBytes =
          std::max<uint64_t>(200u << 10, MemoryModel::of(method, true).overhead(48 * 40));
      RenderOptions cpuOptions = options;  // the GL k-buffers lock per pixel (see GlSeam above)
      if (method.allocation != AllocationPolicy::Unbounded &&
          method.store != StoreChoice::MultiLayer)
        cpuOptions.capture = CaptureMode::FragmentParallel;
      auto g = gl->render(view, method, options);
      auto r = cpu.render(view, method, cpuOptions);
      ASSERT_TRUE(r.ok()) << r.error().message;
      ASSERT_TRUE(g.ok()) << g.error().message;
      const RenderStats &gs = g->stats, &cs = r->stats;
      EXPECT_EQ(gs.method, cs.method);
      EXPECT_EQ(gs.budgetBytes, cs.budgetBytes);
      EXPECT_EQ(gs.fragmentsGenerated, cs.fragmentsGenerated);
      EXPECT_EQ(gs.globalK, cs.globalK);
      EXPECT_EQ(gs.maxDepthComplexity, cs.maxDepthComplexity);
      EXPECT_EQ(gs.meanDepthComplexity, cs.meanDepthComplexity);
      EXPECT_EQ(gs.coveredPixels, cs.coveredPixels);
      const bool deep = method.allocation == AllocationPolicy::Importance &&
                        method.importanceSource == ImportanceSource::Network;
      if (!deep) {
        EXPECT_EQ(gs.bytesUsed, cs.bytesUsed);
        EXPECT_EQ(gs.bytesByCategory, cs.bytesByCategory);
        EXPECT_EQ(gs.fragmentSlots, cs.fragmentSlots);
        EXPECT_EQ(gs.captured, cs.captured);
        EXPECT_EQ(gs.lost, cs.lost);
        EXPECT_EQ(gs.kMin, cs.kMin);
        EXPECT_EQ(gs.kMax, cs.kMax);
        EXPECT_EQ(g->kMap, r->kMap);
      } else {
        uint64_t differ = 0;
        for (size_t p = 0; p < g->kMap.size(); ++p)
          differ += g->kMap[p] > r->kMap[p] ? g->kMap[p] - r->kMap[p] : r->kMap[p] - g->kMap[p];
        EXPECT_LE(differ, g->kMap.size() / 100);  // slots moved by rounding
        EXPECT_LE(std::max(gs.captured, cs.captured) - std::min(gs.captured, cs.captured), differ);
        EXPECT_LE(gs.bytesUsed, *options.budgetBytes);
        EXPECT_EQ(gs.lost, gs.fragmentsGenerated - gs.captured);
      }
      ++checked;
    }
  EXPECT_GE(checked, 30);
}

// The deep k-buffer: features and network in GL shaders. The importance agrees with the CPU
// engine's within float rounding (sums in index order, not Eigen's; float log2 and exp), so k(p)
// = floor(P(p) F(M)) may differ at a few pixels where P(p) F(M) is within rounding of an integer:
// the test bounds those pixels and the images where k(p) agrees.
TEST(GlSeamDeep, ImportanceWithinFloatRoundingOfTheCpuEngine) {
  MFR_GL_ENGINE(gl);
  for (const char* name : {"dkb", "dkb-fill"})
    for (const char* sceneName :
         {"procedural:layers", "procedural:hairball?strands=150", "procedural:bottles?count=4"}) {
      SCOPED_TRACE(std::string(name) + " " + sceneName);
      const Scene scene = loadScene(sceneName).value();
      const Camera camera =
          scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
      const View view{&scene, camera, 96, 80};
      CpuEngine cpu(EngineOptions{2, 16});
      const MethodDesc method = methodPreset(name).value();
      RenderOptions options;
      options.budgetBytes = 400u << 10;
      RenderOptions cpuOptions = options;
      cpuOptions.capture = CaptureMode::FragmentParallel;
      auto g = gl->render(view, method, options);
      auto r = cpu.render(view, method, cpuOptions);
      ASSERT_TRUE(g.ok()) << g.error().message;
      ASSERT_TRUE(r.ok()) << r.error().message;
      EXPECT_EQ(g->stats.fragmentsGenerated, r->stats.fragmentsGenerated);
      EXPECT_LE(g->stats.bytesUsed, *options.budgetBytes);
      const std::vector<float>& gi = g->importance.importance;
      const std::vector<float>& ri = r->importance.importance;
      ASSERT_EQ(gi.size(), ri.size());
      float maxDiff = 0.0f;
      for (size_t p = 0; p < gi.size(); ++p) maxDiff = std::max(maxDiff, std::abs(gi[p] - ri[p]));
      EXPECT_LE(maxDiff, 1e-5f) << "importance";
      ASSERT_EQ(g->kMap.size(), r->kMap.size());
      size_t kDiffer = 0, imageDiffer = 0;
      for (size_t p = 0; p < g->kMap.size(); ++p) {
        if (g->kMap[p] != r->kMap[p]) {
          ++kDiffer;
          continue;
        }
        for (int ch = 0; ch < 3; ++ch)
          imageDiffer += std::abs(g->image.pixels[p][ch] - r->image.pixels[p][ch]) > 1e-6f;
      }
      EXPECT_LE(kDiffer, g->kMap.size() / 100) << "pixels with another k(p)";
      EXPECT_EQ(imageDiffer, 0u) << "channels differing where k(p) agrees";
      RecordProperty(std::string(name) + "_" + sceneName,
                     "importance max diff " + (std::ostringstream() << maxDiff).str() +
                         ", k(p) differs at " + std::to_string(kDiffer) + " px, bytes_used " +
                         std::to_string(g->stats.bytesUsed) + " vs " +
                         std::to_string(r->stats.bytesUsed));
    }
}

// Counted, dynamic and importance-map k on the GPU (count, histogram, importance map, I_tot, k(p),
// prefix sum in compute shaders; the host reads totals only): the allocation is the CPU engine's
// (k(p) and bytes_used identical), the importance map bit for bit its float arithmetic, with the
// default parameters and with others (a non-integer periphery exponent takes GLSL's pow, a
// previous frame's |n.v|). No host allocation pass in the pass list.
TEST(GlSeamDevice, VariableKAllocationInComputeShadersIsTheCpuEngines) {
  MFR_GL_ENGINE(gl);
  struct Case {
    const char* method;
    int variant;  // importance: 0 default, 1 fovea + d 2.5 + no noise, 2 a previous |n.v|
  };
  for (const char* sceneName :
       {"procedural:layers", "procedural:hairball?strands=150", "procedural:bottles?count=4"})
    for (const Case c : {Case{"kplus-sb", 0}, Case{"kplus-dynamic", 0}, Case{"kplus-heap", 0},
                         Case{"vkb", 0}, Case{"vkb", 1}, Case{"vkb", 2}}) {
      SCOPED_TRACE(std::string(c.method) + " " + std::to_string(c.variant) + " " + sceneName);
      const Scene scene = loadScene(sceneName).value();
      const Camera camera =
          scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
      const View view{&scene, camera, 97, 83};
      CpuEngine cpu(EngineOptions{2, 16});
      MethodDesc method = methodPreset(c.method).value();
      if (method.allocation == AllocationPolicy::FixedK) {  // kplus-heap as a counted k
        method.allocation = AllocationPolicy::CountedK;
        method.k = 20;  // above 16: the K+B-SB rule picks the heap where a pixel overflows
        method.store = StoreChoice::PerPixel;
      }
      if (c.variant == 1) {
        method.importance.fovea = glm::vec2(20.25f, 61.5f);
        method.importance.peripheryExponent = 2.5f;
        method.importance.useNoise = false;
        method.importance.alpha = 0.3f;
      }
      std::vector<float> previous;
      RenderOptions options;
      options.budgetBytes = method.k ? 700u << 10 : 250u << 10;
      if (c.variant == 2) {
        for (uint64_t p = 0; p < uint64_t{97} * 83; ++p)
          previous.push_back(static_cast<float>(p % 251) / 250.0f);
        options.previousNearestCosine = &previous;
      }
      RenderOptions cpuOptions = options;
      cpuOptions.capture = CaptureMode::FragmentParallel;
      auto g = gl->render(view, method, options);
      auto r = cpu.render(view, method, cpuOptions);
      ASSERT_TRUE(g.ok()) << g.error().message;
      ASSERT_TRUE(r.ok()) << r.error().message;
      EXPECT_EQ(g->stats.bytesUsed, r->stats.bytesUsed);
      EXPECT_EQ(g->stats.fragmentSlots, r->stats.fragmentSlots);
      EXPECT_EQ(g->stats.globalK, r->stats.globalK);
      EXPECT_EQ(g->stats.captured, r->stats.captured);
      EXPECT_EQ(g->depthComplexity, r->depthComplexity);
      EXPECT_EQ(g->kMap, r->kMap);
      size_t importanceDiffers = 0;
      float maxDiff = 0.0f;
      for (auto [gm, rm] : {std::pair{&g->importance.importance, &r->importance.importance},
                            {&g->importance.depth, &r->importance.depth},
                            {&g->importance.periphery, &r->importance.periphery},
                            {&g->importance.fresnel, &r->importance.fresnel},
                            {&g->importance.noise, &r->importance.noise}}) {
        ASSERT_EQ(gm->size(), rm->size());
        for (size_t p = 0; p < gm->size(); ++p) {
          importanceDiffers += (*gm)[p] != (*rm)[p];
          maxDiff = std::max(maxDiff, std::abs((*gm)[p] - (*rm)[p]));
        }
      }
      // bit for bit, except GLSL's float pow for a non-integer exponent (a few ulp)
      if (c.variant == 1) {
        EXPECT_LE(maxDiff, 1e-6f);
      } else {
        EXPECT_EQ(importanceDiffers, 0u) << "max diff " << maxDiff;
      }
      if (method.allocation == AllocationPolicy::Importance) {
        EXPECT_EQ(g->nearestCosine, r->nearestCosine);
      }
      const float tolerance = method.compositing == Compositing::Hybrid ? 1e-6f : 0.0f;
      for (size_t p = 0; p < g->image.pixels.size(); ++p)
        for (int ch = 0; ch < 3; ++ch)
          ASSERT_LE(std::abs(g->image.pixels[p][ch] - r->image.pixels[p][ch]), tolerance)
              << "pixel " << p;
      bool histogram = false, hostAllocate = false;
      for (const PassTime& t : g->stats.passes) {
        histogram |= t.name == "histogram (allocation)";
        hostAllocate |= t.name == "allocate (host)";
      }
      EXPECT_TRUE(histogram);
      EXPECT_FALSE(hostAllocate);
      RecordProperty(std::string(c.method) + "_" + std::to_string(c.variant) + "_" + sceneName,
                     "importance values differing " + std::to_string(importanceDiffers) +
                         ", max diff " + (std::ostringstream() << maxDiff).str());
    }
}

// Above 65535 pixels (llvmpipe ends a shader's loops after 65535 iterations in all: I_tot's
// serial sum runs in several dispatches), the importance allocation is still the CPU engine's.
TEST(GlSeamDevice, ImportanceAllocationBeyond65535Pixels) {
  MFR_GL_ENGINE(gl);
  const Scene scene = loadScene("procedural:layers").value();
  const View view{&scene, frameBounds(sceneBounds(scene)), 320, 256};
  CpuEngine cpu(EngineOptions{2, 16});
  const MethodDesc method = methodPreset("vkb").value();
  RenderOptions options;
  options.budgetBytes = 40u << 20;  // (k(p) 123-168: every pixel's I(p) counts in I_tot)
  RenderOptions cpuOptions = options;
  cpuOptions.capture = CaptureMode::FragmentParallel;
  auto g = gl->render(view, method, options);
  auto r = cpu.render(view, method, cpuOptions);
  ASSERT_TRUE(g.ok()) << g.error().message;
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(g->stats.bytesUsed, r->stats.bytesUsed);
  EXPECT_EQ(g->stats.fragmentSlots, r->stats.fragmentSlots);
  EXPECT_EQ(g->importance.importance, r->importance.importance);
  EXPECT_EQ(g->kMap, r->kMap);
  EXPECT_EQ(g->image.pixels, r->image.pixels);
}

// The budget checks after the GPU's totals: a budget with room for the per-pixel words but not for
// one node per covered pixel, or for an explicit k, gives the CPU engine's words.
TEST(GlSeamDevice, BudgetErrorsFromTheGpuTotalsAreTheCpuEngines) {
  MFR_GL_ENGINE(gl);
  const Scene scene = loadScene("procedural:layers").value();
  const View view{&scene, frameBounds(sceneBounds(scene)), 40, 36};
  CpuEngine cpu;
  auto counts = cpu.countFragments(**cpu.prepare(view));
  ASSERT_TRUE(counts.ok());
  const int covered = static_cast<int>(
      std::count_if(counts->begin(), counts->end(), [](uint32_t n) { return n > 0; }));
  ASSERT_GT(covered, 100);
  // (nodes beyond the per-pixel words; explicit k or none)
  struct Case {
    const char* name;
    int extra;
    std::optional<uint32_t> k;
  };
  for (const Case c : {Case{"kplus-sb", 3, {}}, Case{"kplus-dynamic", 3, {}}, Case{"vkb", 3, {}},
                       Case{"vkb", covered - 1, {}}, Case{"kplus-dynamic", covered - 1, {}},
                       Case{"kplus-sb", 700, 100}}) {
    const char* name = c.name;
    const int extra = c.extra;
    SCOPED_TRACE(std::string(name) + " " + std::to_string(extra));
    MethodDesc m = methodPreset(name).value();
    if (c.k) m.k = *c.k;  // explicit: the sum of min(n(p), k) does not fit
    const MemoryModel memory = MemoryModel::of(m, true);
    RenderOptions o;
    o.budgetBytes = memory.overhead(40 * 36) + extra * memory.node;
    RenderOptions cpuOptions = o;  // (the GL k-buffers' lock words: the CPU's fragment-parallel)
    cpuOptions.capture = CaptureMode::FragmentParallel;
    auto g = gl->render(view, m, o);
    auto r = cpu.render(view, m, cpuOptions);
    ASSERT_FALSE(r.ok());
    ASSERT_FALSE(g.ok());
    EXPECT_EQ(g.error().message, r.error().message);
  }
}

TEST(GlSeamErrors, MethodsNotInTheGlEngineAndBudgetsAreOneLine) {
  MFR_GL_ENGINE(gl);
  const Scene scene = loadScene("procedural:layers").value();
  const View view{&scene, frameBounds(sceneBounds(scene)), 32, 32};
  auto prepared = gl->prepare(view);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message;
  RenderOptions options;
  options.budgetBytes = 1u << 20;
  // every preset runs on GL; a combination outside the GL engine is one line naming the method
  MethodDesc mlabOccupancy = methodPreset("mlab").value();
  mlabOccupancy.occupancyWords = 1;
  auto unsupported = gl->render(**prepared, mlabOccupancy, options);
  ASSERT_FALSE(unsupported.ok());
  EXPECT_NE(unsupported.error().message.find("mlab"), std::string::npos);
  EXPECT_EQ(unsupported.error().message.find('\n'), std::string::npos);
  options.budgetBytes = 1000;  // less than the per-pixel words
  auto small = gl->render(**prepared, methodPreset("fkb").value(), options);
  ASSERT_FALSE(small.ok());
  EXPECT_NE(small.error().message.find("too small"), std::string::npos) << small.error().message;
  // the same n(p) as the CPU engine's count pass
  CpuEngine cpu;
  auto cpuView = cpu.prepare(view);
  ASSERT_TRUE(cpuView.ok());
  // budget errors of the variable-k methods: the shared allocate()'s, the CPU engine's words
  for (const char* name :
       {"kplus-sb", "kplus-dynamic", "vkb", "vkb-fill", "dkb", "dkb-curve", "optimal"})
    for (std::optional<uint64_t> budget :
         {std::optional<uint64_t>(1000), std::optional<uint64_t>()}) {
      SCOPED_TRACE(name);
      RenderOptions o;
      o.budgetBytes = budget;
      const MethodDesc m = methodPreset(name).value();
      auto g = gl->render(**prepared, m, o);
      auto r = cpu.render(**cpuView, m, o);
      ASSERT_FALSE(g.ok());
      ASSERT_FALSE(r.ok());
      EXPECT_EQ(g.error().message, r.error().message);
    }
  EXPECT_EQ(gl->countFragments(**prepared).value(), cpu.countFragments(**cpuView).value());
  // the nearest fragment's |n.v| (unorm8), the variable k-buffer's previous-frame input
  EXPECT_EQ(gl->nearestCosine(**prepared).value(), cpu.nearestCosine(**cpuView).value());
  EXPECT_FALSE(cpu.render(**prepared, methodPreset("abuffer").value(), {}).ok())
      << "a GL view given to the CPU engine";
}

// n(p) from the count pass alone, also where the view's A-buffer exceeds a storage block (mfr info
// --engine gl at its default 1024x1024 on procedural:layers); multisampled, per sample summed per
// pixel, as the CPU engine counts.
TEST(GlSeam, CountFragmentsNeedsNoABuffer) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", "native");  // (multisampling is the native raster's)
  const Scene scene = loadScene("procedural:layers?k=16&r=16&pd=1").value();
  CpuEngine cpu(EngineOptions{2, 16});
  for (const int samples : {1, 4}) {
    SCOPED_TRACE(samples);
    View view{&scene, *scene.defaultCamera, samples == 1 ? 320 : 96, samples == 1 ? 320 : 80};
    view.samples = samples;
    auto glView = gl->prepare(view);
    auto cpuView = cpu.prepare(view);
    ASSERT_TRUE(glView.ok()) << glView.error().message;
    ASSERT_TRUE(cpuView.ok()) << cpuView.error().message;
    auto g = gl->countFragments(**glView);
    auto r = cpu.countFragments(**cpuView);
    ASSERT_TRUE(g.ok()) << g.error().message;
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*g, *r);
    if (samples == 1) {  // 256 layers on 102,400 pixels: 210 MB of A-buffer nodes
      EXPECT_FALSE(gl->render(**glView, methodPreset("abuffer").value(), {}).ok());
      EXPECT_EQ(std::accumulate(g->begin(), g->end(), uint64_t{0}), uint64_t{256} * 320 * 320);
    }
  }
}

// `mfr compare --engine gl`: ground truth and every run from the GL engine, results.json says so;
// every run carries its metrics (the deep k-buffer's network runs on GL too).
TEST(GlSeamCli, CompareOnTheGlEngine) {
  MFR_GL_ENGINE(gl);
  gl.reset();  // the CLI makes its own context
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("mfr_gl_compare_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::string cmd = std::string(MFR_CLI_PATH) +
                          " compare procedural:layers --engine gl --gl-raster exact --methods "
                          "fkb,kplus-array,dkb "
                          "--budget 200KB,400KB --width 64 --height 64 --quiet --out " +
                          dir.string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(dir / "results.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["engine"], "gl");
  EXPECT_EQ(j["ground_truth"]["engine"], "gl");
  ASSERT_EQ(j["budgets"].size(), 2u);
  for (const auto& budget : j["budgets"])
    for (const auto& run : budget["methods"]) {
      ASSERT_FALSE(run.contains("error")) << run["error"];
      EXPECT_EQ(run["engine"], "gl");
      EXPECT_LE(run["bytes_used"].get<uint64_t>(), budget["budget_bytes"].get<uint64_t>());
      EXPECT_GT(run["flip_mean"].get<double>(), 0.0) << "layers lose fragments at these budgets";
    }
  std::filesystem::remove_all(dir);
}

// --gl-sync: auto is the interlock where the driver offers one, else the lock (stats and
// describe() say which); interlock without the extension is a one-line error naming what the
// driver lacks; an unknown value is an error.
TEST(GlSeam, SyncMode) {
  MFR_GL_ENGINE(gl);
  const std::string sync = gl->describe().at("sync");
  gl.reset();
  auto bogus = makeGlEngine("spin");
  ASSERT_FALSE(bogus.ok());
  EXPECT_EQ(bogus.error().message, "--gl-sync 'spin': expected auto, lock or interlock");
  auto lock = makeGlEngine("lock");
  ASSERT_TRUE(lock.ok()) << lock.error().message;
  EXPECT_EQ((*lock)->describe().at("sync"), "lock");
  const Scene scene = loadScene("procedural:layers").value();
  const View view{&scene, *scene.defaultCamera, 32, 32};
  auto pv = (*lock)->prepare(view);
  ASSERT_TRUE(pv.ok());
  MethodDesc method = methodPreset("kplus-array").value();
  method.k = 4;
  auto out = (*lock)->render(**pv, method, {});
  ASSERT_TRUE(out.ok()) << out.error().message;
  EXPECT_EQ(out->stats.engineCounters.at("sync_interlock"), 0);
  pv.value().reset();
  lock.value().reset();
  auto interlock = makeGlEngine("interlock");
  if (sync == "lock") {  // auto chose the lock: the driver has no interlock
    ASSERT_FALSE(interlock.ok());
    const std::string m = interlock.error().message;
    EXPECT_EQ(m.find("--gl-sync interlock: the driver offers none of "
                     "GL_ARB_fragment_shader_interlock, GL_NV_fragment_shader_interlock, "
                     "GL_INTEL_fragment_shader_ordering"),
              0u)
        << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  } else {
    ASSERT_TRUE(interlock.ok()) << interlock.error().message;
    EXPECT_EQ(sync.rfind("interlock", 0), 0u) << sync;
  }
}

// The CLI: --gl-sync lock renders what the default renders (byte-identical PNG); interlock on a
// driver without it is one line on stderr and exit 1.
TEST(GlSeamCli, GlSyncOption) {
  MFR_GL_ENGINE(gl);
  const bool hasInterlock = gl->describe().at("sync") != "lock";
  gl.reset();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("mfr_gl_sync_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string base = std::string(MFR_CLI_PATH) +
                           " render procedural:layers --engine gl -m kplus-heap --k 4 --width 64 "
                           "--height 64 --quiet";
  ASSERT_EQ(std::system((base + " -o " + (dir / "auto.png").string()).c_str()), 0);
  ASSERT_EQ(std::system((base + " --gl-sync lock -o " + (dir / "lock.png").string()).c_str()), 0);
  EXPECT_FALSE(test::fileBytes(dir / "auto.png").empty());
  if (!hasInterlock) {
    EXPECT_EQ(test::fileBytes(dir / "auto.png"), test::fileBytes(dir / "lock.png"));
    const std::string cmd = base + " --gl-sync interlock -o " + (dir / "x.png").string() + " 2>" +
                            (dir / "err.txt").string();
    const int rc = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(rc));
    EXPECT_EQ(WEXITSTATUS(rc), 1);
    const std::string err = test::fileBytes(dir / "err.txt");
    EXPECT_NE(err.find("--gl-sync interlock: the driver offers none of "
                       "GL_ARB_fragment_shader_interlock"),
              std::string::npos)
        << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mfr::gl
