// Budgets from the scene (scene_budgets.hpp): binary searches over the budget with allocate(), the
// function that decides a render's allocation, on the frame's count pass.
#include "mfr/engine/scene_budgets.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>

#include "mfr/core/units.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/method/pass_plan.hpp"
#include "mfr/method/peel.hpp"

namespace mfr {
namespace {

// the largest budget searched: parseByteSize's limit
constexpr uint64_t kLargestBudget = 1ull << 40;

// What every search over one method's budgets reads.
struct BudgetSearch {
  const MethodDesc& method;
  const MemoryModel& memory;
  PixelLayout layout;                    // the storage pixels (W*S x H under per-sample storage)
  const std::vector<uint32_t>& n;        // n(p) per storage pixel
  const std::vector<float>& importance;  // the importance policies' I(p)
  bool importanceIsRender = false;       // I(p) is render()'s map (else a flat stand-in)
  std::vector<uint32_t> oracleK;         // the optimal policies' k(p) (zeros: only the checks run)
  uint64_t fragments = 0;                // sum n(p)
  uint32_t maxN = 0;

  Result<Allocation> allocateAt(uint64_t budget) const {
    return allocate(layout, method, memory, budget, n, importance, oracleK);
  }
  bool accepts(uint64_t budget) const { return allocateAt(budget).ok(); }
  // every fragment gets a slot: k(p) >= n(p) everywhere (the pool: N nodes)
  bool keepsAll(uint64_t budget) const {
    auto a = allocateAt(budget);
    if (!a) return false;
    if (method.allocation == AllocationPolicy::Pool) return a->slots >= fragments;
    for (size_t p = 0; p < n.size(); ++p)
      if (a->capacity[p] < n[p]) return false;
    return true;
  }
  // bytes of F nodes on top of the per-pixel and per-image words
  uint64_t bytesOf(long double nodes) const {
    const long double bytes = static_cast<long double>(memory.overhead(layout.pixels())) +
                              nodes * static_cast<long double>(memory.node);
    return bytes >= static_cast<long double>(kLargestBudget) ? kLargestBudget
                                                             : static_cast<uint64_t>(bytes);
  }
};

// The smallest budget in [lo, hi] at which `holds` is true, given that it holds at hi and, as the
// budget grows, never stops holding: the `candidates` first (where the policies' rules put the
// answer; one that holds while a byte less does not is the answer), then a binary search between
// the largest that fails and the smallest that holds. Every answer is checked by `holds` itself.
uint64_t smallestHolding(uint64_t lo, uint64_t hi, std::vector<uint64_t> candidates,
                         const std::function<bool(uint64_t)>& holds) {
  std::sort(candidates.begin(), candidates.end());
  for (uint64_t c : candidates) {
    if (c < lo || c > hi) continue;
    if (!holds(c)) {
      lo = c + 1;
      continue;
    }
    if (c == lo || !holds(c - 1)) return c;
    hi = c - 1;
    break;
  }
  while (lo < hi) {
    const uint64_t mid = lo + (hi - lo) / 2;
    if (holds(mid))
      hi = mid;
    else
      lo = mid + 1;
  }
  return hi;
}

// An upper bound of the search: a budget that holds, from `guess` doubled up to kLargestBudget.
std::optional<uint64_t> holdingAbove(uint64_t guess, const std::function<bool(uint64_t)>& holds) {
  for (uint64_t b = std::max<uint64_t>(guess, 1);; b = std::min(kLargestBudget, b * 2)) {
    if (holds(b)) return b;
    if (b >= kLargestBudget) return std::nullopt;
  }
}

void findExact(const BudgetSearch& s, MethodBudget& row) {
  const MethodDesc& m = s.method;
  if (m.allocation == AllocationPolicy::NoNodes) {
    if (peelingRule(m.compositing) && !m.maxPeels) {
      row.exactBytes = row.fixedBytes;
      row.note = "exact by passes, not bytes: peels until no fragment remains";
    } else if (peelingRule(m.compositing)) {
      row.note = "never exact: --max-peels " + std::to_string(*m.maxPeels) +
                 " ends the peeling (without it, exact at its fixed memory)";
    } else {
      row.note = std::string("never exact: ") + toString(m.compositing) +
                 " approximates the fragments it accumulates";
    }
    return;
  }
  if (s.fragments == 0) {  // nothing to keep: exact wherever it runs
    row.exactBytes = row.minimumBytes;
    return;
  }
  const bool network = m.allocation == AllocationPolicy::Importance &&
                       m.importanceSource == ImportanceSource::Network;
  if (network && !m.fillUnusedSlots) {
    row.note =
        "exact budget not computed: the network reads F(M) as a feature, so k(p) at one budget "
        "says nothing of another (render and read lost)";
    return;
  }
  if (m.allocation == AllocationPolicy::Importance && !m.fillUnusedSlots && !s.importanceIsRender) {
    row.note = "exact budget not computed: no importance map of this view's storage pixels";
    return;
  }
  if (m.k && s.maxN > *m.k &&
      (m.allocation == AllocationPolicy::FixedK || m.allocation == AllocationPolicy::CountedK)) {
    row.note = "never exact: k = " + std::to_string(*m.k) + " is below the largest n(p), " +
               std::to_string(s.maxN);
    return;
  }
  if (m.allocation == AllocationPolicy::DynamicK &&
      s.maxN > std::min<uint64_t>(m.k.value_or(kHistogramBins - 1), kHistogramBins - 1)) {
    row.note =
        "never exact: its k stops at " +
        std::to_string(std::min<uint64_t>(m.k.value_or(kHistogramBins - 1), kHistogramBins - 1)) +
        ", below the largest n(p), " + std::to_string(s.maxN);
    return;
  }
  std::function<bool(uint64_t)> holds;
  uint64_t guess = 0;
  // where the rules put it: N nodes (the count-pass policies, the pool), max n(p) per pixel
  // (fixed and counted k), the importance rule's bound
  std::vector<uint64_t> candidates = {
      s.bytesOf(static_cast<long double>(s.fragments)),
      s.bytesOf(static_cast<long double>(s.layout.pixels()) * s.maxN)};
  if (m.allocation == AllocationPolicy::Optimal) {
    // the oracle gives every pixel all its fragments once they all fit (optimal_allocation's
    // all-fit), and no allocation keeps N fragments in fewer than N slots
    holds = [&s](uint64_t b) {
      return s.accepts(b) && s.memory.fragmentSlots(b, s.layout.pixels()) >= s.fragments;
    };
    guess = s.bytesOf(static_cast<long double>(s.fragments));
    row.note = "all-fit: every fragment fits in F(M)";
  } else {
    holds = [&s](uint64_t b) { return s.keepsAll(b); };
    long double nodes = std::max<long double>(
        s.fragments, static_cast<long double>(s.layout.pixels()) * std::max<uint32_t>(s.maxN, 1));
    if (m.allocation == AllocationPolicy::Importance && !m.fillUnusedSlots) {
      // k(p) = floor(I(p) / sum I * F): F >= n(p) sum I / I(p) at every covered pixel (the
      // sum as allocate() takes it; the float rounding either side is the search's)
      double total = 0.0;
      for (float i : s.importance) total += i;
      double least = 0.0;
      for (size_t p = 0; p < s.n.size(); ++p) {
        if (s.n[p] == 0) continue;
        if (!(s.importance[p] > 0.0f)) {
          row.note = "never exact: a covered pixel has importance 0";
          return;
        }
        least = std::max(least, std::ceil(s.n[p] * total / s.importance[p]));
      }
      for (double d : {-1.0, 0.0, 1.0})
        candidates.push_back(s.bytesOf(static_cast<long double>(std::max(0.0, least + d))));
      nodes = std::max<long double>(nodes, least + 2.0);
    }
    guess = s.bytesOf(nodes + 1.0L);
  }
  auto hi = holdingAbove(guess, holds);
  if (!hi) {
    row.note = "never exact below 1 TiB";
    return;
  }
  row.exactBytes = smallestHolding(row.minimumBytes.value_or(0), *hi, candidates, holds);
}

// fixed memory: the accumulators, the A-buffer, an explicit k under fixed or counted k
void findFixed(const BudgetSearch& s, MethodBudget& row) {
  const MethodDesc& m = s.method;
  const bool explicitK = m.k && (m.allocation == AllocationPolicy::FixedK ||
                                 m.allocation == AllocationPolicy::CountedK);
  if (m.allocation != AllocationPolicy::NoNodes && m.allocation != AllocationPolicy::Unbounded &&
      !explicitK)
    return;
  if (!row.minimumBytes) return;
  auto a = s.allocateAt(*row.minimumBytes);
  if (a) row.fixedBytes = s.memory.overhead(s.layout.pixels()) + a->reservedSlots * s.memory.node;
}

// What the rows of one frame share, counted once: n(p) per image pixel (the relative budgets'
// counts) and per storage pixel of each discipline, the view's nearest |n.v|.
struct FrameData {
  Engine& engine;
  const PreparedView& view;
  std::optional<std::vector<uint32_t>> imageCounts;
  std::optional<std::vector<uint32_t>> storageCounts[2];  // by SampleStorage
  std::optional<std::vector<float>> cosine;

