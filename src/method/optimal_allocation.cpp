// Optimal k-buffer allocators (DHOIT sec. 3.1.2, Algorithm 1); see optimal_allocation.hpp.
#include "mfr/method/optimal_allocation.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <queue>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "mfr/core/color.hpp"
#include "mfr/core/result.hpp"

namespace mfr {

std::vector<double> errorCurve(const FragmentNode* sorted, uint32_t n, glm::vec3 background,
                               Compositing compositing, uint32_t firstK) {
  MFR_CHECK_LE(firstK, 1u);
  if (n == 0) return {};
  std::vector<double> err(n + 1 - firstK, 0.0);
  // prefix: core colour and transmittance; suffix: tail sums (the calling thread's scratch, reused
  // from pixel to pixel: the oracle calls this once per covered pixel)
  thread_local std::vector<glm::dvec3> core, T, tailColor;
  thread_local std::vector<double> tailAlpha;
  core.assign(n + 1, glm::dvec3(0.0));
  T.assign(n + 1, glm::dvec3(1.0));
  tailColor.assign(n + 2, glm::dvec3(0.0));
  tailAlpha.assign(n + 2, 0.0);
  // the node kinds of method_math.h blendStep / hybridTailAddNode (over, additive, multiply)
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t rgba = nodeColor(sorted[i]);
    const glm::dvec4 c(unpackFragmentColor(rgba));
    if ((rgba >> 24) == kAdditiveAlphaByte) {
      core[i + 1] = core[i] + glm::dvec3(c) * T[i];
      T[i + 1] = T[i];
    } else if ((rgba >> 24) == kMultiplyAlphaByte) {
      core[i + 1] = core[i];
      T[i + 1] = T[i] * glm::dvec3(c);
    } else {
      core[i + 1] = core[i] + glm::dvec3(c) * (c.a * T[i]);
      T[i + 1] = T[i] * (1.0 - c.a);
    }
  }
  for (uint32_t i = n; i-- > 0;) {
    const uint32_t rgba = nodeColor(sorted[i]);
    const glm::dvec4 c(unpackFragmentColor(rgba));
    const double weight = (rgba >> 24) == kAdditiveAlphaByte ? 1.0 : c.a;
    tailColor[i] = tailColor[i + 1] + glm::dvec3(c) * weight;
    tailAlpha[i] = tailAlpha[i + 1] + ((rgba >> 24) == kAdditiveAlphaByte ? 0.0 : c.a);
  }
  const glm::dvec3 bg(background);
  auto hybrid = [&](uint32_t k) {
    const uint32_t t = n - k;
    if (compositing == Compositing::KBuffer) return core[k] + T[k] * bg;  // tail dropped
    if (t == 0) return core[k] + T[k] * bg;
    if (tailAlpha[k] <= 0.0) return core[k] + T[k] * (bg + tailColor[k]);
    const glm::dvec3 colour = tailColor[k] / tailAlpha[k];
    const double alpha =
        1.0 - std::pow(std::max(0.0, 1.0 - tailAlpha[k] / t), static_cast<double>(t));
    return core[k] + T[k] * (alpha * colour + (1.0 - alpha) * bg);
  };
  const glm::dvec3 exact = hybrid(n);
  for (uint32_t k = firstK; k <= n; ++k) {
    const glm::dvec3 d = exact - hybrid(k);
    err[k - firstK] = glm::dot(d, d);
  }
  return err;
}

std::vector<double> hybridErrorCurve(const FragmentNode* sorted, uint32_t n, glm::vec3 background) {
  return errorCurve(sorted, n, background, Compositing::Hybrid);
}

double allocationError(const std::vector<std::vector<double>>& curves,
                       const std::vector<uint32_t>& k, uint32_t firstK) {
  double total = 0.0;
  for (size_t p = 0; p < curves.size(); ++p)
    if (!curves[p].empty()) total += curves[p][k[p] - firstK];
  return total;
}

std::vector<uint32_t> allocateOptimalGreedy(const std::vector<std::vector<double>>& curves,
                                            uint64_t slots) {
  std::vector<uint32_t> k(curves.size(), 0);
  uint64_t used = 0;
  using Entry = std::pair<double, uint32_t>;  // error after removing one more, pixel
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  for (size_t p = 0; p < curves.size(); ++p) {
    k[p] = static_cast<uint32_t>(curves[p].size());
    used += k[p];
    if (k[p] >= 2) heap.push({curves[p][k[p] - 2], static_cast<uint32_t>(p)});
  }
  while (used > slots && !heap.empty()) {
    const uint32_t p = heap.top().second;
    heap.pop();
    --k[p];
    --used;
    if (k[p] >= 2) heap.push({curves[p][k[p] - 2], p});
  }
  return k;
}

