// bytes_used is the papers' accounting (MemoryModel: what a GPU would lay out); bytes_allocated
// is what the CPU engine really allocated for the method's buffers, measured where they are
// allocated. Both are checked here against the documented layouts (docs/MEMORY.md),
// recomputed from the run's k(p) and n(p).
#include <gtest/gtest.h>

#include "mfr/method/dkb_features.hpp"

#include <algorithm>
#include <map>
#include <string>

#include "mfr/cpu/render.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

struct Frame {
  Scene scene;
  RasterFrame frame;
};

const RasterFrame& hairball() {
  static const Frame f = [] {
    Scene s = loadScene("procedural:hairball?strands=200").value();
    RasterFrame fr = RasterFrame::build(s, *s.defaultCamera, RasterOptions{72, 64, 16, 2}).value();
    return Frame{std::move(s), std::move(fr)};
  }();
  return f.frame;
}

// The CPU engine's documented buffers of one run (docs/MEMORY.md).
std::map<std::string, uint64_t> documentedCpuBuffers(const MethodDesc& m, const RenderOutput& out,
                                                     uint64_t pixels, bool parallel,
                                                     uint64_t abufferFragments) {
  std::map<std::string, uint64_t> b;
  if (m.allocation == AllocationPolicy::NoNodes) {  // wboit, mboit*: accumulators, no nodes
    // documented: wboit 20 B, mboit 36 B, mboit6 and mboit-trig3 44 B, mboit8 and mboit-trig4
    // 52 B, aoit4 44 B, aoit8 76 B, aoit16 140 B per pixel; the 16-bit moment forms 28, 32, 36 B;
    // peel 36 B, dual-peel 72 B; dfaoit 52 B; stochastic, stochastic-strat 52 B; hashed-alpha 8 B
    const uint64_t perPixel = m.compositing == Compositing::WeightedBlended       ? 20
                              : m.compositing == Compositing::MomentBased6        ? 44
                              : m.compositing == Compositing::MomentBased8        ? 52
                              : m.compositing == Compositing::MomentBasedTrig3    ? 44
                              : m.compositing == Compositing::MomentBasedTrig4    ? 52
                              : m.compositing == Compositing::MomentBased16       ? 28
                              : m.compositing == Compositing::MomentBased6_16     ? 32
                              : m.compositing == Compositing::MomentBased8_16     ? 36
                              : m.compositing == Compositing::MomentBasedTrig3_16 ? 32
                              : m.compositing == Compositing::MomentBasedTrig4_16 ? 36
                              : m.compositing == Compositing::Adaptive4           ? 44
                              : m.compositing == Compositing::Adaptive8           ? 76
                              : m.compositing == Compositing::Adaptive16          ? 140
                              : m.compositing == Compositing::DualPeel            ? 72
                              : m.compositing == Compositing::DeepApproximate     ? 52
                              : m.compositing == Compositing::Stochastic8         ? 52
                              : m.compositing == Compositing::StochasticStrat8    ? 52
                              : m.compositing == Compositing::HashedAlpha         ? 8
                                                                                  : 36;
    b["accumulators"] = perPixel * pixels;
    b["counters"] = 4 * pixels;  // the CPU engine's count of accumulated fragments
    b["k"] = 4 * pixels;
    b["offsets"] = 8 * pixels;
    b["store_kind"] = pixels;
    if (parallel) b["locks"] = 4 * pixels;
    return b;
  }
  if (m.allocation == AllocationPolicy::Pool) {  // linked lists: heads and the 12-byte pool
    b["nodes"] = 12 * out.stats.fragmentSlots;
    b["heads"] = 4 * pixels;
    b["counters"] = 4 * pixels;  // the CPU engine's list lengths
    b["k"] = 4 * pixels;
    b["offsets"] = 8 * pixels;
    b["store_kind"] = pixels;
    b["depth_complexity"] = 4 * pixels;
    if (m.compositing == Compositing::Hybrid) b["tail"] = 20 * pixels;
    return b;  // (no lock in either mode; the admission pass's scratch is checked by the caller)
  }
  const bool importance = m.allocation == AllocationPolicy::Importance;
  uint64_t materialised = 0;  // nodes: min(k(p), n(p)) for importance allocation, else k(p)
  for (size_t p = 0; p < pixels; ++p)
    materialised += importance ? std::min(out.kMap[p], out.depthComplexity[p]) : out.kMap[p];
  b["nodes"] = (m.store == StoreChoice::MultiLayer ? 20 : 8) * materialised;  // mlab: 20 B
  b["counters"] = 4 * pixels;
  b["k"] = 4 * pixels * (importance ? 2 : 1);  // k(p) [+ the reserved k(p) of importance]
  b["offsets"] = 8 * pixels;                   // 64-bit offsets
  b["store_kind"] = pixels;
  if (m.allocation != AllocationPolicy::FixedK) b["depth_complexity"] = 4 * pixels;
  if (parallel) b["locks"] = 4 * pixels;
  if (m.compositing == Compositing::Hybrid) b["tail"] = 20 * pixels;
  if (m.occupancyWords)
    b["occupancy"] = (12 + 4 * static_cast<uint64_t>(m.occupancyWords)) * pixels;
  if (m.allocation == AllocationPolicy::DynamicK) b["allocation_scratch"] = 1024 * 8;
  if (importance) b["allocation_scratch"] = 8 * pixels;
  if (importance && m.importanceSource == ImportanceSource::Heuristic) {
    b["importance"] = 5 * 4 * pixels;  // I, I_d, I_per, I_f, noise
    b["nearest_normal"] = 4 * pixels;
  }
  if (importance && m.importanceSource == ImportanceSource::Network) b["importance"] = 4 * pixels;
  if (m.allocation == AllocationPolicy::Optimal && m.predictedCurves) {
    b["oracle_k"] = 4 * pixels;
    // dkb-curve: a feature accumulator and 9 predictions per pixel, 12 features and 9 outputs
    // per covered pixel, the rebuilt curves (a vector per pixel, a double per fragment)
    uint64_t covered = 0;
    for (uint32_t n : out.depthComplexity) covered += n > 0;
    // (under hybrid compositing every covered pixel's curve starts at k = 0: one more double)
    const uint64_t fromZero = m.compositing == Compositing::Hybrid ? covered : 0;
    b["oracle_prepass"] = (sizeof(FeatureAccumulator) + 4 * 9) * pixels + (12 + 9) * 4 * covered +
                          8 * (abufferFragments + fromZero) + sizeof(std::vector<double>) * pixels;
  } else if (m.allocation == AllocationPolicy::Optimal) {
    b["oracle_k"] = 4 * pixels;
    // n(p) and the error curves (the A-buffer is tile-local: one tile's nodes per worker); under
    // hybrid compositing each covered pixel's curve starts at k = 0, the tail alone (one double)
    uint64_t covered = 0;
    for (uint32_t n : out.depthComplexity) covered += n > 0;
    const uint64_t fromZero = m.compositing == Compositing::Hybrid ? covered : 0;
    const uint64_t curves =
        8 * (abufferFragments + fromZero) + sizeof(std::vector<double>) * pixels;
    b["oracle_prepass"] = 4 * pixels + curves;
  }
  return b;
}

