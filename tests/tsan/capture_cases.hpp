// Scenes and helpers shared by the capture tests (tests/test_methods.cpp,
// tests/test_parallel_capture.cpp) and the ThreadSanitizer build (tests/tsan/): frames at small
// sizes, the hot-pixel scene, runs of a preset with an explicit k, and the per-pixel captured sets
// a run leaves in RenderOutput (keepStores).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "../test_util.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::test {

/// The bounded presets of the k-buffer family (zbuffer and abuffer apart).
inline const std::vector<std::string>& boundedPresets() {
  static const std::vector<std::string> names = {"fkb", "kplus-array", "kplus-heap", "kplus-sb",
                                                 "kplus-dynamic"};
  return names;
}

inline std::optional<RasterFrame> buildFrame(const Scene& scene, const Camera& camera, int width,
                                             int height, int threads) {
  RasterOptions ro;
  ro.width = width;
  ro.height = height;
  ro.threads = threads;
  auto frame = RasterFrame::build(scene, camera, ro);
  EXPECT_TRUE(frame.ok()) << (frame.ok() ? "" : frame.error().message);
  if (!frame.ok()) return std::nullopt;
  return std::move(frame.value());
}

/// Hundreds of tiny screen-aligned rectangles (two triangles each) over the same 3x3 pixels of a
/// size x size image: every triangle contends for the same few pixels. Depths and colours come
/// from small sets, so there are many equal depths and many nodes equal in depth and colour.
inline Scene hotPixelScene(int size, int rects, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<TestTriangle> tris;
  const double c = size / 2.0;
  const glm::vec4 palette[] = {{1.0f, 0.1f, 0.1f, 0.3f},
                               {0.1f, 0.8f, 0.2f, 0.5f},
                               {0.2f, 0.3f, 1.0f, 0.2f},
                               {0.9f, 0.9f, 0.1f, 0.7f}};
  for (int i = 0; i < rects; ++i) {
    // corners around the 3x3 pixel block [c-1.5, c+1.5]: each rectangle covers 1 to 9 of them
    const double x0 = c - 1.8 + (rng() % 3), y0 = c - 1.8 + (rng() % 3);
    const double x1 = std::max(x0 + 0.6, c - 0.2 + (rng() % 3)),
                 y1 = std::max(y0 + 0.6, c - 0.2 + (rng() % 3));
    // nearer on average the later the rectangle (the k+ test's worst case: most arrivals pass it
    // and evict under the lock), on a grid of 1/200 so that many depths are equal
    const int step = 400 * (rects - i) / rects + static_cast<int>(rng() % 20);
    const float z = -static_cast<float>(step) / 200.0f;
    const auto rect = screenRect(x0, y0, x1, y1, size, z, palette[rng() % 4]);
    tris.insert(tris.end(), rect.begin(), rect.end());
  }
  return makeScene(tris);
}

inline MethodDesc presetWithK(const std::string& preset, std::optional<uint32_t> k,
                              Compositing compositing) {
  auto m = methodPreset(preset);
  EXPECT_TRUE(m.ok()) << preset;
  MethodDesc method = m.ok() ? m.value() : MethodDesc{};
  if (k) method.k = *k;
  method.compositing = compositing;
  if (compositing == Compositing::Hybrid) method.name += " (hybrid)";
  return method;
}

inline std::optional<RenderOutput> runMethod(const RasterFrame& frame, const MethodDesc& method,
                                             CaptureMode mode,
                                             std::optional<uint64_t> budget = std::nullopt,
                                             glm::vec3 background = glm::vec3(0.2f, 0.4f, 0.6f)) {
  RenderOptions options;
  options.capture = mode;
  options.keepStores = true;
  options.budgetBytes = budget;
  options.background = background;
  auto out = render(frame, method, options);
  EXPECT_TRUE(out.ok()) << method.name << ": " << (out.ok() ? "" : out.error().message);
  if (!out.ok()) return std::nullopt;
  return std::move(out.value());
}