namespace {

constexpr size_t kPixelGrain = 4096;  // pixels per task of the parallel passes

// fn(p) for p < pixels on the calling task arena's workers
template <class F>
void forEachPixel(size_t pixels, F&& fn) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, kPixelGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t p = r.begin(); p != r.end(); ++p) fn(p);
                    });
}

struct HullSolution {
  std::vector<uint32_t> k;
  double lambda = 0.0;  // drop per slot of the first segment not bought whole (0: all bought)
};

// The hull allocator buys the segments of every pixel's lower convex hull in the order (drop per
// slot descending, then pixel and position in its chain), whole while they fit, then the critical
// and later ones partially. Sorting every segment of a large frame costs seconds and tens of
// bytes per fragment, so the order is materialised only where it matters:
//
//   hull       per pixel, the hull's vertices k (flat, at the pixel's own offset; <= n(p) each).
//              A chain is cut before the first segment whose drop exceeds its predecessor's (only
//              rounding makes that happen): such a segment reaches its turn before the pixel
//              gets to its start, is skipped, and so is everything after it.
//   level 1    cost (slots) per bucket of the top 16 bits of the drop's order key: the buckets
//              above the one where the cumulative cost first exceeds the budget are bought whole;
//   level 2    the same on the next 16 bits inside that bucket;
//   chunks     the segments sharing the critical 32-bit prefix are sorted exactly and processed
//              one by one as the straightforward loop does, then the lower keys in chunks of at
//              least OracleOptions::hullChunkSegments until the budget is spent.
// The result (k and lambda) is the straightforward sorted loop's, bit for bit.
//
// The hulls and every pass over the segments run on the calling task arena's workers, over ranges
// of pixels: each worker folds its segments into its own state (cost histograms, slots bought,
// the chunk's segments), and the states are combined in no particular order. Nothing computed
// depends on that order: the histograms and slot counts are integer sums, a bought segment raises
// its own pixel's k, and a chunk is sorted into one total order (drop, then position) before it
// is processed, so the result is the same for any number of workers.
class HullAllocator {
 public:
  HullAllocator(const std::vector<std::vector<double>>& curves, uint64_t slots,
                uint64_t chunkSegments)
      : curves_(curves), slots_(slots), chunkSegments_(std::max<uint64_t>(chunkSegments, 1)) {}

