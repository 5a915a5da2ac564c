// planPasses and fillSharedStats (pass_plan.hpp).
#include "mfr/method/pass_plan.hpp"

#include <algorithm>

#include "mfr/method/peer_method.hpp"

namespace mfr {
namespace {

/// The combinations of store, allocation and rule a method may have.
Result<void> checkComposition(const MethodDesc& m) {
  if (m.occupancyWords < 0 || m.occupancyWords > 64)
    return makeError(m.name + ": occupancy d must be in [1, 64]");
  if (m.allocation == AllocationPolicy::Unbounded && m.occupancyWords > 0)
    return makeError(m.name + ": occupancy culling needs a bounded k");
  if (m.store == StoreChoice::Append && m.allocation != AllocationPolicy::Unbounded)
    return makeError(m.name + ": the append store needs exact (unbounded) allocation");
  // the peer methods' rules go with their own allocation and store (docs/METHODS.md): an
  // accumulating one with no nodes, one of nodes with the multi-layer store and fixed k
  bool accumulates = false, peerNodes = false;
  visitPeer(m.compositing, [&]<class Peer>() {
    accumulates = !Peer::kNodes;
    peerNodes = Peer::kNodes;
  });
  if (accumulates != (m.allocation == AllocationPolicy::NoNodes) ||
      accumulates != (m.store == StoreChoice::None))
    return makeError(m.name + ": " + toString(m.compositing) +
                     " compositing goes with no-nodes allocation and no store, and only it");
  if (peerNodes != (m.store == StoreChoice::MultiLayer) ||
      (m.store == StoreChoice::MultiLayer && m.allocation != AllocationPolicy::FixedK))
    return makeError(m.name + ": the multi-layer store goes with fixed k and " +
                     "multi-layer-alpha compositing, and only them");
  if ((m.store == StoreChoice::LinkedList) != (m.allocation == AllocationPolicy::Pool) ||
      (m.store == StoreChoice::LinkedList && !kBufferFamilyRule(m.compositing)))
    return makeError(m.name + ": the linked-list store goes with the pool allocation and " +
                     "kbuffer or hybrid compositing, and only them");
  if (m.allocation == AllocationPolicy::Pool && m.occupancyWords > 0)
    return makeError(m.name + ": occupancy culling needs a bounded k");
  if (!kBufferFamilyRule(m.compositing) && m.occupancyWords > 0)
    return makeError(m.name + ": occupancy culling applies to k-buffers only");
  return {};
}

}  // namespace

std::string peelPassName(uint32_t index) {
  return "peel " + std::to_string(index + 1);
}

std::vector<std::string> PassPlan::names() const {
  std::vector<std::string> n;
  if (count) n.push_back("count");
  if (nearestNormal) n.push_back("nearest_normal");
  if (heuristicImportance) n.push_back("importance");
  if (networkImportance) {
    n.push_back("features");
    n.push_back("inference");
  }
  if (predictedCurves) n.push_back("curves");
  if (oracle) n.push_back("oracle");
  n.push_back("allocate");
  n.push_back("clear");
  if (occupancy)
    for (const char* pass : {"depth_range", "occupancy_fill", "occupancy_count"}) n.push_back(pass);
  for (const std::string& pass : peerPasses) n.push_back(pass);
  n.push_back(peel ? kPeelPasses : "capture");
  n.push_back("resolve");
  return n;
}

Result<PassPlan> planPasses(const MethodDesc& m, const RenderOptions& options) {
  MFR_TRY(checkComposition(m));
  PassPlan plan;
  const bool importance = m.allocation == AllocationPolicy::Importance;
  plan.networkImportance = importance && m.importanceSource == ImportanceSource::Network;
  plan.heuristicImportance = importance && !plan.networkImportance;
  plan.nearestNormal = plan.heuristicImportance;
  plan.depthRange = plan.networkImportance;
  const bool optimal = m.allocation == AllocationPolicy::Optimal && options.budgetBytes;
  plan.predictedCurves = optimal && m.predictedCurves;
  plan.oracle = optimal && !m.predictedCurves;
  // the optimal k-buffer counts in its own pre-pass; fixed k and the accumulators need no n(p)
  plan.count = m.allocation != AllocationPolicy::FixedK &&
               m.allocation != AllocationPolicy::NoNodes && !optimal;
  if (plan.networkImportance && !options.budgetBytes) return makeError(m.name + ": needs a budget");
  plan.occupancy = m.occupancyWords > 0;
  plan.tail = m.compositing == Compositing::Hybrid || m.peelTail;
  visitPeer(m.compositing, [&]<class Peer>() {
    for (const char* pass : Peer::kExtraPasses) plan.peerPasses.push_back(pass);
    plan.peel = peerRepeatsCapture<Peer>();
  });
  if (!plan.peel && (m.maxPeels || m.peelTail))
    return makeError(m.name +
                     ": --max-peels and the peeled hybrid tail apply to depth peeling "
                     "(peel, dual-peel) only");
  if (m.maxPeels && *m.maxPeels == 0) return makeError(m.name + ": --max-peels must be >= 1");
  plan.maxPeels = m.maxPeels;
  return plan;
}

void fillSharedStats(const SharedMeasures& in, RenderStats& s) {
  const Allocation& a = in.allocation;
  const std::vector<uint32_t>& n = in.depthComplexity;
  const size_t pixels = a.capacity.size();
  const bool accumulates = in.method.allocation == AllocationPolicy::NoNodes;
  const std::vector<uint32_t>& seen = in.captureCounts;
  MFR_CHECK(in.held.size() == pixels || (in.held.empty() && seen.size() == pixels));
  MFR_CHECK(n.empty() || n.size() == pixels);
  s.method = in.method.name;
  s.budgetBytes = in.budgetBytes;
  s.fragmentSlots = a.reservedSlots;
  s.bytesByCategory = in.memory.breakdown(pixels, a.reservedSlots);
  s.bytesUsed = 0;
  for (const auto& [category, bytes] : s.bytesByCategory) s.bytesUsed += bytes;
  if (in.budgetBytes) MFR_CHECK_LE(s.bytesUsed, *in.budgetBytes);
  s.fragmentsGenerated = in.fragmentsGenerated;
  s.globalK = a.globalK;
  // the k reported: as allocated (importance may reserve more slots than n(p))
  const std::vector<uint32_t>& reported = a.reservedK.empty() ? a.capacity : a.reservedK;
  uint32_t kMin = UINT32_MAX, kMax = 0, maxN = 0;
  uint64_t sumN = 0;
  s.captured = 0;
  s.coveredPixels = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const uint32_t held = !in.held.empty() ? in.held[p]
                          : accumulates    ? seen[p]
                                           : std::min(seen[p], a.capacity[p]);
    s.captured += held;
    const bool covered = n.empty() ? held > 0 : n[p] > 0;
    if (!covered) continue;
    ++s.coveredPixels;
    kMin = std::min(kMin, reported[p]);
    kMax = std::max(kMax, reported[p]);
    if (!n.empty()) {
      sumN += n[p];
      maxN = std::max(maxN, n[p]);
    }
  }
  s.kMin = s.coveredPixels ? kMin : 0;
  s.kMax = kMax;
  s.lost = s.fragmentsGenerated - s.captured;
  s.maxDepthComplexity.reset();
  s.meanDepthComplexity.reset();
  if (!n.empty()) {
    s.maxDepthComplexity = maxN;
    s.meanDepthComplexity = s.coveredPixels ? static_cast<double>(sumN) / s.coveredPixels : 0.0;
  }
}

SampleStorage sampleStorageOf(const MethodDesc& method, const RenderOptions& options) {
  if (options.sampleStorage == SampleStorage::Sample) return SampleStorage::Sample;
  const bool ownState = visitPeer(method.compositing, []<class>() {});
  const bool oracle = method.allocation == AllocationPolicy::Optimal && !method.predictedCurves;
  return ownState || oracle ? SampleStorage::Sample : SampleStorage::Pixel;
}

}  // namespace mfr
