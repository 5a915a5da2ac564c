#include "mfr/method/method.hpp"

#include "mfr/core/quote.hpp"
#include "mfr/core/suggest.hpp"
#include "mfr/method/peer_method.hpp"

namespace mfr {

namespace {

// The preset table: every preset's name, paper, one-line summary and fields. presetNames(),
// methodPreset(), `mfr render --help`, `mfr presets` (the README's table, checked by a test)
// and the compare report's legend all read it.
struct PresetRow {
  PresetInfo info;
  void (*configure)(MethodDesc&);
};

void kPlusCore(MethodDesc& m) {  // the k+-buffer family: k+ culling test under a per-pixel lock
  m.culling = CullingTest::KPlus;
  m.perPixelLock = true;
}

const std::vector<PresetRow>& presetRows() {
  static const std::vector<PresetRow> table = [] {
    std::vector<PresetRow> rows = {
        {{"zbuffer", "k+-buffer (Vasilakis & Fudos 2014), k = 1",
          "the nearest fragment only: the k+-buffer with k = 1"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::FixedK;
           m.store = StoreChoice::MaxArray;
           kPlusCore(m);
           m.k = 1;
         }},
        {{"abuffer", "A-buffer (Carpenter 1984)",
          "every fragment, sorted per pixel: the exact ground truth (no budget)"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::Unbounded;
           m.store = StoreChoice::Append;
         }},
        {{"fkb", "k-buffer (Bavoil et al. 2007)",
          "the same k for every pixel, max-array insertion without the k+ test"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::FixedK;
           m.store = StoreChoice::MaxArray;
           m.culling = CullingTest::None;
         }},
        {{"kplus-array", "k+-buffer (Vasilakis & Fudos 2014)",
          "fixed k, max-array store, k+ culling test, per-pixel lock"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::FixedK;
           m.store = StoreChoice::MaxArray;
           kPlusCore(m);
         }},
        {{"kplus-heap", "k+-buffer (Vasilakis & Fudos 2014)",
          "fixed k, max-heap store, k+ culling test, per-pixel lock"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::FixedK;
           m.store = StoreChoice::MaxHeap;
           kPlusCore(m);
         }},
        {{"kplus-sb", "k+-buffer K+B-SB (Vasilakis & Fudos 2014)",
          "count pass, min(n(p), k) slots per pixel at prefix-sum offsets (memory-exact)"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::CountedK;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
         }},
        {{"kplus-dynamic", "k+-buffer, dynamic k (Vasilakis & Fudos 2014)",
          "k chosen from the depth-complexity histogram, min(n(p), k) slots per pixel"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::DynamicK;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
         }},
        {{"vkb", "variable k-buffer (Vasilakis, Vardis, Papaioannou, Moustakas)",
          "k(p) from the importance map (depth complexity x periphery x Fresnel + noise)"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::Importance;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
         }},
        {{"vkb-fill", "variable k-buffer + mfr's slot filling",
          "vkb, with the slots it leaves unused handed to the most important pixels"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::Importance;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
           m.fillUnusedSlots = true;
         }},
        {{"dkb", "deep k-buffer (DHOIT: Tsopouridis, Fudos, Vasilakis)",
          "k(p) from the MLP's importance over 12 features; hybrid compositing"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::Importance;
           m.importanceSource = ImportanceSource::Network;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
           m.compositing = Compositing::Hybrid;  // deep hybrid transparency (DHOIT sec. 3.3)
         }},
        {{"dkb-fill", "deep k-buffer + mfr's slot filling",
          "dkb, with the slots it leaves unused handed to the most important pixels"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::Importance;
           m.importanceSource = ImportanceSource::Network;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
           m.compositing = Compositing::Hybrid;
           m.fillUnusedSlots = true;
         }},
        {{"dkb-curve", "mfr: DHOIT's features + the optimal k-buffer's hull allocation",
          "a network predicts each pixel's error-vs-k curve; k(p) by the oracle's hull allocator"},
         [](MethodDesc& m) {
           // beyond the paper (issue 14 sec. 4): the oracle's hull allocation over curves a network
           // predicts from the deep k-buffer's features (mfr/method/dkb_curve.hpp)
           m.allocation = AllocationPolicy::Optimal;
           m.predictedCurves = true;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
           m.compositing = Compositing::Hybrid;
         }},
        {{"optimal", "optimal k-buffer (DHOIT sec. 3.1.2; mfr's convex-hull allocator)",
          "exact A-buffer pre-pass, k(p) minimising the summed squared error under the budget"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::Optimal;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
           m.compositing = Compositing::Hybrid;  // the oracle minimises the hybrid error
         }},
        {{"optimal-greedy", "optimal k-buffer, DHOIT sec. 3.1.2 Algorithm 1 as published",
          "the paper's greedy min-heap allocation over the exact pre-pass"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::Optimal;
           m.store = StoreChoice::PerPixel;
           kPlusCore(m);
           m.compositing = Compositing::Hybrid;
           m.publishedGreedy = true;
         }},
    };
    // the peer methods (docs/METHODS.md), each described by its type (peer_method.hpp)
    PeerMethods::forEach([&]<class Peer>() {
      rows.push_back({Peer::preset(), configurePeerPreset<Peer>});
    });
    // per-pixel linked lists (mfr/method/linked_list.hpp): a pool allocation + the linked-list
    // store
    rows.push_back(
        {{"linked-list", "per-pixel linked lists (Yang, Hensley, Gruen, Thibieroz, EGSR 2010)",
          "head pointer per pixel + one pool of F(M) 12 B nodes; a full pool drops (or tails) "
          "the later fragments in primitive order"},
         [](MethodDesc& m) {
           m.allocation = AllocationPolicy::Pool;
           m.store = StoreChoice::LinkedList;
         }});
    return rows;
  }();
  return table;
}

}  // namespace

const std::vector<PresetInfo>& presetTable() {
  static const std::vector<PresetInfo> table = [] {
    std::vector<PresetInfo> t;
    for (const PresetRow& row : presetRows()) t.push_back(row.info);
    return t;
  }();
  return table;
}

std::vector<std::string> presetNames() {
  std::vector<std::string> names;
  for (const PresetRow& row : presetRows()) names.push_back(row.info.name);
  return names;
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
  const PresetRow* row = nullptr;
  for (const PresetRow& r : presetRows())
    if (r.info.name == name) row = &r;
  if (row == nullptr) {
    std::string known;
    std::vector<std::string> candidates;  // for "did you mean": every name that runs
    for (const std::string& n : presetNames()) {
      known += (known.empty() ? "" : ", ") + n;
      candidates.push_back(n);
    }
    for (const std::string& n : presetNames())
      if (methodPreset(n + suffix)) candidates.push_back(n + suffix);
    const std::string suggestion = didYouMean(fullName, candidates);
    return makeError("method " + quoteInput(fullName) + ": unknown" +
                     (suggestion.empty() ? "" : "; " + suggestion) + " (known: " + known +
                     ", each optionally with +occupancy)");
  }
  row->configure(m);
  if (occupancy) {
    if (!kBufferFamilyRule(m.compositing))
      return makeError("method '" + fullName + "': occupancy culling applies to k-buffers only");
    if (m.allocation == AllocationPolicy::Unbounded || m.allocation == AllocationPolicy::Pool)
      return makeError("method '" + fullName + "': occupancy culling needs a bounded k");
    m.occupancyWords = 1;
  }
  return m;
}

std::string presetTableMarkdown() {
  std::string md =
      "| preset | follows | what it keeps | compositing | `+occupancy` |\n|---|---|---|---|---|\n";
  for (const PresetInfo& p : presetTable()) {
    const MethodDesc m = methodPreset(p.name).value();
    md += "| `" + p.name + "` | " + p.paper + " | " + p.summary + " | " + toString(m.compositing) +
          " | " + (methodPreset(p.name + "+occupancy") ? "yes" : "no") + " |\n";
  }
  return md;
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
    case AllocationPolicy::Pool:
      return "pool";
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
    case StoreChoice::LinkedList:
      return "linked-list";
  }
  return "?";
}
const char* toString(CullingTest c) {
  return c == CullingTest::None ? "none" : "kplus";
}
const char* toString(Compositing c) {
  if (c == Compositing::KBuffer) return "kbuffer";
  if (c == Compositing::Hybrid) return "hybrid";
  const char* name = "?";
  visitPeer(c, [&]<class Peer>() { name = Peer::kRuleName; });
  return name;
}

bool kBufferFamilyRule(Compositing c) {
  // every other rule is a peer method's own (mfr/method/peer_method.hpp)
  return c == Compositing::KBuffer || c == Compositing::Hybrid;
}

Result<Compositing> parseCompositing(const std::string& text) {
  if (text == "kbuffer") return Compositing::KBuffer;
  if (text == "hybrid") return Compositing::Hybrid;
  return makeError("compositing " + quoteInput(text) + ": expected kbuffer or hybrid");
}

}  // namespace mfr