  HullSolution run() {
    HullSolution out;
    out.k.assign(curves_.size(), 0);
    k_ = &out.k;
    buildHulls();
    // level 1
    std::vector<uint64_t> cost1(kBuckets, 0), count1(kBuckets, 0);
    struct Level1 {
      std::vector<uint64_t> cost = std::vector<uint64_t>(kBuckets, 0);
      std::vector<uint64_t> count = std::vector<uint64_t>(kBuckets, 0);
    };
    segmentPass<Level1>(
        [](Level1& l, const Segment& s) {
          l.cost[s.key >> 48] += s.to - s.from;
          ++l.count[s.key >> 48];
        },
        [&](const Level1& l) {
          for (int b = 0; b < kBuckets; ++b) {
            cost1[b] += l.cost[b];
            count1[b] += l.count[b];
          }
        });
    const int64_t budget = static_cast<int64_t>(slots_) - static_cast<int64_t>(used_);
    int64_t cum = 0;
    const int b1 = criticalBucket(cost1, budget, cum);
    struct Bought {
      uint64_t used = 0;
    };
    if (b1 < 0) {  // every segment fits
      segmentPass<Bought>([&](Bought& b, const Segment& s) { buy(s, b.used); },
                          [&](const Bought& b) { used_ += b.used; });
      return out;
    }
    // level 2 inside b1, buying whole what lies above b1
    std::vector<uint64_t> cost2(kBuckets, 0);
    struct Level2 {
      uint64_t used = 0;
      std::vector<uint64_t> cost = std::vector<uint64_t>(kBuckets, 0);
    };
    segmentPass<Level2>(
        [&](Level2& l, const Segment& s) {
          const uint64_t top = s.key >> 48;
          if (top > static_cast<uint64_t>(b1)) {
            buy(s, l.used);
          } else if (top == static_cast<uint64_t>(b1)) {
            l.cost[(s.key >> 32) & 0xffff] += s.to - s.from;
          }
        },
        [&](const Level2& l) {
          used_ += l.used;
          for (int b = 0; b < kBuckets; ++b) cost2[b] += l.cost[b];
        });
    int64_t cum2 = 0;
    const int b2 = criticalBucket(cost2, budget - cum, cum2);
    MFR_CHECK(b2 >= 0);
    const uint64_t prefix = (static_cast<uint64_t>(b1) << 16) | static_cast<uint64_t>(b2);
    // chunk 0: the critical 32-bit prefix, buying whole what lies above it in b1
    struct Chunk {
      uint64_t used = 0;
      std::vector<Segment> segments;
    };
    std::vector<Segment> chunk;
    const auto gather = [&](const Chunk& c) {
      used_ += c.used;
      chunk.insert(chunk.end(), c.segments.begin(), c.segments.end());
    };
    segmentPass<Chunk>(
        [&](Chunk& c, const Segment& s) {
          const uint64_t top32 = s.key >> 32;
          if ((top32 >> 16) != static_cast<uint64_t>(b1)) return;
          if (top32 > prefix) {
            buy(s, c.used);
          } else if (top32 == prefix) {
            c.segments.push_back(s);
          }
        },
        gather);
    process(chunk, out.lambda);
    // lower keys, in chunks: [lower, upper)
    uint64_t upper = prefix << 32;
    int bucket = b1;
    while (!done() && upper > 0) {
      uint64_t lower = static_cast<uint64_t>(bucket) << 48, count = 0;
      if (lower == upper) {
        --bucket;
        lower = static_cast<uint64_t>(bucket) << 48;
        count = count1[bucket];
      }
      while (bucket > 0 && count < chunkSegments_) {
        --bucket;
        lower = static_cast<uint64_t>(bucket) << 48;
        count += count1[bucket];
      }
      chunk.clear();
      segmentPass<Chunk>(
          [&](Chunk& c, const Segment& s) {
            if (s.key >= lower && s.key < upper) c.segments.push_back(s);
          },
          gather);
      process(chunk, out.lambda);
      upper = lower;
    }
    return out;
  }

 private:
  static constexpr int kBuckets = 1 << 16;

  struct Segment {
    uint64_t key;    // order key of dropPerSlot: larger first
    uint64_t index;  // position in the flat hull array: pixel, then chain order
    double dropPerSlot;
    uint32_t pixel, from, to;  // k values
  };

  // unsigned order of the key = numeric order of the double (no NaN; -0 taken as 0)
  static uint64_t orderKey(double d) {
    if (d == 0.0) d = 0.0;
    uint64_t bits = 0;
    std::memcpy(&bits, &d, sizeof bits);
    return (bits >> 63) ? ~bits : bits | (uint64_t{1} << 63);
  }

  // highest bucket where the cumulative cost (from the top) first exceeds `budget`; -1 if none.
  // `cum` receives the cost of the buckets above it.
  static int criticalBucket(const std::vector<uint64_t>& cost, int64_t budget, int64_t& cum) {
    cum = 0;
    for (int b = kBuckets - 1; b >= 0; --b) {
      if (cost[b] == 0) continue;
      if (cum + static_cast<int64_t>(cost[b]) > budget) return b;
      cum += static_cast<int64_t>(cost[b]);
    }
    return -1;
  }

  // fold(state, segment) over every segment, one State per worker; then combine(state) for each
  template <class State, class Fold, class Combine>
  void segmentPass(Fold&& fold, Combine&& combine) const {
    tbb::enumerable_thread_specific<State> states;
    forEachPixel(curves_.size(), [&](size_t p) {
      State& state = states.local();
      forEachSegmentOf(p, [&](const Segment& s) { fold(state, s); });
    });
    for (const State& state : states) combine(state);
  }

  void buildHulls() {
    start_.assign(curves_.size() + 1, 0);
    uint64_t total = 0;
    for (size_t p = 0; p < curves_.size(); ++p) {
      start_[p] = total;
      total += curves_[p].size();
      used_ += !curves_[p].empty();  // every covered pixel starts at k = 1
    }
    start_.back() = total;
    hull_.resize(total);
    length_.assign(curves_.size(), 0);
    forEachPixel(curves_.size(), [&](size_t p) { buildHull(p); });
  }

