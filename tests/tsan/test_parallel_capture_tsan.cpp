// The fragment-parallel capture under ThreadSanitizer (built against mfr_tsan, run with
// TSAN_OPTIONS=halt_on_error=1): per-pixel spin-locks, the k+ test reading slot 0 and the counter
// outside the critical section, hybrid tails and occupancy culling, with 4 and 8 threads contending
// for a handful of pixels. A reported race aborts the test; otherwise the captured sets must equal
// the tile-owned capture's.
//
// TBB is not instrumented, so TSan cannot see the synchronisation of its task hand-offs and reports
// every object passed to a TBB worker (task objects, the passes' lambdas) as a race. The
// fragment-parallel capture runs on plain std::threads, which TSan follows end to end; the other
// passes (count, occupancy, tile-owned capture, resolve) run in TBB arenas. So TBB is limited to
// the calling thread here (global_control): those passes run serially on the main thread, the
// capture still runs on frame.threads() std::threads, and no suppression is needed.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <string>
#include <vector>

#include "capture_cases.hpp"

namespace mfr {
namespace {

using test::expectFragmentParallelMatchesTileOwned;
using test::presetWithK;

const std::vector<std::string> kPresets = {"zbuffer",
                                           "fkb",
                                           "kplus-array",
                                           "kplus-heap",
                                           "kplus-sb",
                                           "kplus-dynamic",
                                           "kplus-array+occupancy",
                                           "fkb+occupancy",
                                           "kplus-heap+occupancy",
                                           "kplus-sb+occupancy"};

int runAll(const Scene& scene, const Camera& camera, int size, const std::string& name,
           int repeats) {
  int reordered = 0;
  const tbb::global_control serialTbb(tbb::global_control::max_allowed_parallelism, 1);
  for (const int threads : {4, 8}) {
    const auto frame = test::buildFrame(scene, camera, size, size, threads);
    if (!frame) return reordered;
    for (const Compositing comp : {Compositing::KBuffer, Compositing::Hybrid})
      for (const std::string& preset : kPresets)
        for (const uint32_t k : {3u, 17u}) {
          if (preset == "zbuffer" && k != 3u) continue;  // its k is 1
          const MethodDesc m = presetWithK(
              preset, preset == "zbuffer" ? std::nullopt : std::optional<uint32_t>(k), comp);
          std::string what = name;
          what += " threads=";
          what += std::to_string(threads);
          what += " ";
          what += m.name;
          what += " k=";
          what += std::to_string(m.k.value_or(0));
          expectFragmentParallelMatchesTileOwned(*frame, m, repeats, what, reordered);
        }
  }
  return reordered;
}

TEST(FragmentParallelCaptureTsan, HotPixelIsRaceFreeAndMatchesTileOwned) {
  const int reordered =
      runAll(test::hotPixelScene(16, 3000, 9), test::screenCamera(), 16, "hot-pixel", 3);
  EXPECT_GT(reordered, 0) << "the threads never interleaved: the run proved nothing";
}

TEST(FragmentParallelCaptureTsan, SmallHairballIsRaceFreeAndMatchesTileOwned) {
  auto scene = loadScene("procedural:hairball?strands=80&segments=8");
  ASSERT_TRUE(scene.ok());
  (void)runAll(*scene, *scene->defaultCamera, 48, "hairball", 1);
}

}  // namespace
}  // namespace mfr
