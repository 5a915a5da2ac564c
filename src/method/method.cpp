#include "mfr/method/method.hpp"

namespace mfr {

std::vector<std::string> presetNames() {
  return {"zbuffer",  "abuffer",       "fkb",           "kplus-array", "kplus-heap",
          "kplus-sb", "kplus-dynamic", "vkb",           "vkb-fill",    "dkb",
          "dkb-fill", "optimal",       "optimal-greedy"};
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
  } else if (name == "optimal" || name == "optimal-greedy") {
    m.allocation = AllocationPolicy::Optimal;
    m.store = StoreChoice::PerPixel;
    m.culling = CullingTest::KPlus;
    m.perPixelLock = true;
    m.compositing = Compositing::Hybrid;  // the oracle minimises the hybrid error
    m.publishedGreedy = name == "optimal-greedy";
  } else {
    std::string known;
    for (const std::string& n : presetNames()) known += (known.empty() ? "" : ", ") + n;
    return makeError("method '" + fullName + "': unknown (known: " + known +
                     ", each optionally with +occupancy)");
  }
  if (occupancy) {
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
    default:
      return "optimal";
  }
}
const char* toString(StoreChoice s) {
  switch (s) {
    case StoreChoice::Append:
      return "append";
    case StoreChoice::MaxArray:
      return "max-array";
    case StoreChoice::MaxHeap:
      return "max-heap";
    default:
      return "per-pixel";
  }
}
const char* toString(CullingTest c) {
  return c == CullingTest::None ? "none" : "kplus";
}
const char* toString(Compositing c) {
  return c == Compositing::KBuffer ? "kbuffer" : "hybrid";
}

Result<Compositing> parseCompositing(const std::string& text) {
  if (text == "kbuffer") return Compositing::KBuffer;
  if (text == "hybrid") return Compositing::Hybrid;
  return makeError("compositing '" + text + "': expected kbuffer or hybrid");
}

}  // namespace mfr
