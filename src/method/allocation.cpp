// Allocation policies: how many fragment slots each pixel gets under a budget M.
//   fixed k       k = floor(F(M) / |P|) (or explicit), the same k pre-allocated for every pixel
//                 (k-buffer / k+-buffer, k+-buffer paper sec. 3.2);
//   counted k     k(p) = min(n(p), k), exact memory from the count pass (K+B-SB, sec. 3.3); k as
//                 for fixed k unless explicit;
//   dynamic k     the largest global k whose exact memory fits M, read off the depth-complexity
//                 histogram (dynamic k-buffer, [VPF15] as summarised by the variable k-buffer
//                 paper);
//   importance    k(p) = floor(P(p) F(M)), P(p) = I(p) / sum I (variable k-buffer, Eqs. 1-2); the
//                 fill variant gives every covered pixel one slot, the rest by importance capped
//                 at n(p), and hands freed and remainder slots to the pixels with the largest unmet
//                 importance (under hybrid compositing capped at n(p) - 1: a one-fragment tail is
//                 exact, so the last fragment never needs a slot);
//   optimal       k(p) from the offline oracle (optimal_allocation.hpp) over an A-buffer pre-pass;
//   (under hybrid compositing the counted, dynamic, importance and optimal policies may give a
//   covered pixel k(p) = 0: it is composited from its order-independent tail alone, so their
//   budget floor is the per-pixel words; allowsTailOnlyPixels, issue 28)
//   unbounded     k(p) = n(p) (A-buffer / S-buffer);
//   no nodes      k(p) = 0 (wboit, mboit: per-pixel accumulators only; the budget must cover them);
//   pool          one pool of F(M) nodes for every pixel, first come first served (linked lists,
//                 Yang et al. 2010; without a budget every fragment, sum n(p)).
// Node bytes are the memory model's S_f (8, or 20 for mlab's nodes).
// Offsets are an exclusive prefix sum of k(p) in tile-major order (the S-buffer's clustering of
// pixels by tiles, for locality).
#include <algorithm>
#include <cmath>
#include <string>

#include "mfr/method/allocation.hpp"

namespace mfr {
namespace {

std::string bytesText(uint64_t b) {
  return std::to_string(b) + " B";
}

std::string sizeText(const PixelLayout& f) {
  return std::to_string(f.width) + "x" + std::to_string(f.height);
}

// Store of a pixel: the K+B-SB rule picks the heap when the pixel overflows and k > 16.
StoreKind pickStore(StoreChoice choice, uint32_t n, uint32_t k) {
  switch (choice) {
    case StoreChoice::Append:
      return StoreKind::Append;
    case StoreChoice::MaxArray:
      return StoreKind::MaxArray;
    case StoreChoice::MaxHeap:
      return StoreKind::MaxHeap;
    case StoreChoice::PerPixel:
      return (n > k && k > 16) ? StoreKind::MaxHeap : StoreKind::MaxArray;
    case StoreChoice::MultiLayer:  // MLAB's own store (peer_methods.cpp); the kind is unused
    case StoreChoice::None:
    case StoreChoice::LinkedList:
      return StoreKind::MaxArray;
  }
  return StoreKind::MaxArray;
}

}  // namespace

// Water-filling for vkb-fill: k(p) <= n(p), sum k(p) <= slots, extra slots in proportion to the
// importance of the pixels still short of n(p), the last few one each by descending importance.
void fillByImportance(const std::vector<uint32_t>& n, const std::vector<float>& importance,
                      uint64_t slots, std::vector<uint64_t>& k) {
  uint64_t used = 0;
  for (size_t p = 0; p < n.size(); ++p) used += k[p];
  for (int round = 0; round < 64 && used < slots; ++round) {
    double unmetImportance = 0.0;
    for (size_t p = 0; p < n.size(); ++p)
      if (k[p] < n[p]) unmetImportance += importance[p];
    if (unmetImportance <= 0.0) break;
    const uint64_t spare = slots - used;
    uint64_t given = 0;
    for (size_t p = 0; p < n.size(); ++p) {
      if (k[p] >= n[p]) continue;
      const uint64_t extra = std::min<uint64_t>(
          n[p] - k[p], static_cast<uint64_t>(spare * (importance[p] / unmetImportance)));
      k[p] += extra;
      given += extra;
    }
    used += given;
    if (given == 0) break;
  }
  if (used >= slots) return;
  std::vector<uint32_t> order;
  for (size_t p = 0; p < n.size(); ++p)
    if (k[p] < n[p]) order.push_back(static_cast<uint32_t>(p));
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return importance[a] > importance[b]; });
  while (used < slots && !order.empty()) {  // one each, most important first, until exhausted
    size_t kept = 0;
    for (uint32_t p : order) {
      if (used < slots && k[p] < n[p]) {
        ++k[p];
        ++used;
      }
      if (k[p] < n[p]) order[kept++] = p;
    }
    order.resize(kept);
  }
}