  void buildHull(size_t p) {
    const std::vector<double>& e = curves_[p];
    if (e.empty()) return;
    (*k_)[p] = 1;
    // lower convex hull of (k, e(k)), k = 1..n (monotone chain)
    uint32_t* hull = hull_.data() + start_[p];
    uint32_t size = 0;
    for (uint32_t x = 1; x <= e.size(); ++x) {
      while (size >= 2) {
        const uint32_t a = hull[size - 2], b = hull[size - 1];
        // drop b if it lies on or above the line from a to x
        const double cross = (e[b - 1] - e[a - 1]) * (x - a) - (e[x - 1] - e[a - 1]) * (b - a);
        if (cross >= 0.0) {
          --size;
        } else {
          break;
        }
      }
      hull[size++] = x;
    }
    // cut the chain before its first rising drop
    uint32_t live = 1;
    double previous = std::numeric_limits<double>::infinity();
    for (; live < size; ++live) {
      const double d = dropPerSlot(e, hull[live - 1], hull[live]);
      if (d > previous) break;
      previous = d;
    }
    length_[p] = live;
  }

  static double dropPerSlot(const std::vector<double>& e, uint32_t from, uint32_t to) {
    return (e[from - 1] - e[to - 1]) / (to - from);
  }

  template <class F>
  void forEachSegmentOf(size_t p, F&& f) const {
    const uint32_t* hull = hull_.data() + start_[p];
    for (uint32_t i = 1; i < length_[p]; ++i) {
      Segment s;
      s.dropPerSlot = dropPerSlot(curves_[p], hull[i - 1], hull[i]);
      s.key = orderKey(s.dropPerSlot);
      s.index = start_[p] + i;
      s.pixel = static_cast<uint32_t>(p);
      s.from = hull[i - 1];
      s.to = hull[i];
      f(s);
    }
  }

  // a segment above the critical one: bought whole (its chain's earlier segments are too); only
  // its own pixel's k changes, and `used` (the caller's share of the slots) grows by its cost
  void buy(const Segment& s, uint64_t& used) const {
    (*k_)[s.pixel] = std::max((*k_)[s.pixel], s.to);
    used += s.to - s.from;
  }

  bool done() const { return critical_ && used_ >= slots_; }

  // the straightforward loop over a chunk sorted in the global order
  void process(std::vector<Segment>& chunk, double& lambda) {
    std::sort(chunk.begin(), chunk.end(), [](const Segment& a, const Segment& b) {
      return a.key != b.key ? a.key > b.key : a.index < b.index;
    });
    std::vector<uint32_t>& k = *k_;
    for (const Segment& s : chunk) {
      if (k[s.pixel] != s.from) continue;  // an earlier segment of this pixel was cut short
      const uint64_t cost = s.to - s.from;
      if (used_ + cost <= slots_) {
        k[s.pixel] = s.to;
        used_ += cost;
        continue;
      }
      if (!critical_) {
        critical_ = true;
        lambda = std::max(0.0, s.dropPerSlot);
      }
      if (used_ >= slots_) return;
      // partial: the best k in (from, from + affordable]
      const std::vector<double>& e = curves_[s.pixel];
      uint32_t best = s.from;
      for (uint32_t x = s.from + 1; x <= s.from + (slots_ - used_); ++x)
        if (e[x - 1] < e[best - 1]) best = x;
      used_ += best - s.from;
      k[s.pixel] = best;
    }
  }

  const std::vector<std::vector<double>>& curves_;
  const uint64_t slots_;
  const uint64_t chunkSegments_;
  std::vector<uint32_t>* k_ = nullptr;
  std::vector<uint64_t> start_;  // per pixel, its hull's offset in hull_ (prefix of n)
  std::vector<uint32_t> hull_, length_;
  uint64_t used_ = 0;
  bool critical_ = false;
};

HullSolution hullAllocation(const std::vector<std::vector<double>>& curves, uint64_t slots,
                            uint64_t chunkSegments) {
  return HullAllocator(curves, slots, chunkSegments).run();
}

