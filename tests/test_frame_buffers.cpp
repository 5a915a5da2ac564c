// Buffers kept from one CPU render to the next (mfr/cpu/frame_buffers.hpp): a sequence of renders
// through one FrameBuffers (methods, sizes, compositing rules and capture modes changing from one
// to the next) gives every render's image, counters and memory figures as a fresh render does,
// and a render of the same size reuses the previous node pool and allocation arrays.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cpu/pipeline.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/cpu/frame_buffers.hpp"
#include "mfr/scene/procedural.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr {
namespace {

struct Step {
  std::string preset;
  Compositing rule;
  CaptureMode mode;
  int size;
  std::optional<uint32_t> k;
  std::optional<uint64_t> budget;
};

TEST(FrameBuffers, ReusedBuffersGiveWhatFreshOnesGive) {
  auto scene = makeProceduralScene("layers?k=6&r=2&pd=0.55", 1);
  ASSERT_TRUE(scene.ok());
  const Camera camera = scene->defaultCamera ? *scene->defaultCamera : test::screenCamera();
  const std::vector<Step> steps = {
      {"kplus-heap", Compositing::KBuffer, CaptureMode::TileOwned, 64, 4, std::nullopt},
      {"kplus-heap", Compositing::KBuffer, CaptureMode::TileOwned, 64, 4, std::nullopt},
      {"kplus-dynamic", Compositing::Hybrid, CaptureMode::TileOwned, 48, std::nullopt,
       48 * 48 * 40},
      {"wboit", Compositing::WeightedBlended, CaptureMode::TileOwned, 64, std::nullopt,
       std::nullopt},
      {"linked-list", Compositing::KBuffer, CaptureMode::TileOwned, 64, std::nullopt, 64 * 64 * 30},
      {"kplus-array", Compositing::KBuffer, CaptureMode::FragmentParallel, 80, 3, std::nullopt},
      {"abuffer", Compositing::KBuffer, CaptureMode::TileOwned, 40, std::nullopt, std::nullopt},
      {"kplus-heap", Compositing::Hybrid, CaptureMode::TileOwned, 64, 4, std::nullopt}};
  FrameBuffers buffers;
  for (const Step& s : steps) {
    const auto frame = test::buildFrame(*scene, camera, s.size, s.size, 2);
    ASSERT_TRUE(frame);
    const MethodDesc method = test::presetWithK(s.preset, s.k, s.rule);
    RenderOptions options;
    options.capture = s.mode;
    options.budgetBytes = s.budget;
    options.background = glm::vec3(0.2f, 0.4f, 0.6f);
    const auto fresh = render(*frame, method, options);
    options.reuse = &buffers;
    const auto reused = render(*frame, method, options);
    ASSERT_TRUE(fresh.ok() && reused.ok()) << method.name;
    const std::string what = method.name + " at " + std::to_string(s.size);
    EXPECT_TRUE(fresh->image.pixels == reused->image.pixels) << what << ": images differ";
    EXPECT_EQ(fresh->stats.bytesUsed, reused->stats.bytesUsed) << what;
    EXPECT_EQ(fresh->stats.bytesAllocated, reused->stats.bytesAllocated) << what;
    EXPECT_EQ(fresh->stats.bytesAllocatedByCategory, reused->stats.bytesAllocatedByCategory)
        << what;
    EXPECT_EQ(fresh->stats.captured, reused->stats.captured) << what;
    if (s.mode == CaptureMode::TileOwned) {  // (parallel capture: insertions follow arrival)
      EXPECT_EQ(fresh->stats.inserted, reused->stats.inserted) << what;
    }
    EXPECT_EQ(fresh->stats.fragmentsGenerated, reused->stats.fragmentsGenerated) << what;
  }
}

TEST(FrameBuffers, TheSameFrameAgainReusesTheNodePool) {
  auto scene = makeProceduralScene("layers?k=4&r=2&pd=0.55", 1);
  ASSERT_TRUE(scene.ok());
  const Camera camera = scene->defaultCamera ? *scene->defaultCamera : test::screenCamera();
  const auto frame = test::buildFrame(*scene, camera, 64, 64, 2);
  ASSERT_TRUE(frame);
  const MethodDesc method = test::presetWithK("kplus-heap", 4, Compositing::KBuffer);
  FrameBuffers buffers;
  RenderOptions options;
  options.reuse = &buffers;
  ASSERT_TRUE(render(*frame, method, options).ok());
  std::unique_ptr<detail::Stores> kept = buffers.take();
  ASSERT_TRUE(kept);
  const FragmentNode* pool = kept->nodes.data();
  const uint64_t* offsets = kept->spare.offsets.data();
  EXPECT_EQ(kept->nodes.size(), 64u * 64u * 4u);
  EXPECT_EQ(kept->spare.offsets.size(), 64u * 64u);
  EXPECT_FALSE(buffers.take()) << "taken twice";
  buffers.give(std::move(kept));
  ASSERT_TRUE(render(*frame, method, options).ok());
  kept = buffers.take();
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->nodes.data(), pool) << "the second render allocated a new node pool";
  EXPECT_EQ(kept->spare.offsets.data(), offsets) << "the second render allocated new offsets";
  buffers.give(std::move(kept));
  // a frame more than twice smaller gets a pool of its own size
  const auto small = test::buildFrame(*scene, camera, 32, 32, 2);
  ASSERT_TRUE(small);
  ASSERT_TRUE(render(*small, method, options).ok());
  kept = buffers.take();
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->nodes.size(), 32u * 32u * 4u);
  buffers.give(std::move(kept));
  buffers.release();
  kept = buffers.take();
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->nodes.size(), 0u) << "release() kept the pool";
}

// CpuEngine keeps its buffers between renders: a second render of the same view, and one after
// releaseBuffers(), give the same image.
TEST(FrameBuffers, CpuEngineRendersTheSameImageTwice) {
  auto scene = makeProceduralScene("layers?k=4&r=2&pd=0.55", 1);
  ASSERT_TRUE(scene.ok());
  CpuEngine engine;
  View view{&scene.value(), scene->defaultCamera ? *scene->defaultCamera : test::screenCamera(), 48,
            48};
  auto prepared = engine.prepare(view);
  ASSERT_TRUE(prepared.ok()) << prepared.error().message;
  const MethodDesc method = test::presetWithK("kplus-heap", 4, Compositing::KBuffer);
  const auto first = engine.render(**prepared, method, RenderOptions{});
  const auto second = engine.render(**prepared, method, RenderOptions{});
  engine.releaseBuffers();
  const auto third = engine.render(**prepared, method, RenderOptions{});
  ASSERT_TRUE(first.ok() && second.ok() && third.ok());
  EXPECT_TRUE(first->image.pixels == second->image.pixels);
  EXPECT_TRUE(first->image.pixels == third->image.pixels);
}

}  // namespace
}  // namespace mfr