bool allowsTailOnlyPixels(const MethodDesc& method) {
  if (method.compositing != Compositing::Hybrid) return false;
  switch (method.allocation) {
    case AllocationPolicy::CountedK:
    case AllocationPolicy::DynamicK:
    case AllocationPolicy::Importance:
    case AllocationPolicy::Optimal:
      return true;
    case AllocationPolicy::Unbounded:
    case AllocationPolicy::FixedK:
    case AllocationPolicy::NoNodes:
    case AllocationPolicy::Pool:
      return false;
  }
  return false;
}

Result<uint64_t> budgetSlots(const PixelLayout& frame, const MethodDesc& method,
                             const MemoryModel& memory, std::optional<uint64_t> budget) {
  const uint64_t pixels = frame.pixels();
  const uint64_t overhead = memory.overhead(pixels);
  const std::string& name = method.name;
  if (method.allocation == AllocationPolicy::NoNodes) {  // wboit, mboit: accumulators only
    if (budget && *budget < overhead)
      return makeError("budget " + bytesText(*budget) + ": too small for " + name + " at " +
                       sizeText(frame) + " (its per-pixel buffers take " + bytesText(overhead) +
                       ")");
    return uint64_t{0};
  }
  if (allowsTailOnlyPixels(method)) {  // hybrid: a pixel without a slot keeps its tail
    if (budget && *budget < overhead)
      return makeError("budget " + bytesText(*budget) + ": too small for " + name + " at " +
                       sizeText(frame) + " (its per-pixel buffers take " + bytesText(overhead) +
                       ", the floor under hybrid compositing, where a pixel without a slot is "
                       "composited from its tail alone)");
    return budget ? memory.fragmentSlots(*budget, pixels) : UINT64_MAX;
  }
  if (budget && *budget < overhead + memory.node)
    return makeError("budget " + bytesText(*budget) + ": too small for " + name + " at " +
                     sizeText(frame) + " (its per-pixel buffers take " + bytesText(overhead) +
                     ", leaving no room for a fragment)");
  return budget ? memory.fragmentSlots(*budget, pixels) : UINT64_MAX;
}

namespace {

// the budget cannot give one node to every (covered) pixel; for a policy that could go lower under
// hybrid compositing, the message says why this rule cannot
Error tooSmallFor(const PixelLayout& frame, const MethodDesc& method, const MemoryModel& memory,
                  uint64_t budget, const char* which, uint64_t count) {
  const uint64_t overhead = memory.overhead(frame.pixels());
  MethodDesc hybrid = method;
  hybrid.compositing = Compositing::Hybrid;
  const std::string why =
      allowsTailOnlyPixels(hybrid)
          ? ": kbuffer compositing keeps no tail, so a pixel without a slot would lose all its "
            "fragments; under hybrid compositing the floor is the per-pixel words, " +
                bytesText(overhead)
          : "";
  return makeError("budget " + bytesText(budget) + ": too small for one fragment per " + which +
                   " with " + method.name + " at " + sizeText(frame) + " (needs " +
                   bytesText(overhead + count * memory.node) + why + ")");
}

}  // namespace

