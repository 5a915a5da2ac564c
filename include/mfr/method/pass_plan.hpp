// Which passes one render of a method runs, decided once from its description and the options.
// Both engines execute this plan (the CPU engine's render(), the GL engine's render), and both
// report what they measured through fillSharedStats, which defines captured, lost, bytes and k
// for every engine:
//
//   [count | count + depth range] -> [nearest normal -> importance | features -> inference]
//   -> [oracle | curves] -> allocate -> [depth range -> occupancy fill -> occupancy count]
//   -> [peer passes, e.g. mboit's moments] -> capture -> resolve
// Depth peeling (peel, dual-peel) repeats its capture: its passes are "peel 1", "peel 2", ... (as
// many as the frame needs, at most MethodDesc::maxPeels), then "peel tail" under peelTail when
// fragments remain, in place of "capture".
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/render_output.hpp"

namespace mfr {

/// PassPlan::names()' entry for depth peeling's numbered passes "peel 1", "peel 2", ...
inline constexpr const char* kPeelPasses = "peel N";

/// The name of depth peeling's pass `index` (0-based): "peel 1", ...; and of its tail pass.
std::string peelPassName(uint32_t index);
inline constexpr const char* kPeelTailPass = "peel tail";

struct PassPlan {
  bool count = false;          // n(p) before the allocation (exact, counted, dynamic, importance k)
  bool depthRange = false;     // the count pass also finds the image's depth range (dkb's input)
  bool nearestNormal = false;  // vkb: |n.v| of each pixel's nearest fragment
  bool heuristicImportance = false;  // vkb: I(p) from n(p), periphery, Fresnel, noise (Eqs. 3-6)
  bool networkImportance = false;    // dkb: 12 features per pixel, then the MLP's I(p)
  bool oracle = false;               // optimal: exact A-buffer pre-pass, error curves, allocation
  bool predictedCurves = false;      // dkb-curve: curves predicted from the features, allocation
  bool occupancy = false;            // depth range, occupancy fill and count before the capture
  /// The peer method's own geometry passes before its capture (mboit: "moments").
  std::vector<std::string> peerPasses;
  bool tail = false;  // hybrid compositing: the order-independent tail beside the core
  /// Depth peeling: the capture repeated, at most maxPeels times (none: until nothing remains),
  /// then the tail pass under tail.
  bool peel = false;
  std::optional<uint32_t> maxPeels;

  /// The passes in order, as RenderStats::passes names them ("count", "allocate", ...); depth
  /// peeling's passes, whose number the frame decides, are the one entry "peel N" (kPeelPasses).
  std::vector<std::string> names() const;
};

/// The plan, after the checks every engine shares: the store, allocation and compositing rule go
/// together (the append store with exact allocation, the peer rules with their own store),
/// occupancy culling needs a bounded k-buffer, importance and the network need a budget.
Result<PassPlan> planPasses(const MethodDesc& method, const RenderOptions& options);

/// How a multisampled render of `method` stores its samples: the requested discipline
/// (RenderOptions::sampleStorage), except that the methods without per-pixel nodes of their own
/// store per sample whatever is asked: the peer methods and depth peeling (their state
/// accumulates per sample, as in a multisampled target) and the optimal oracle (its error curves
/// composite samples, not coverage masks).
SampleStorage sampleStorageOf(const MethodDesc& method, const RenderOptions& options);

/// What an engine measured in one render, for fillSharedStats.
struct SharedMeasures {
  const MethodDesc& method;
  const MemoryModel& memory;
  const Allocation& allocation;
  /// n(p) from the plan's count pass (or the oracle's pre-pass); empty when the plan has none.
  const std::vector<uint32_t>& depthComplexity;
  /// The fragments each pixel's store holds after the capture (nodes in use; for an accumulator
  /// every fragment it took), as the engine counted them.
  const std::vector<uint32_t>& held;
  /// Or, where `held` is empty, n(p) as the engine's capture saw it: every store holds
  /// min(n(p), k(p)) nodes, an accumulator all n(p) fragments.
  const std::vector<uint32_t>& captureCounts;
  uint64_t fragmentsGenerated = 0;
  std::optional<uint64_t> budgetBytes;
};

/// The statistics every engine reports the same way: the method, the budget, bytes used and by
/// category (MemoryModel), fragment slots, fragments generated, captured (held in the stores at
/// the end) and lost (generated - captured), covered pixels (n(p) > 0, or a held fragment when
/// no count ran), k over the covered pixels (as allocated: an importance allocation may reserve
/// more than n(p)), the global k and the depth complexity.
void fillSharedStats(const SharedMeasures& measured, RenderStats& stats);

}  // namespace mfr