/// Pixel p's captured nodes, sorted.
inline std::vector<FragmentNode> capturedAt(const RenderOutput& out, size_t p) {
  std::vector<FragmentNode> v(
      out.nodes.begin() + static_cast<std::ptrdiff_t>(out.offsets[p]),
      out.nodes.begin() + static_cast<std::ptrdiff_t>(out.offsets[p] + out.counts[p]));
  std::sort(v.begin(), v.end());
  return v;
}

/// Every pixel's captured nodes, sorted.
inline std::vector<std::vector<FragmentNode>> capturedSets(const RenderOutput& out) {
  std::vector<std::vector<FragmentNode>> sets(out.counts.size());
  for (size_t p = 0; p < sets.size(); ++p) sets[p] = capturedAt(out, p);
  return sets;
}

/// First pixel whose captured set differs, or -1.
inline long firstDifferentPixel(const std::vector<std::vector<FragmentNode>>& a,
                                const std::vector<std::vector<FragmentNode>>& b) {
  if (a.size() != b.size()) return 0;
  for (size_t p = 0; p < a.size(); ++p)
    if (a[p] != b[p]) return static_cast<long>(p);
  return -1;
}

inline std::string modeName(CaptureMode mode) {
  return mode == CaptureMode::TileOwned ? "tile-owned" : "fragment-parallel";
}

/// Runs `method` in both capture modes on the frame (fragment-parallel `repeats` times, to see more
/// interleavings) and expects the same captured set in every pixel; with kbuffer compositing the
/// same image bytes, with hybrid compositing the same image up to the float summation order of the
/// tail accumulators. Adds to `reordered` the fragment-parallel runs whose fragments evidently
/// arrived in another order than the tile-owned primitive order (different insert / evict / cull
/// counts), so callers can check that the threads did interleave.
inline void expectFragmentParallelMatchesTileOwned(const RasterFrame& frame,
                                                   const MethodDesc& method, int repeats,
                                                   const std::string& what, int& reordered) {
  const auto owned = runMethod(frame, method, CaptureMode::TileOwned);
  ASSERT_TRUE(owned) << what;
  ASSERT_GT(owned->stats.captured, 0u) << what << ": nothing captured, nothing to compare";
  const auto ownedSets = capturedSets(*owned);
  const std::vector<uint8_t> ownedBytes = encodeSrgb(owned->image).rgba;
  for (int r = 0; r < repeats; ++r) {
    const auto parallel = runMethod(frame, method, CaptureMode::FragmentParallel);
    ASSERT_TRUE(parallel) << what;
    const long different = firstDifferentPixel(capturedSets(*parallel), ownedSets);
    EXPECT_EQ(different, -1) << what << " run " << r
                             << ": captured sets differ (first pixel shown)";
    bool imageOk = true;
    if (method.compositing == Compositing::KBuffer) {
      imageOk = encodeSrgb(parallel->image).rgba == ownedBytes;
      EXPECT_TRUE(imageOk) << what << " run " << r << ": image bytes differ";
    } else {
      float maxDiff = 0.0f;
      for (size_t p = 0; p < owned->image.pixels.size(); ++p) {
        const glm::vec3 d = glm::abs(parallel->image.pixels[p] - owned->image.pixels[p]);
        maxDiff = std::max({maxDiff, d.r, d.g, d.b});
      }
      imageOk = maxDiff < 1e-5f;
      EXPECT_LT(maxDiff, 1e-5f) << what << " run " << r;
    }
    const RenderStats &a = owned->stats, &b = parallel->stats;
    EXPECT_EQ(b.fragmentsGenerated, a.fragmentsGenerated) << what;
    EXPECT_EQ(b.captured, a.captured) << what;
    EXPECT_EQ(b.culledOccupancy, a.culledOccupancy) << what << ": occupancy culling is order-free";
    EXPECT_EQ(b.culledOccupancy + b.culledKPlus + b.rejectedInStore + b.inserted,
              b.fragmentsGenerated)
        << what << ": no fragment is dropped";
    EXPECT_EQ(b.inserted - b.evicted, b.captured) << what;
    if (b.inserted != a.inserted || b.evicted != a.evicted || b.culledKPlus != a.culledKPlus ||
        b.rejectedInStore != a.rejectedInStore)
      ++reordered;
    if (different != -1 || !imageOk) return;  // one report per method is enough
  }
}

}  // namespace mfr::test
