#include "mfr/method/method.hpp"

#include "mfr/core/quote.hpp"

namespace mfr {

std::vector<std::string> presetNames() {
  return {"zbuffer", "abuffer",  "fkb", "kplus-array", "kplus-heap", "kplus-sb", "kplus-dynamic",
          "vkb",     "vkb-fill", "dkb", "dkb-fill",    "dkb-curve",  "optimal",  "optimal-greedy",
          "wboit",   "mboit",    "mlab"};
}

Result<MethodDesc> methodPreset(const std::string& fullName) {
  std::string name = fullName;
  bool occupancy = false;
  const std::string suffix = "+occupancy";
  if (name.size() > suffix.size() && name.ends_with(suffix)) {
    occupancy = true;
    name.resize(name.size() - suffix.size());
  }
  MethodDesc m;
  m.name = fullName;
  if (name == "zbuffer") {
    m.allocation = AllocationPolicy::FixedK;
    m.store = StoreChoice::MaxArray;
    m.culling = CullingTest::KPlus;
    m.perPixelLock = true;
    m.k = 1;
  } else if (name == "abuffer") {
    m.allocation = AllocationPolicy::Unbounded;
    m.store = StoreChoice::Append;
  } else if (name == "fkb") {
    m.allocation = AllocationPolicy::FixedK;
    m.store = StoreChoice::MaxArray;
    m.culling = CullingTest::None;
  } else if (name == "kplus-array" || name == "kplus-heap") {
    m.allocation = AllocationPolicy::FixedK;
    m.store = name == "kplus-array" ? StoreChoice::MaxArray : StoreChoice::MaxHeap;
    m.culling = CullingTest::KPlus;
    m.perPixelLock = true;
  } else if (name == "kplus-sb" || name == "kplus-dynamic") {
    m.allocation = name == "kplus-sb" ? AllocationPolicy::CountedK : AllocationPolicy::DynamicK;
    m.store = StoreChoice::PerPixel;
    m.culling = CullingTest::KPlus;
    m.perPixelLock = true;
  } else if (name == "vkb" || name == "vkb-fill") {
    m.allocation = AllocationPolicy::Importance;
    m.store = StoreChoice::PerPixel;
    m.culling = CullingTest::KPlus;
    m.perPixelLock = true;
    m.fillUnusedSlots = name == "vkb-fill";
  } else if (name == "dkb" || name == "dkb-fill") {
    m.allocation = AllocationPolicy::Importance;
    m.importanceSource = ImportanceSource::Network;
    m.store = StoreChoice::PerPixel;
    m.culling = CullingTest::KPlus;
    m.perPixelLock = true;
    m.compositing = Compositing::Hybrid;  // deep hybrid transparency (DHOIT sec. 3.3)
    m.fillUnusedSlots = name == "dkb-fill";
  } else if (name == "dkb-curve") {
    // beyond the paper (issue 14 sec. 4): the oracle's hull allocation over curves a network
    // predicts from the deep k-buffer's features (mfr/method/dkb_curve.hpp)
    m.allocation = AllocationPolicy::Optimal;
    m.predictedCurves = true;
    m.store = StoreChoice::PerPixel;
    m.culling = CullingTest::KPlus;
    m.perPixelLock = true;
    m.compositing = Compositing::Hybrid;
  } else if (name == "optimal" || name == "optimal-greedy") {
    m.allocation = AllocationPolicy::Optimal;
    m.store = StoreChoice::PerPixel;
    m.culling = CullingTest::KPlus;
    m.perPixelLock = true;
    m.compositing = Compositing::Hybrid;  // the oracle minimises the hybrid error
    m.publishedGreedy = name == "optimal-greedy";
  } else if (name == "wboit" || name == "mboit") {
    // the peer methods (README "Peer methods"): per-pixel accumulators, no fragment nodes
    m.allocation = AllocationPolicy::NoNodes;
    m.store = StoreChoice::None;
    m.compositing = name == "wboit" ? Compositing::WeightedBlended : Compositing::MomentBased;
  } else if (name == "mlab") {
    // k nodes per pixel from the budget like fkb, MLAB's store, the k+ family's per-pixel lock
    m.allocation = AllocationPolicy::FixedK;
    m.store = StoreChoice::MultiLayer;
    m.perPixelLock = true;
    m.compositing = Compositing::MultiLayerAlpha;
  } else {
    std::string known;
    for (const std::string& n : presetNames()) known += (known.empty() ? "" : ", ") + n;
    return makeError("method " + quoteInput(fullName) + ": unknown (known: " + known +
                     ", each optionally with +occupancy)");
  }
  if (occupancy) {
    if (!kBufferFamilyRule(m.compositing))
      return makeError("method '" + fullName + "': occupancy culling applies to k-buffers only");
    if (m.allocation == AllocationPolicy::Unbounded)
      return makeError("method '" + fullName + "': occupancy culling needs a bounded k");
    m.occupancyWords = 1;
  }
  return m;
}

const char* toString(AllocationPolicy a) {
  switch (a) {
    case AllocationPolicy::Unbounded:
      return "unbounded";
    case AllocationPolicy::FixedK:
      return "fixed-k";
    case AllocationPolicy::CountedK:
      return "counted-k";
    case AllocationPolicy::DynamicK:
      return "dynamic-k";
    case AllocationPolicy::Importance:
      return "importance";
    case AllocationPolicy::Optimal:
      return "optimal";
    case AllocationPolicy::NoNodes:
      return "no-nodes";
  }
  return "?";
}
const char* toString(StoreChoice s) {
  switch (s) {
    case StoreChoice::Append:
      return "append";
    case StoreChoice::MaxArray:
      return "max-array";
    case StoreChoice::MaxHeap:
      return "max-heap";
    case StoreChoice::PerPixel:
      return "per-pixel";
    case StoreChoice::MultiLayer:
      return "multi-layer";
    case StoreChoice::None:
      return "none";
  }
  return "?";
}
const char* toString(CullingTest c) {
  return c == CullingTest::None ? "none" : "kplus";
}
const char* toString(Compositing c) {
  switch (c) {
    case Compositing::KBuffer:
      return "kbuffer";
    case Compositing::Hybrid:
      return "hybrid";
    case Compositing::WeightedBlended:
      return "weighted-blended";
    case Compositing::MomentBased:
      return "moment-based";
    case Compositing::MultiLayerAlpha:
      return "multi-layer-alpha";
  }
  return "?";
}

bool kBufferFamilyRule(Compositing c) {
  switch (c) {
    case Compositing::KBuffer:
    case Compositing::Hybrid:
      return true;
    case Compositing::WeightedBlended:
    case Compositing::MomentBased:
    case Compositing::MultiLayerAlpha:
      return false;
  }
  return false;
}

Result<Compositing> parseCompositing(const std::string& text) {
  if (text == "kbuffer") return Compositing::KBuffer;
  if (text == "hybrid") return Compositing::Hybrid;
  return makeError("compositing " + quoteInput(text) + ": expected kbuffer or hybrid");
}

}  // namespace mfr