  Result<const std::vector<uint32_t>*> image() {
    if (!imageCounts) {
      auto counted = engine.countFragments(view);
      if (!counted) return counted.error();
      imageCounts = std::move(counted.value());
    }
    return &*imageCounts;
  }
  Result<const std::vector<uint32_t>*> storage(SampleStorage storage) {
    if (view.samples() == 1) return image();
    std::optional<std::vector<uint32_t>>& counts = storageCounts[static_cast<int>(storage)];
    if (!counts) {
      auto counted = engine.storageFragmentCounts(view, storage);
      if (!counted) return counted.error();
      counts = std::move(counted.value());
    }
    return &*counts;
  }
  Result<const std::vector<float>*> nearestCosine() {
    if (!cosine) {
      auto own = engine.nearestCosine(view);
      if (!own) return own.error();
      cosine = std::move(own.value());
    }
    return &*cosine;
  }
};

Result<MethodBudget> rowOf(FrameData& frame, const MethodDesc& method,
                           const RenderOptions& options) {
  Engine& engine = frame.engine;
  const PreparedView& view = frame.view;
  MethodBudget row;
  row.method = method.name;
  const SampleStorage storage = sampleStorageOf(method, options);
  const MemoryModel memory = engine.memoryModel(method, options);
  // refused at every budget: the engine's pre-flight (the memory limit) or the pass plan
  if (auto fits = engine.preflight(view.width(), view.height(), method, options); !fits) {
    row.note = "refused at any budget: " + fits.error().message;
    return row;
  }
  RenderOptions budgeted = options;
  budgeted.budgetBytes = kLargestBudget;
  if (auto plan = planPasses(method, budgeted); !plan) {
    row.note = "refused at any budget: " + plan.error().message;
    return row;
  }
  auto counted = frame.storage(storage);
  if (!counted) {
    row.note = "not computed: " + counted.error().message;
    return row;
  }
  const std::vector<uint32_t>& n = **counted;
  // the relative budgets' counts, as compare and render resolve them
  auto imageCounts = frame.image();
  if (!imageCounts) return imageCounts.error();
  FrameCounts relative = FrameCounts::of(**imageCounts);
  relative.pixels = view.storagePixels(storage);

  const int height = view.height();
  PixelLayout layout{height > 0 ? static_cast<int>(n.size() / static_cast<size_t>(height)) : 0,
                     height, 0};
  // the importance map render() computes for the variable k-buffer (the paper's rule reads it;
  // the fill variant keeps every fragment from N slots whatever the map, and whether a budget is
  // accepted never depends on it, so elsewhere a flat one serves)
  std::vector<float> importance;
  bool importanceIsRender = false;
  if (method.allocation == AllocationPolicy::Importance) {
    const bool sameLayout = n.size() == view.pixelCount();
    if (method.importanceSource == ImportanceSource::Heuristic && sameLayout) {
      const std::vector<float>* cosine = nullptr;
      if (options.previousNearestCosine && options.previousNearestCosine->size() == n.size()) {
        cosine = options.previousNearestCosine;
      } else {
        auto own = frame.nearestCosine();
        if (!own) return own.error();
        cosine = *own;
      }
      importance =
          computeImportance(layout.width, layout.height, n, *cosine, method.importance).importance;
      importanceIsRender = true;
    } else {
      importance.assign(n.size(), 0.0f);
      for (size_t p = 0; p < n.size(); ++p) importance[p] = n[p] > 0 ? 1.0f : 0.0f;
    }
  }
  BudgetSearch s{method, memory, layout, n, importance, importanceIsRender, {}, 0, 0};
  if (method.allocation == AllocationPolicy::Optimal) s.oracleK.assign(n.size(), 0);
  uint64_t covered = 0;
  for (uint32_t c : n) {
    s.fragments += c;
    s.maxN = std::max(s.maxN, c);
    covered += c > 0;
  }

  const auto accepts = [&s](uint64_t b) { return s.accepts(b); };
  const uint64_t perPixelK = std::max<uint64_t>(method.k.value_or(1), 1);
  const uint64_t guess = s.bytesOf(
      static_cast<long double>(std::max<uint64_t>(s.fragments, layout.pixels() * perPixelK)) +
      1.0L);
  auto hi = holdingAbove(guess, accepts);
  if (!hi) {
    auto refusal = s.allocateAt(kLargestBudget);
    row.note = "refused at any budget up to 1 TiB" +
               (refusal ? std::string() : ": " + refusal.error().message);
    return row;
  }
  // where the rules put it: the per-pixel words alone, one node, one per covered pixel, k per
  // pixel, every fragment
  std::vector<uint64_t> candidates;
  for (uint64_t nodes :
       {uint64_t{0}, uint64_t{1}, covered, layout.pixels() * perPixelK, s.fragments})
    candidates.push_back(s.bytesOf(static_cast<long double>(nodes)));
  row.minimumBytes = smallestHolding(0, *hi, candidates, accepts);
  const double percent = smallestWorkingPercent(method, memory, relative);
  if (std::isfinite(percent)) row.minimumPercent = percent;
  findFixed(s, row);
  findExact(s, row);
  return row;
}

}  // namespace

Result<SceneBudgets> sceneBudgets(Engine& engine, const PreparedView& view,
                                  const std::vector<MethodDesc>& methods,
                                  const RenderOptions& options) {
  SceneBudgets out;
  out.width = view.width();
  out.height = view.height();
  out.samples = view.samples();
  FrameData frame{engine, view, {}, {}, {}};
  auto counted = frame.image();
  if (!counted) return counted.error();
  out.counts = FrameCounts::of(**counted);
  for (uint32_t c : **counted) out.maxDepthComplexity = std::max(out.maxDepthComplexity, c);
  out.meanDepthComplexity = out.counts.coveredPixels
                                ? static_cast<double>(out.counts.fragments) /
                                      static_cast<double>(out.counts.coveredPixels)
                                : 0.0;
  // the ground truth: the A-buffer, per sample when multisampled (compare's)
  auto abuffer = methodPreset("abuffer");
  if (!abuffer) return abuffer.error();
  RenderOptions exact = options;
  exact.sampleStorage = SampleStorage::Sample;
  const MemoryModel abufferMemory = engine.memoryModel(abuffer.value(), exact);
  out.abufferBytes = abufferMemory.overhead(view.storagePixels(SampleStorage::Sample)) +
                     out.counts.fragments * abufferMemory.node;
  for (const MethodDesc& method : methods) {
    auto row = rowOf(frame, method, options);
    if (!row) return row.error();
    out.methods.push_back(std::move(row.value()));
  }
  return out;
}

Result<MethodBudget> methodBudget(Engine& engine, const PreparedView& view,
                                  const MethodDesc& method, const RenderOptions& options) {
  FrameData frame{engine, view, {}, {}, {}};
  return rowOf(frame, method, options);
}

std::vector<BudgetSpec> autoBudgets(const SceneBudgets& budgets, int count) {
  count = std::max(count, 2);
  std::optional<uint64_t> lo, loAll;
  uint64_t hi = 0;  // the largest minimum: at the last budget every method runs
  for (const MethodBudget& row : budgets.methods) {
    if (!row.minimumBytes) continue;
    loAll = std::min(loAll.value_or(UINT64_MAX), *row.minimumBytes);
    hi = std::max(hi, *row.minimumBytes);
    if (!row.fixedBytes) lo = std::min(lo.value_or(UINT64_MAX), *row.minimumBytes);
  }
  if (!lo) lo = loAll;
  if (!lo) return {};
  const uint64_t from = std::max<uint64_t>(*lo, 1);
  const uint64_t to = std::max({from, budgets.abufferBytes, hi});
  // up to a multiple of an eighth of the leading power of two (at least 1 KiB): never below the
  // value, so the smallest budget stays at or above the smallest minimum
  const auto tidy = [](uint64_t v) {
    const uint64_t step = std::max<uint64_t>(1024, std::bit_floor(v) / 8);
    return (v + step - 1) / step * step;
  };
  std::vector<BudgetSpec> out;
  const double ratio = static_cast<double>(to) / static_cast<double>(from);
  for (int i = 0; i < count; ++i) {
    const double v =
        static_cast<double>(from) * std::pow(ratio, static_cast<double>(i) / (count - 1));
    const uint64_t bytes = tidy(i == 0 ? from : i == count - 1 ? to : static_cast<uint64_t>(v));
    if (out.empty() || *out.back().bytes < bytes) out.emplace_back(bytes);
  }
  return out;
}

std::string belowMinimumText(const MethodBudget& row, const std::string& budgetLabel,
                             const std::string& size) {
  if (!row.minimumBytes)
    return row.method + " at " + budgetLabel + ": " +
           (row.note.empty() ? std::string("refused at any budget") : row.note);
  return row.method + " at " + budgetLabel + ": needs at least " + formatBytes(*row.minimumBytes) +
         " (" + std::to_string(*row.minimumBytes) + " B) at " + size;
}

}  // namespace mfr
