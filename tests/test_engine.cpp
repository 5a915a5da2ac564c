// The engine seam (mfr/engine/engine.hpp): makeEngine, the CPU engine behind it rendering exactly
// what the CPU passes render, engine-specific counters beside the shared statistics, the pure
// allocation's pixel layouts, and --engine on the command line.
#include <gtest/gtest.h>

#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

const Scene& bottles() {
  static const Scene scene = loadScene("procedural:bottles?count=3").value();
  return scene;
}

Camera cameraOf(const Scene& scene) {
  return scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
}

TEST(Engine, MakeEngineKnowsCpuAndNamesTheUnknownOnOneLine) {
  EXPECT_EQ(engineNames(), std::vector<std::string>{"cpu"});
  auto cpu = makeEngine("cpu");
  ASSERT_TRUE(cpu.ok());
  EXPECT_EQ((*cpu)->name(), "cpu");
  EXPECT_EQ((*cpu)->describe().at("engine"), "cpu");
  auto unknown = makeEngine("vulkan\nx");
  ASSERT_FALSE(unknown.ok());
  const std::string& m = unknown.error().message;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_NE(m.find("vulkan"), std::string::npos) << m;
  EXPECT_NE(m.find("known: cpu"), std::string::npos) << m;
}

// Rendering through the engine is the CPU passes on the frame prepare() built: same image bits,
// same statistics, for a counted, an importance and a peer method.
TEST(Engine, CpuEngineRendersWhatTheCpuPassesRender) {
  const Scene& scene = bottles();
  const Camera camera = cameraOf(scene);
  CpuEngine engine(EngineOptions{2, 16});
  auto view = engine.prepare(View{&scene, camera, 67, 53});
  ASSERT_TRUE(view.ok()) << view.error().message;
  EXPECT_EQ((*view)->width(), 67);
  EXPECT_EQ((*view)->height(), 53);
  auto frame = RasterFrame::build(scene, camera, RasterOptions{67, 53, 16, 2});
  ASSERT_TRUE(frame.ok());
  for (const char* preset : {"kplus-sb", "vkb", "wboit"}) {
    RenderOptions options;
    options.budgetBytes = 96u << 10;
    auto viaEngine = engine.render(**view, methodPreset(preset).value(), options);
    auto direct = render(*frame, methodPreset(preset).value(), options);
    ASSERT_TRUE(viaEngine.ok()) << preset << ": " << viaEngine.error().message;
    ASSERT_TRUE(direct.ok()) << preset;
    EXPECT_EQ(viaEngine->image.pixels, direct->image.pixels) << preset;
    EXPECT_EQ(viaEngine->kMap, direct->kMap) << preset;
    EXPECT_EQ(viaEngine->stats.bytesUsed, direct->stats.bytesUsed) << preset;
    EXPECT_EQ(viaEngine->stats.captured, direct->stats.captured) << preset;
    // the engine's own counters sit beside the shared statistics
    EXPECT_EQ(viaEngine->stats.engine, "cpu");
    EXPECT_EQ(viaEngine->stats.engineCounters.at("threads"), 2.0);
    EXPECT_TRUE(direct->stats.engine.empty()) << "the CPU passes alone name no engine";
  }
  auto n = engine.countFragments(**view);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(n.value(), countFragments(*frame));
  auto cosine = engine.nearestCosine(**view);
  ASSERT_TRUE(cosine.ok());
  EXPECT_EQ(cosine.value(), nearestCosine(*frame));
}

TEST(Engine, AViewFromAnotherEngineAndBadViewsAreOneLineErrors) {
  struct ForeignView final : PreparedView {
    int width() const override { return 4; }
    int height() const override { return 4; }
  };
  CpuEngine engine;
  auto out = engine.render(ForeignView{}, methodPreset("abuffer").value(), RenderOptions{});
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.error().message.find("another engine"), std::string::npos);
  EXPECT_FALSE(engine.prepare(View{}).ok()) << "no scene";
  auto tooBig = engine.prepare(View{&bottles(), cameraOf(bottles()), 0, 16});
  ASSERT_FALSE(tooBig.ok());
  EXPECT_EQ(tooBig.error().message.find('\n'), std::string::npos);
}

// allocate() is a pure function of its inputs: the same k(p) for any layout, offsets an exclusive
// prefix sum in the layout's order (tile-major, or row-major with tile size 0).
TEST(Allocation, LayoutOnlyOrdersTheOffsets) {
  const int w = 37, h = 21;
  std::vector<uint32_t> n(static_cast<size_t>(w) * h);
  for (size_t p = 0; p < n.size(); ++p) n[p] = static_cast<uint32_t>((p * 7919) % 11);
  const MethodDesc method = methodPreset("kplus-sb").value();
  const MemoryModel memory = MemoryModel::of(method);
  const uint64_t budget = memory.overhead(n.size()) + 3000 * memory.node;
  auto rows = allocate(PixelLayout{w, h, 0}, method, memory, budget, n, {}, {});
  auto tiles = allocate(PixelLayout{w, h, 8}, method, memory, budget, n, {}, {});
  ASSERT_TRUE(rows.ok()) << rows.error().message;
  ASSERT_TRUE(tiles.ok());
  EXPECT_EQ(rows->capacity, tiles->capacity);
  EXPECT_EQ(rows->slots, tiles->slots);
  EXPECT_LE(rows->slots, 3000u);
  uint64_t running = 0;
  for (size_t p = 0; p < n.size(); ++p) {  // row-major: the plain exclusive prefix sum
    EXPECT_EQ(rows->offsets[p], running) << p;
    running += rows->capacity[p];
  }
  // tile-major: pixel (8, 0) starts after the whole first 8x8 tile
  uint64_t firstTile = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) firstTile += tiles->capacity[static_cast<size_t>(y) * w + x];
  EXPECT_EQ(tiles->offsets[8], firstTile);
  // the last tile row and column are partial (37 = 4*8 + 5, 21 = 2*8 + 5) and still covered
  EXPECT_EQ(tiles->offsets.back() + tiles->capacity.back(), tiles->slots);
}

TEST(EngineCli, EngineOptionNamesTheEngine) {
  const auto dir = test::processTempDir("engine_cli");
  const test::CliRun ok = test::runCli(
      "render procedural:bottles?count=3 --width 32 --height 32 --quiet --method fkb --budget "
      "64KB -o " +
          (dir / "a.png").string() + " --engine cpu --stats-json " + (dir / "s.json").string(),
      dir);
  EXPECT_EQ(ok.exitCode, 0) << ok.err;
  const test::CliRun bad = test::runCli(
      "render procedural:bottles?count=3 --width 32 --height 32 --quiet --method fkb --budget "
      "64KB -o " +
          (dir / "b.png").string() + " --engine warp",
      dir);
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.err.find("--engine 'warp': unknown engine (known: cpu"), std::string::npos)
      << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "b.png"));
  const test::CliRun info = test::runCli(
      "info procedural:bottles?count=3 --width 32 --height 32 --json --engine cpu", dir);
  EXPECT_EQ(info.exitCode, 0) << info.err;
  EXPECT_NE(info.out.find("\"engine\""), std::string::npos) << info.out;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mfr