Result<uint32_t> boundedK(const PixelLayout& frame, const MethodDesc& method,
                          const MemoryModel& memory, std::optional<uint64_t> budget,
                          const CountSummary& counts) {
  const std::string& name = method.name;
  const uint64_t pixels = frame.pixels();
  auto slots = budgetSlots(frame, method, memory, budget);
  if (!slots) return slots.error();
  const uint64_t slotsInBudget = *slots;
  const bool tailOnly = allowsTailOnlyPixels(method);  // k = 0 may be the answer
  uint64_t k = 0;
  if (method.allocation == AllocationPolicy::CountedK && method.k) {
    k = *method.k;
  } else if (method.allocation == AllocationPolicy::CountedK) {
    if (!budget) return makeError(name + ": needs a budget or an explicit k");
    k = std::max<uint64_t>(1, std::min<uint64_t>(slotsInBudget / pixels, 1u << 20));
    // k = 1 needs a node per covered pixel (F(M) / |P| >= 1 always has it): else tail only, or
    // under kbuffer compositing too small
    if (slotsInBudget < counts.covered)
      return tailOnly
                 ? Result<uint32_t>(uint32_t{0})
                 : tooSmallFor(frame, method, memory, *budget, "covered pixel", counts.covered);
  } else {
    if (!budget && !method.k) return makeError(name + ": needs a budget");
    MFR_CHECK(counts.histogram.size() == kHistogramBins);
    const std::vector<uint64_t>& histogram = counts.histogram;
    // never above the largest n(p): a larger k buys nothing
    const uint64_t kLimit =
        std::min<uint64_t>({method.k.value_or(kHistogramBins - 1), kHistogramBins - 1,
                            std::max<uint64_t>(1, counts.maxN)});
    // the largest k that fits, scanning from high to low; exact because k never exceeds the last
    // bin
    for (uint64_t candidate = kLimit; candidate >= 1 && k == 0; --candidate) {
      uint64_t need = 0;
      for (uint64_t bin = 1; bin < kHistogramBins; ++bin)
        need += histogram[bin] * std::min(bin, candidate);
      if (need <= slotsInBudget) k = candidate;
    }
    if (k == 0 && tailOnly) return uint32_t{0};  // every pixel tail-only
    if (k == 0) return tooSmallFor(frame, method, memory, *budget, "covered pixel", counts.covered);
  }
  if (k == 0) return makeError(name + ": k must be at least 1");
  return static_cast<uint32_t>(k);
}

Result<void> checkBoundedSlots(const PixelLayout& frame, const MethodDesc& method,
                               const MemoryModel& memory, std::optional<uint64_t> budget,
                               uint32_t k, uint64_t slots) {
  auto inBudget = budgetSlots(frame, method, memory, budget);
  if (!inBudget) return inBudget.error();
  if (slots > *inBudget)
    return makeError("budget " + bytesText(*budget) + ": " + method.name +
                     " with k = " + std::to_string(k) + " needs " +
                     bytesText(memory.overhead(frame.pixels()) + slots * memory.node) + " at " +
                     sizeText(frame));
  return {};
}

Result<void> checkCoveredPixels(const PixelLayout& frame, const MethodDesc& method,
                                const MemoryModel& memory, std::optional<uint64_t> budget,
                                uint64_t covered) {
  auto inBudget = budgetSlots(frame, method, memory, budget);
  if (!inBudget) return inBudget.error();
  if (!budget) return makeError(method.name + ": needs a budget");
  if (*inBudget < covered && !allowsTailOnlyPixels(method))
    return tooSmallFor(frame, method, memory, *budget, "covered pixel", covered);
  return {};
}

CountSummary summarizeCounts(const std::vector<uint32_t>& n) {
  CountSummary s;
  s.histogram.assign(kHistogramBins, 0);
  for (uint32_t c : n) {
    ++s.histogram[std::min<uint64_t>(c, kHistogramBins - 1)];
    s.maxN = std::max<uint64_t>(s.maxN, c);
    s.covered += c > 0;
  }
  return s;
}

namespace {

// What every policy step reads: the frame, the method, the counts n(p) and the slots F(M) the
// budget leaves for nodes.
struct AllocationInputs {
  const PixelLayout& frame;
  const MethodDesc& method;
  const MemoryModel& memory;
  std::optional<uint64_t> budget;
  const std::vector<uint32_t>& n;
  uint64_t slotsInBudget;
  uint64_t covered;  // pixels with n(p) > 0
  bool tailOnly;     // allowsTailOnlyPixels: k(p) = 0 allowed for a covered pixel

