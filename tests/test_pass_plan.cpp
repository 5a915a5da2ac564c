// The pass plan (mfr/method/pass_plan.hpp): which passes each preset runs, written out here by
// hand from the papers' pass structures; the CPU engine runs exactly the plan's passes for every
// preset; the composition checks every engine shares; fillSharedStats' definitions of captured,
// lost and k on a hand-made allocation.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/pass_plan.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

using Names = std::vector<std::string>;

RenderOptions withBudget(uint64_t bytes) {
  RenderOptions o;
  o.budgetBytes = bytes;
  return o;
}

TEST(PassPlan, EachPresetsPassesAsItsPaperRunsThem) {
  const Names capture = {"clear", "capture", "resolve"};
  const auto with = [&](Names before) {
    before.push_back("allocate");
    before.insert(before.end(), capture.begin(), capture.end());
    return before;
  };
  const std::map<std::string, Names> expected = {
      {"zbuffer", with({})},                                     // fixed k = 1
      {"fkb", with({})},                                         // fixed k: no n(p)
      {"kplus-heap", with({})},                                  // fixed k
      {"abuffer", with({"count"})},                              // exact slots from n(p)
      {"kplus-sb", with({"count"})},                             // K+B-SB: count, prefix sum
      {"kplus-dynamic", with({"count"})},                        // k from n(p)'s histogram
      {"vkb", with({"count", "nearest_normal", "importance"})},  // Eqs. 3-6
      {"dkb", with({"count", "features", "inference"})},         // DHOIT: features + MLP
      {"optimal", with({"oracle"})},                             // A-buffer pre-pass, curves
      {"dkb-curve", with({"curves"})},                           // predicted curves
      {"wboit", with({})},                                       // one accumulation pass
      {"mlab", with({})},                                        // blended nodes, fixed k
  };
  for (const auto& [name, passes] : expected) {
    SCOPED_TRACE(name);
    auto plan = planPasses(methodPreset(name).value(), withBudget(1 << 20));
    ASSERT_TRUE(plan.ok()) << plan.error().message;
    EXPECT_EQ(plan->names(), passes);
  }
  // mboit: its moments pass before the capture; occupancy: three passes after the allocation
  EXPECT_EQ(planPasses(methodPreset("mboit").value(), withBudget(1 << 20))->names(),
            (Names{"allocate", "clear", "moments", "capture", "resolve"}));
  // aoit: its visibility pass (the compressed visibility function) before the capture
  for (const char* aoit : {"aoit4", "aoit8", "aoit16"})
    EXPECT_EQ(planPasses(methodPreset(aoit).value(), withBudget(1 << 20))->names(),
              (Names{"allocate", "clear", "visibility", "capture", "resolve"}))
        << aoit;
  // stochastic transparency: the total-alpha and the stochastic-depth passes before the capture
  // (the accumulation); hashed alpha: its one pass into the z-buffer
  for (const char* stochastic : {"stochastic", "stochastic-strat"})
    EXPECT_EQ(planPasses(methodPreset(stochastic).value(), withBudget(1 << 20))->names(),
              (Names{"allocate", "clear", "total-alpha", "stochastic-depth", "capture", "resolve"}))
        << stochastic;
  EXPECT_EQ(planPasses(methodPreset("hashed-alpha").value(), withBudget(1 << 20))->names(),
            (Names{"allocate", "clear", "capture", "resolve"}));
  EXPECT_EQ(planPasses(methodPreset("kplus-sb+occupancy").value(), withBudget(1 << 20))->names(),
            (Names{"count", "allocate", "clear", "depth_range", "occupancy_fill", "occupancy_count",
                   "capture", "resolve"}));
  // hybrid compositing adds the tail, no pass
  MethodDesc hybrid = methodPreset("fkb").value();
  hybrid.compositing = Compositing::Hybrid;
  EXPECT_TRUE(planPasses(hybrid, withBudget(1 << 20))->tail);
  EXPECT_FALSE(planPasses(methodPreset("fkb").value(), withBudget(1 << 20))->tail);
}