// Exact minimum over k_p in options[p] (ascending), sum k <= capacity + sum options[p][0], by
// dynamic programming over the extra slots; false when it would exceed the cell limit.
bool exactCore(const std::vector<std::vector<double>>& curves, const std::vector<uint32_t>& core,
               const std::vector<std::vector<uint32_t>>& options, uint64_t capacity,
               uint64_t maxCells, std::vector<uint32_t>& k) {
  uint64_t maxExtra = 0, optionCount = 0;
  for (const std::vector<uint32_t>& o : options) {
    if (o.size() > 65535) return false;
    maxExtra += o.back() - o.front();
    optionCount += o.size();
  }
  capacity = std::min(capacity, maxExtra);
  const uint64_t width = capacity + 1;
  if (optionCount > maxCells / width) return false;
  std::vector<double> dp(width, 0.0), next(width);
  std::vector<uint16_t> choice(core.size() * width);
  for (size_t i = 0; i < core.size(); ++i) {
    const std::vector<double>& e = curves[core[i]];
    const std::vector<uint32_t>& o = options[i];
    uint16_t* pick = choice.data() + i * width;
    for (uint64_t c = 0; c < width; ++c) {
      double best = std::numeric_limits<double>::infinity();
      uint16_t bestIndex = 0;
      for (size_t j = 0; j < o.size(); ++j) {
        const uint64_t extra = o[j] - o.front();
        if (extra > c) break;
        const double v = dp[c - extra] + e[o[j] - 1];
        if (v < best) {
          best = v;
          bestIndex = static_cast<uint16_t>(j);
        }
      }
      next[c] = best;
      pick[c] = bestIndex;
    }
    dp.swap(next);
  }
  uint64_t c = capacity;
  for (size_t i = core.size(); i-- > 0;) {
    const std::vector<uint32_t>& o = options[i];
    const uint32_t chosen = o[choice[i * width + c]];
    k[core[i]] = chosen;
    c -= chosen - o.front();
  }
  return true;
}

}  // namespace

std::vector<uint32_t> allocateOptimalHull(const std::vector<std::vector<double>>& curves,
                                          uint64_t slots) {
  return allocateOptimalHull(curves, slots, OracleOptions{});
}

namespace {

// Curves from k = 0 (options.firstK = 0) as curves from k' = k + 1 = 1: the same problem with one
// more slot per covered pixel; then k = k' - 1 for every covered pixel.
uint64_t shiftedSlots(const std::vector<std::vector<double>>& curves, uint64_t slots,
                      const OracleOptions& options) {
  MFR_CHECK_LE(options.firstK, 1u);
  if (options.firstK == 1) return slots;
  uint64_t covered = 0;
  for (const std::vector<double>& c : curves) covered += !c.empty();
  return slots > UINT64_MAX - covered ? UINT64_MAX : slots + covered;
}

void unshift(const std::vector<std::vector<double>>& curves, const OracleOptions& options,
             std::vector<uint32_t>& k) {
  if (options.firstK == 1) return;
  for (size_t p = 0; p < curves.size(); ++p)
    if (!curves[p].empty()) --k[p];
}

}  // namespace

std::vector<uint32_t> allocateOptimalHull(const std::vector<std::vector<double>>& curves,
                                          uint64_t slots, const OracleOptions& options) {
  std::vector<uint32_t> k =
      hullAllocation(curves, shiftedSlots(curves, slots, options), options.hullChunkSegments).k;
  unshift(curves, options, k);
  return k;
}

bool errorCurveIsConvex(const std::vector<double>& e) {
  if (e.size() < 3) return true;
  const double tolerance = 1e-12 * std::max(std::fabs(e.front()), 1e-300);
  for (size_t i = 2; i < e.size(); ++i)
    if (e[i - 2] - e[i - 1] < e[i - 1] - e[i] - tolerance) return false;
  return true;
}