  Error tooSmall(const char* which, uint64_t count) const {
    return tooSmallFor(frame, method, memory, *budget, which, count);
  }
};

// sum over p of min(n(p), k)
uint64_t cappedSum(const std::vector<uint32_t>& n, uint64_t k) {
  uint64_t s = 0;
  for (uint32_t c : n) s += std::min<uint64_t>(c, k);
  return s;
}

// I(p) comes from hand-set parameters or a model file (deep k-buffer): a NaN, infinite or
// negative value counts as 0, so that no float-to-integer conversion below ever sees it. Returns
// importanceIn itself when it is clean, else the copy made in scratch.
const std::vector<float>& usableImportance(const std::vector<float>& importanceIn,
                                           std::vector<float>& scratch) {
  const auto usable = [](float i) { return std::isfinite(i) && i >= 0.0f; };
  if (std::all_of(importanceIn.begin(), importanceIn.end(), usable)) return importanceIn;
  scratch = importanceIn;
  for (float& i : scratch)
    if (!usable(i)) i = 0.0f;
  return scratch;
}

// unbounded: k(p) = n(p), all fragments or an error
Result<void> allocateUnbounded(const AllocationInputs& in, Allocation& a) {
  a.slots = cappedSum(in.n, UINT32_MAX);
  if (a.slots > in.slotsInBudget)
    return makeError("budget " + bytesText(*in.budget) + ": " + in.method.name + " needs " +
                     bytesText(in.memory.overhead(in.frame.pixels()) + a.slots * in.memory.node) +
                     " for all " + std::to_string(a.slots) + " fragments at " + sizeText(in.frame));
  for (size_t p = 0; p < in.frame.pixels(); ++p) a.capacity[p] = in.n[p];
  return {};
}

// fixed k: the explicit k, or floor(F(M) / |P|), for every pixel
Result<void> allocateFixedK(const AllocationInputs& in, Allocation& a) {
  const std::string& name = in.method.name;
  const uint64_t pixels = in.frame.pixels();
  uint64_t k = in.method.k.value_or(0);
  if (!in.method.k) {
    if (!in.budget) return makeError(name + ": needs a budget or an explicit k");
    k = std::min<uint64_t>(in.slotsInBudget / pixels, 1u << 20);
    if (k == 0) return in.tooSmall("pixel", pixels);
  }
  if (k == 0) return makeError(name + ": k must be at least 1");
  if (k * pixels > in.slotsInBudget)
    return makeError("budget " + bytesText(*in.budget) + ": " + name +
                     " with k = " + std::to_string(k) + " needs " +
                     bytesText(in.memory.overhead(pixels) + k * pixels * in.memory.node) + " at " +
                     sizeText(in.frame));
  a.globalK = static_cast<uint32_t>(k);
  a.slots = k * pixels;
  std::fill(a.capacity.begin(), a.capacity.end(), static_cast<uint32_t>(k));
  return {};
}

// counted k and dynamic k: one global k (boundedK), k(p) = min(n(p), k)
Result<void> allocateBoundedK(const AllocationInputs& in, Allocation& a) {
  const bool dynamic = in.method.allocation == AllocationPolicy::DynamicK;
  const CountSummary summary = dynamic ? summarizeCounts(in.n) : CountSummary{{}, 0, in.covered};
  if (dynamic) a.scratchBytes += summary.histogram.capacity() * sizeof(uint64_t);
  auto k = boundedK(in.frame, in.method, in.memory, in.budget, summary);
  if (!k) return k.error();
  a.slots = cappedSum(in.n, *k);
  MFR_TRY(checkBoundedSlots(in.frame, in.method, in.memory, in.budget, *k, a.slots));
  a.globalK = *k;
  for (size_t p = 0; p < in.frame.pixels(); ++p) a.capacity[p] = std::min(in.n[p], *k);
  return {};
}

// importance: k(p) = floor(I(p) / sum I * F(M)) (Eq. 1), or the fill variant; the reserved k(p)
// may exceed n(p), the capacity never does
Result<void> allocateByImportance(const AllocationInputs& in, const std::vector<float>& importance,
                                  Allocation& a) {
  const std::vector<uint32_t>& n = in.n;
  const uint64_t pixels = in.frame.pixels();
  const uint64_t slotsInBudget = in.slotsInBudget;
  if (!in.budget) return makeError(in.method.name + ": needs a budget");
  if (slotsInBudget < in.covered && !in.tailOnly) return in.tooSmall("covered pixel", in.covered);
  double total = 0.0;
  for (float i : importance) total += i;
  std::vector<uint64_t> k(pixels, 0);
  if (!in.method.fillUnusedSlots) {  // the paper's rule, Eq. 1
    if (total > 0.0)
      for (size_t p = 0; p < pixels; ++p)
        k[p] = static_cast<uint64_t>(
            std::floor(importance[p] / total * static_cast<double>(slotsInBudget)));
  } else {
    // fill (mfr's variant): the slots a pixel can use are n(p), or n(p) - 1 under hybrid
    // compositing, where a one-fragment tail is exact (C_tail = c, alpha_tail = a): its last
    // fragment needs no slot, so a pixel of one fragment needs none
    std::vector<uint32_t> useful(n);
    if (in.tailOnly)
      for (uint32_t& u : useful) u = u > 0 ? u - 1 : 0;
    uint64_t needing = 0;  // pixels that can use a slot
    for (uint32_t u : useful) needing += u > 0;
    if (slotsInBudget >= needing) {
      // one slot for every such pixel first (like DHOIT's allocation), the rest by importance,
      // capped at what it can use, then the freed and remainder slots to the unmet pixels
      const double share = static_cast<double>(slotsInBudget - needing);
      for (size_t p = 0; p < pixels; ++p) {
        if (useful[p] == 0) continue;
        const uint64_t byImportance =
            total > 0.0 ? static_cast<uint64_t>(std::floor(importance[p] / total * share)) : 0;
        k[p] = 1 + std::min<uint64_t>(useful[p] - 1, byImportance);
      }
    }
    // (fewer slots than such pixels, under hybrid compositing: the water-filling from k = 0
    // gives them by importance, the last ones one each to the most important pixels)
    fillByImportance(useful, importance, slotsInBudget, k);
    // slots left once every pixel has what it can use: up to n(p) (the last fragment's slot buys
    // nothing exactly, but its float rounding is the A-buffer's)
    if (in.tailOnly) fillByImportance(n, importance, slotsInBudget, k);
  }
  a.scratchBytes += k.capacity() * sizeof(uint64_t);
  a.reservedK.resize(pixels);
  for (size_t p = 0; p < pixels; ++p) {
    a.reservedSlots += k[p];
    a.reservedK[p] = static_cast<uint32_t>(std::min<uint64_t>(k[p], UINT32_MAX));
    a.capacity[p] = static_cast<uint32_t>(std::min<uint64_t>(k[p], n[p]));
    a.slots += a.capacity[p];
  }
  MFR_CHECK_LE(a.reservedSlots, slotsInBudget);
  return {};
}

// optimal: k(p) chosen by the oracle (render.cpp) within F(M)
Result<void> allocateOptimal(const AllocationInputs& in, const std::vector<uint32_t>& oracleK,
                             Allocation& a) {
  if (!in.budget) return makeError(in.method.name + ": needs a budget");
  if (in.slotsInBudget < in.covered && !in.tailOnly)
    return in.tooSmall("covered pixel", in.covered);
  MFR_CHECK_EQ(oracleK.size(), in.frame.pixels());
  for (size_t p = 0; p < in.frame.pixels(); ++p) {
    a.capacity[p] = oracleK[p];
    a.slots += oracleK[p];
  }
  MFR_CHECK_LE(a.slots, in.slotsInBudget);
  return {};
}

// pool (linked lists): F(M) nodes shared by all pixels, or every fragment without a budget; no
// per-pixel region (k(p) is what the capture links, offsets unused); the next index is 32-bit
// with 0xFFFFFFFF ending a list
Result<void> allocatePool(const AllocationInputs& in, Allocation& a) {
  constexpr uint64_t kMaxPool = 0xFFFFFFFEull;
  if (in.budget) {
    a.slots = std::min(in.slotsInBudget, kMaxPool);
    return {};
  }
  a.slots = cappedSum(in.n, UINT32_MAX);
  if (a.slots > kMaxPool)
    return makeError(in.method.name + ": " + std::to_string(a.slots) +
                     " fragments exceed the linked list's 32-bit node index at " +
                     sizeText(in.frame) + " (give a budget)");
  return {};
}

// exclusive prefix sum of the capacities in tile-major order (row-major: one tile as wide and
// high as the frame)
void tileMajorOffsets(const PixelLayout& frame, Allocation& a) {
  a.offsets.assign(frame.pixels(), 0);
  uint64_t running = 0;
  const int tw = frame.tileSize > 0 ? frame.tileSize : std::max(frame.width, 1);
  const int th = frame.tileSize > 0 ? frame.tileSize : std::max(frame.height, 1);
  for (int ty = 0; ty < frame.height; ty += th)
    for (int tx = 0; tx < frame.width; tx += tw)
      for (int y = ty; y < std::min(frame.height, ty + th); ++y)
        for (int x = tx; x < std::min(frame.width, tx + tw); ++x) {
          const size_t p = static_cast<size_t>(y) * static_cast<size_t>(frame.width) + x;
          a.offsets[p] = running;
          running += a.capacity[p];
        }
  MFR_CHECK_EQ(running, a.slots);
}

}  // namespace