TEST(MemoryMeasured, BytesAllocatedFollowTheDocumentedCpuLayoutForEveryPreset) {
  const RasterFrame& frame = hairball();
  const uint64_t pixels = frame.pixelCount();
  const RenderOutput truth = render(frame, methodPreset("abuffer").value(), {}).value();
  const uint64_t fragments = truth.stats.fragmentsGenerated;
  int checked = 0;
  for (std::string name : presetNames())
    for (const char* suffix : {"", "+occupancy"})
      for (bool parallel : {false, true})
        for (Compositing rule : {Compositing::KBuffer, Compositing::Hybrid}) {
          if ((name == "abuffer" || name == "linked-list") && *suffix) continue;
          // the peer methods: no +occupancy, their own rule only (--composite does not apply)
          const bool peer = !kBufferFamilyRule(methodPreset(name).value().compositing);
          if (peer && (*suffix || rule == Compositing::Hybrid)) continue;
          MethodDesc m = methodPreset(name + suffix).value();
          if (!peer) m.compositing = rule;
          RenderOptions o;
          // (aoit16's fixed 140 B + lock per pixel take more than 600000 B here)
          if (name != "abuffer")
            o.budgetBytes =
                std::max<uint64_t>(600000, MemoryModel::of(m, parallel).overhead(pixels));
          o.capture = parallel ? CaptureMode::FragmentParallel : CaptureMode::TileOwned;
          auto out = render(frame, m, o);
          ASSERT_TRUE(out.ok()) << m.name << ": " << out.error().message;
          const std::string what = m.name + (parallel ? " parallel " : " tile ") + toString(rule);
          std::map<std::string, uint64_t> measured = out->stats.bytesAllocatedByCategory;
          if (m.allocation == AllocationPolicy::Pool) {
            // the admission pass: per tile its (primitive, fragments) runs (at most one per
            // fragment, a vector's growth at most doubling them), per primitive a count, the
            // boundary's pixels (fewer than the fragments), per tile its first node
            uint32_t primitives = 0;
            for (const TriangleSetup& t : frame.setups())
              primitives = std::max(primitives, t.prim + 1);
            EXPECT_GT(measured["allocation_scratch"], 8u * primitives) << what;
            EXPECT_LE(measured["allocation_scratch"],
                      8 * primitives + (16 + 4) * fragments + 64 * (frame.tileCount() + 1))
                << what;
            measured.erase("allocation_scratch");
          }
          EXPECT_EQ(measured, documentedCpuBuffers(m, out.value(), pixels, parallel, fragments))
              << what;
          uint64_t sum = 0;
          for (const auto& [category, bytes] : out->stats.bytesAllocatedByCategory) sum += bytes;
          EXPECT_EQ(out->stats.bytesAllocated, sum) << what;
          // the papers' accounting stays within the budget
          if (o.budgetBytes) {
            EXPECT_LE(out->stats.bytesUsed, *o.budgetBytes) << what;
          }
          ++checked;
        }
  // the peer methods (wboit, the mboit family, mlab, aoit, peel): one rule, no +occupancy, both
  // capture modes; abuffer and linked-list: no +occupancy
  int kPeers = 0;
  for (const std::string& name : presetNames())
    kPeers += kBufferFamilyRule(methodPreset(name).value().compositing) ? 0 : 1;
  EXPECT_GE(kPeers, 18);
  EXPECT_EQ(checked,
            4 * (2 + 2 * (static_cast<int>(presetNames().size()) - 2 - kPeers)) + 2 * kPeers);
}