TEST(PassPlan, TheCpuEngineRunsThePlanOfEveryPreset) {
  const Scene scene = loadScene("procedural:bottles?count=3").value();
  CpuEngine cpu(EngineOptions{2, 16});
  const View view{&scene, *scene.defaultCamera, 40, 32};
  int checked = 0;
  for (const std::string& base : presetNames())
    for (const std::string& name : {base, base + "+occupancy"}) {
      auto method = methodPreset(name);
      if (!method) continue;  // the peer methods have no +occupancy
      SCOPED_TRACE(name);
      const RenderOptions options = withBudget(256 << 10);
      auto plan = planPasses(*method, options);
      ASSERT_TRUE(plan.ok()) << plan.error().message;
      auto out = cpu.render(view, *method, options);
      ASSERT_TRUE(out.ok()) << out.error().message;
      Names ran;
      for (const PassTime& t : out->stats.passes) {
        // depth peeling's numbered passes are the plan's one entry "peel N"
        const bool peelPass =
            plan->peel && t.name.rfind("peel ", 0) == 0 && t.name != kPeelTailPass;
        if (peelPass && !ran.empty() && ran.back() == kPeelPasses) continue;
        ran.push_back(peelPass ? std::string(kPeelPasses) : t.name);
      }
      EXPECT_EQ(ran, plan->names());
      EXPECT_EQ(out->depthComplexity.empty(),
                !(plan->count || plan->oracle || plan->predictedCurves));
      ++checked;
    }
  EXPECT_GE(checked, 30);  // every bounded preset twice (abuffer once), the peers once
}

TEST(PassPlan, CompositionErrorsAreOneLineNamingTheMethod) {
  MethodDesc m = methodPreset("fkb").value();
  m.store = StoreChoice::MultiLayer;  // MLAB's nodes under k-buffer compositing
  auto bad = planPasses(m, withBudget(1 << 20));
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message,
            "fkb: the multi-layer store goes with fixed k and multi-layer-alpha compositing, and "
            "only them");
  MethodDesc occ = methodPreset("abuffer").value();
  occ.occupancyWords = 1;
  EXPECT_EQ(planPasses(occ, {}).error().message, "abuffer: occupancy culling needs a bounded k");
  EXPECT_EQ(planPasses(methodPreset("dkb").value(), {}).error().message, "dkb: needs a budget");
  // the optimal k-buffer without a budget has no oracle to run: allocate() refuses it
  auto optimal = planPasses(methodPreset("optimal").value(), {});
  ASSERT_TRUE(optimal.ok());
  EXPECT_FALSE(optimal->oracle);
}

TEST(SharedStats, CapturedLostAndKFromTheStoresOrTheCounts) {
  // four pixels: n = 0, 1, 3, 5 under k = 2 (fixed): the stores hold 0, 1, 2, 2
  const MethodDesc m = methodPreset("fkb").value();
  const MemoryModel memory = MemoryModel::of(m);
  Allocation a;
  a.capacity = {2, 2, 2, 2};
  a.offsets = {0, 2, 4, 6};
  a.slots = a.reservedSlots = 8;
  a.globalK = 2;
  const std::vector<uint32_t> n = {0, 1, 3, 5}, held = {0, 1, 2, 2}, none;
  RenderStats fromCounts, fromStores;
  fillSharedStats({m, memory, a, none, none, n, 9, 100}, fromCounts);
  fillSharedStats({m, memory, a, none, held, none, 9, 100}, fromStores);
  for (const RenderStats* s : {&fromCounts, &fromStores}) {
    EXPECT_EQ(s->captured, 5u);
    EXPECT_EQ(s->lost, 4u);
    EXPECT_EQ(s->coveredPixels, 3u);  // a held fragment, without a count pass
    EXPECT_EQ(s->kMin, 2u);
    EXPECT_EQ(s->kMax, 2u);
    EXPECT_EQ(s->fragmentSlots, 8u);
    EXPECT_EQ(s->bytesUsed, 8u * 8 + 4u * 4);  // nodes + counters
    EXPECT_FALSE(s->maxDepthComplexity.has_value());
  }
  // with the count pass's n(p): its depth complexity over the covered pixels
  RenderStats counted;
  fillSharedStats({m, memory, a, n, held, none, 9, 100}, counted);
  EXPECT_EQ(counted.maxDepthComplexity, 5u);
  EXPECT_DOUBLE_EQ(*counted.meanDepthComplexity, 3.0);
  // an accumulator holds every fragment it took
  const MethodDesc w = methodPreset("wboit").value();
  Allocation none4;
  none4.capacity = {0, 0, 0, 0};
  RenderStats wboit;
  fillSharedStats({w, MemoryModel::of(w), none4, none, none, n, 9, 100}, wboit);
  EXPECT_EQ(wboit.captured, 9u);
  EXPECT_EQ(wboit.lost, 0u);
  EXPECT_EQ(wboit.bytesUsed, 4u * 20);
}

}  // namespace
}  // namespace mfr