namespace {

// allocateOptimal over curves from k = 1
OracleAllocation allocateOptimalFromOne(const std::vector<std::vector<double>>& curves,
                                        uint64_t slots, const OracleOptions& options) {
  OracleAllocation out;
  uint64_t fragments = 0;
  {
    std::vector<uint8_t> nonconvex(curves.size(), 0);
    forEachPixel(curves.size(), [&](size_t p) { nonconvex[p] = !errorCurveIsConvex(curves[p]); });
    for (size_t p = 0; p < curves.size(); ++p) {
      fragments += curves[p].size();
      out.nonconvexPixels += nonconvex[p];
    }
  }
  if (fragments <= slots) {  // every fragment fits: the exact image
    out.k.resize(curves.size());
    for (size_t p = 0; p < curves.size(); ++p) out.k[p] = static_cast<uint32_t>(curves[p].size());
    out.error = out.lowerBound = out.lagrangianBound = allocationError(curves, out.k);
    out.exact = true;
    out.solver = "all-fit";
    return out;
  }

  HullSolution hull = hullAllocation(curves, slots, options.hullChunkSegments);
  const double lambda = hull.lambda;
  // Lagrangian bound: sum_p min_k (err_p(k) + lambda k) - lambda F <= any feasible error
  std::vector<double> floorCost(curves.size(), 0.0);
  forEachPixel(curves.size(), [&](size_t p) {
    const std::vector<double>& e = curves[p];
    if (e.empty()) return;
    double m = std::numeric_limits<double>::infinity();
    for (uint32_t x = 1; x <= e.size(); ++x) m = std::min(m, e[x - 1] + lambda * x);
    floorCost[p] = m;
  });
  double bound = -lambda * static_cast<double>(slots);
  for (size_t p = 0; p < curves.size(); ++p)  // in pixel order: the same sum on any workers
    if (!curves[p].empty()) bound += floorCost[p];
  const double hullError = allocationError(curves, hull.k);
  out.lagrangianBound = std::max(0.0, std::min(bound, hullError));
  out.k = std::move(hull.k);
  out.error = hullError;
  out.lowerBound = out.lagrangianBound;
  out.solver = options.publishedGreedy ? "greedy" : "hull";

  if (options.publishedGreedy) {
    out.k = allocateOptimalGreedy(curves, slots);
    out.error = allocationError(curves, out.k);
    if (out.error <= out.lowerBound) {
      out.lowerBound = out.error;
      out.exact = true;
    }
    return out;
  }

  // rounding: a gap this small is no gap
  const double tolerance = 1e-12 * std::max(out.error, 1e-300);
  if (out.error - out.lowerBound <= tolerance) {
    out.lowerBound = out.error;
    out.exact = true;
    return out;
  }

  // reduced-cost fixing: an improving allocation keeps every r_p(k_p) below the gap
  const double gap = out.error - out.lowerBound + tolerance;
  const auto isCandidate = [&](size_t p, uint32_t x) {
    return x == out.k[p] || curves[p][x - 1] + lambda * x - floorCost[p] <= gap;
  };
  // the pixels with more than one candidate k (few), found in parallel, then listed in order
  std::vector<uint8_t> several(curves.size(), 0);
  forEachPixel(curves.size(), [&](size_t p) {
    uint32_t count = 0;
    for (uint32_t x = 1; x <= curves[p].size() && count < 2; ++x) count += isCandidate(p, x);
    several[p] = count > 1;
  });
  std::vector<uint32_t> core;
  std::vector<std::vector<uint32_t>> coreOptions;
  uint64_t fixedSlots = 0;
  for (size_t p = 0; p < curves.size(); ++p) {
    if (curves[p].empty()) continue;
    if (!several[p]) {
      fixedSlots += out.k[p];
      continue;
    }
    std::vector<uint32_t>& candidates = coreOptions.emplace_back();
    for (uint32_t x = 1; x <= curves[p].size(); ++x)
      if (isCandidate(p, x)) candidates.push_back(x);
    core.push_back(static_cast<uint32_t>(p));
  }
  out.corePixels = core.size();
  uint64_t coreBase = 0;
  for (const std::vector<uint32_t>& o : coreOptions) coreBase += o.front();
  std::vector<uint32_t> k = out.k;
  if (fixedSlots + coreBase <= slots &&
      exactCore(curves, core, coreOptions, slots - fixedSlots - coreBase, options.maxDpCells, k)) {
    const double error = allocationError(curves, k);
    if (error <= out.error) {
      out.k = std::move(k);
      out.error = error;
    }
    out.lowerBound = out.error;
    out.exact = true;
    out.solver = "hull+dp";
    return out;
  }
  // no exact step: never worse than the published greedy
  std::vector<uint32_t> greedy = allocateOptimalGreedy(curves, slots);
  const double greedyError = allocationError(curves, greedy);
  if (greedyError < out.error) {
    out.k = std::move(greedy);
    out.error = greedyError;
    out.solver = "greedy";
  }
  return out;
}

}  // namespace

OracleAllocation allocateOptimal(const std::vector<std::vector<double>>& curves, uint64_t slots,
                                 const OracleOptions& options) {
  OracleAllocation out =
      allocateOptimalFromOne(curves, shiftedSlots(curves, slots, options), options);
  unshift(curves, options, out.k);
  return out;
}

}  // namespace mfr
