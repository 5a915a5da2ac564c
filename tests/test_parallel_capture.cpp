// Fragment-parallel capture (the k+-buffer paper's algorithm as written: any thread, any arrival
// order, a spin-lock per pixel, the k+ test outside the critical section and again inside) against
// the deterministic tile-owned capture: the captured sets, and so the kbuffer images, are the same;
// the hybrid tail differs only by the float summation order.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mfr/scene/load.hpp"
#include "test_util.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr {
namespace {

using test::expectFragmentParallelMatchesTileOwned;
using test::presetWithK;

// Thousands of tiny triangles over the same 4x4 pixels: every chunk of triangles contends for the
// same pixel locks, and there are enough chunks for the threads to overlap.
constexpr int kHotRects = 6000;

std::vector<std::string> parallelPresets() {
  std::vector<std::string> v = {"zbuffer", "zbuffer+occupancy"};
  for (const std::string& p : test::boundedPresets()) {
    v.push_back(p);
    v.push_back(p + "+occupancy");
  }
  return v;
}

std::string label(const std::string& scene, int threads, const MethodDesc& m) {
  std::string s = scene;
  s += " threads=";
  s += std::to_string(threads);
  s += " ";
  s += m.name;
  if (m.k) {
    s += " k=";
    s += std::to_string(*m.k);
  }
  return s;
}

// Every preset with every k, with 2 and 8 raster threads; returns the number of fragment-parallel
// runs whose arrival order evidently differed from the tile-owned one.
int compareAllPresets(const Scene& scene, const Camera& camera, int size, const std::string& name,
                      const std::vector<uint32_t>& ks, Compositing comp, int repeats) {
  int reordered = 0;
  for (const int threads : {2, 8}) {
    const auto frame = test::buildFrame(scene, camera, size, size, threads);
    if (!frame) return reordered;
    EXPECT_EQ(frame->threads(), threads);
    for (const std::string& preset : parallelPresets())
      for (const uint32_t k : ks) {
        if (preset.starts_with("zbuffer") && k != ks.front()) continue;  // k is 1
        const MethodDesc m = presetWithK(
            preset, preset.starts_with("zbuffer") ? std::nullopt : std::optional<uint32_t>(k),
            comp);
        expectFragmentParallelMatchesTileOwned(*frame, m, repeats, label(name, threads, m),
                                               reordered);
      }
  }
  return reordered;
}

TEST(FragmentParallelCapture, MatchesTileOwnedCaptureOnHairball) {
  auto scene = loadScene("procedural:hairball?strands=300");
  ASSERT_TRUE(scene.ok());
  (void)compareAllPresets(*scene, *scene->defaultCamera, 96, "hairball", {4, 17},
                          Compositing::KBuffer, 1);
}

TEST(FragmentParallelCapture, MatchesTileOwnedCaptureOnAHotPixel) {
  const Scene scene = test::hotPixelScene(16, kHotRects, 3);
  const int reordered = compareAllPresets(scene, test::screenCamera(), 16, "hot-pixel",
                                          {1, 4, 17, 64}, Compositing::KBuffer, 3);
  EXPECT_GT(reordered, 0) << "the threads never interleaved: the comparison proved nothing";
}

TEST(FragmentParallelCapture, HybridKeepsTheCoreAndTheTailUpToSummationOrder) {
  const Scene hot = test::hotPixelScene(16, kHotRects, 5);
  const int reordered = compareAllPresets(hot, test::screenCamera(), 16, "hot-pixel", {4, 17},
                                          Compositing::Hybrid, 3);
  EXPECT_GT(reordered, 0) << "the threads never interleaved: the comparison proved nothing";
  auto hair = loadScene("procedural:hairball?strands=300");
  ASSERT_TRUE(hair.ok());
  (void)compareAllPresets(*hair, *hair->defaultCamera, 96, "hairball", {4}, Compositing::Hybrid, 1);
}

TEST(FragmentParallelCapture, HotPixelSceneHasTheContentionItIsMeantToHave) {
  // guards the scene above: hundreds of fragments per pixel on at most 16 pixels
  const Scene scene = test::hotPixelScene(16, kHotRects, 3);
  const auto frame = test::buildFrame(scene, test::screenCamera(), 16, 16, 2);
  ASSERT_TRUE(frame);
  const std::vector<uint32_t> n = countFragments(*frame);
  int covered = 0;
  uint32_t minN = UINT32_MAX;
  for (const uint32_t c : n)
    if (c > 0) {
      ++covered;
      minN = std::min(minN, c);
    }
  EXPECT_LE(covered, 16);
  EXPECT_GE(minN, static_cast<uint32_t>(kHotRects / 20));
}

}  // namespace
}  // namespace mfr