TEST(MemoryMeasured, FragmentParallelModeChargesItsLockWordWithinTheBudget) {
  // fkb has no lock word of its own; fragment-parallel capture needs one per pixel, charged
  const RasterFrame& frame = hairball();
  const uint64_t pixels = frame.pixelCount();
  const MethodDesc fkb = methodPreset("fkb").value();
  // exactly one slot per pixel plus the counter: enough for tile-owned capture only
  const uint64_t budget = pixels * 4 + pixels * kNodeBytes;
  RenderOptions tile;
  tile.budgetBytes = budget;
  auto owned = render(frame, fkb, tile);
  ASSERT_TRUE(owned.ok()) << owned.error().message;
  EXPECT_EQ(owned->stats.globalK, 1u);
  EXPECT_FALSE(owned->stats.bytesByCategory.contains("locks"));
  EXPECT_EQ(owned->stats.bytesUsed, budget);

  RenderOptions parallel = tile;
  parallel.capture = CaptureMode::FragmentParallel;
  auto refused = render(frame, fkb, parallel);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("too small"), std::string::npos)
      << refused.error().message;

  parallel.budgetBytes = budget + pixels * 4;  // room for the lock words
  auto locked = render(frame, fkb, parallel);
  ASSERT_TRUE(locked.ok()) << locked.error().message;
  EXPECT_EQ(locked->stats.bytesByCategory.at("locks"), 4 * pixels);
  EXPECT_EQ(locked->stats.globalK, 1u);
  EXPECT_EQ(locked->stats.bytesUsed, *parallel.budgetBytes);
  EXPECT_EQ(locked->stats.bytesAllocatedByCategory.at("locks"), 4 * pixels);
}

}  // namespace
}  // namespace mfr