Result<Allocation> allocate(const PixelLayout& frame, const MethodDesc& method,
                            const MemoryModel& memory, std::optional<uint64_t> budget,
                            const std::vector<uint32_t>& n, const std::vector<float>& importanceIn,
                            const std::vector<uint32_t>& oracleK, Allocation* reuse) {
  std::vector<float> sanitized;
  const std::vector<float>& importance = usableImportance(importanceIn, sanitized);
  const uint64_t pixels = frame.pixels();
  Allocation a;
  if (reuse) {  // arrays of exactly this size only: callers count their capacities
    if (reuse->capacity.capacity() == pixels) a.capacity = std::move(reuse->capacity);
    if (reuse->offsets.capacity() == pixels) a.offsets = std::move(reuse->offsets);
    if (reuse->kind.capacity() == pixels) a.kind = std::move(reuse->kind);
  }
  a.capacity.assign(pixels, 0);
  a.kind.assign(pixels, StoreKind::MaxArray);

  auto inBudget = budgetSlots(frame, method, memory, budget);
  if (!inBudget) return inBudget.error();
  if (method.allocation == AllocationPolicy::NoNodes) {  // wboit, mboit: accumulators only
    a.offsets.assign(pixels, 0);
    return a;
  }
  uint64_t covered = 0;
  for (uint32_t c : n) covered += c > 0;
  const AllocationInputs in{frame, method,    memory,  budget,
                            n,     *inBudget, covered, allowsTailOnlyPixels(method)};

  switch (method.allocation) {
    case AllocationPolicy::Unbounded:
      MFR_TRY(allocateUnbounded(in, a));
      break;
    case AllocationPolicy::FixedK:
      MFR_TRY(allocateFixedK(in, a));
      break;
    case AllocationPolicy::CountedK:
    case AllocationPolicy::DynamicK:
      MFR_TRY(allocateBoundedK(in, a));
      break;
    case AllocationPolicy::Importance:
      MFR_TRY(allocateByImportance(in, importance, a));
      break;
    case AllocationPolicy::NoNodes:  // returned above
      break;
    case AllocationPolicy::Optimal:
      MFR_TRY(allocateOptimal(in, oracleK, a));
      break;
    case AllocationPolicy::Pool:
      MFR_TRY(allocatePool(in, a));
      a.reservedSlots = a.slots;
      a.offsets.assign(pixels, 0);
      return a;
  }
  if (a.reservedK.empty()) a.reservedSlots = a.slots;

  for (size_t p = 0; p < pixels; ++p)
    a.kind[p] = pickStore(method.store, n.empty() ? a.capacity[p] + 1 : n[p], a.capacity[p]);
  tileMajorOffsets(frame, a);
  return a;
}

}  // namespace mfr
