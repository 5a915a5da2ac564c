// Optimal k-buffer allocators (DHOIT sec. 3.1.2, Algorithm 1); see optimal_allocation.hpp.
#include "mfr/method/optimal_allocation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "mfr/core/color.hpp"

namespace mfr {

std::vector<double> errorCurve(const FragmentNode* sorted, uint32_t n, glm::vec3 background,
                               Compositing compositing) {
  std::vector<double> err(n, 0.0);
  if (n == 0) return err;
  // prefix: core colour and transmittance; suffix: tail sums
  std::vector<glm::dvec3> core(n + 1, glm::dvec3(0.0));
  std::vector<double> T(n + 1, 1.0);
  std::vector<glm::dvec3> tailColor(n + 2, glm::dvec3(0.0));
  std::vector<double> tailAlpha(n + 2, 0.0);
  for (uint32_t i = 0; i < n; ++i) {
    const glm::dvec4 c(unpackFragmentColor(nodeColor(sorted[i])));
    core[i + 1] = core[i] + glm::dvec3(c) * (c.a * T[i]);
    T[i + 1] = T[i] * (1.0 - c.a);
  }
  for (uint32_t i = n; i-- > 0;) {
    const glm::dvec4 c(unpackFragmentColor(nodeColor(sorted[i])));
    tailColor[i] = tailColor[i + 1] + glm::dvec3(c) * c.a;
    tailAlpha[i] = tailAlpha[i + 1] + c.a;
  }
  const glm::dvec3 bg(background);
  auto hybrid = [&](uint32_t k) {
    const uint32_t t = n - k;
    if (compositing == Compositing::KBuffer) return core[k] + T[k] * bg;  // tail dropped
    if (t == 0 || tailAlpha[k] <= 0.0) return core[k] + T[k] * bg;
    const glm::dvec3 colour = tailColor[k] / tailAlpha[k];
    const double alpha =
        1.0 - std::pow(std::max(0.0, 1.0 - tailAlpha[k] / t), static_cast<double>(t));
    return core[k] + T[k] * (alpha * colour + (1.0 - alpha) * bg);
  };
  const glm::dvec3 exact = hybrid(n);
  for (uint32_t k = 1; k <= n; ++k) {
    const glm::dvec3 d = exact - hybrid(k);
    err[k - 1] = glm::dot(d, d);
  }
  return err;
}

std::vector<double> hybridErrorCurve(const FragmentNode* sorted, uint32_t n, glm::vec3 background) {
  return errorCurve(sorted, n, background, Compositing::Hybrid);
}

double allocationError(const std::vector<std::vector<double>>& curves,
                       const std::vector<uint32_t>& k) {
  double total = 0.0;
  for (size_t p = 0; p < curves.size(); ++p)
    if (!curves[p].empty()) total += curves[p][k[p] - 1];
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

struct HullSolution {
  std::vector<uint32_t> k;
  double lambda = 0.0;  // drop per slot of the first segment not bought whole (0: all bought)
};

// The hull allocator (see the header); also returns the critical multiplier lambda.
HullSolution hullAllocation(const std::vector<std::vector<double>>& curves, uint64_t slots) {
  HullSolution out;
  std::vector<uint32_t>& k = out.k;
  k.assign(curves.size(), 0);
  uint64_t used = 0;
  struct Segment {
    double dropPerSlot;
    uint32_t pixel, from, to;  // k values
  };
  std::vector<Segment> segments;
  std::vector<uint32_t> hull;
  for (size_t p = 0; p < curves.size(); ++p) {
    const std::vector<double>& e = curves[p];
    if (e.empty()) continue;
    k[p] = 1;
    ++used;
    // lower convex hull of (k, e(k)), k = 1..n (monotone chain)
    hull.clear();
    for (uint32_t x = 1; x <= e.size(); ++x) {
      while (hull.size() >= 2) {
        const uint32_t a = hull[hull.size() - 2], b = hull.back();
        // drop b if it lies on or above the line from a to x
        const double cross = (e[b - 1] - e[a - 1]) * (x - a) - (e[x - 1] - e[a - 1]) * (b - a);
        if (cross >= 0.0) {
          hull.pop_back();
        } else {
          break;
        }
      }
      hull.push_back(x);
    }
    for (size_t i = 1; i < hull.size(); ++i)
      segments.push_back({(e[hull[i - 1] - 1] - e[hull[i] - 1]) / (hull[i] - hull[i - 1]),
                          static_cast<uint32_t>(p), hull[i - 1], hull[i]});
  }
  // convex hulls: within a pixel the drops decrease, so the global order respects each chain
  std::stable_sort(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) {
    return a.dropPerSlot > b.dropPerSlot;
  });
  bool critical = false;
  for (const Segment& s : segments) {
    if (k[s.pixel] != s.from) continue;  // an earlier segment of this pixel was cut short
    const uint64_t cost = s.to - s.from;
    if (used + cost <= slots) {
      k[s.pixel] = s.to;
      used += cost;
      continue;
    }
    if (!critical) {
      critical = true;
      out.lambda = std::max(0.0, s.dropPerSlot);
    }
    if (used >= slots) break;
    // partial: the best k in (from, from + affordable]
    const std::vector<double>& e = curves[s.pixel];
    uint32_t best = s.from;
    for (uint32_t x = s.from + 1; x <= s.from + (slots - used); ++x)
      if (e[x - 1] < e[best - 1]) best = x;
    used += best - s.from;
    k[s.pixel] = best;
  }
  return out;
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
  return hullAllocation(curves, slots).k;
}

bool errorCurveIsConvex(const std::vector<double>& e) {
  if (e.size() < 3) return true;
  const double tolerance = 1e-12 * std::max(std::fabs(e.front()), 1e-300);
  for (size_t i = 2; i < e.size(); ++i)
    if (e[i - 2] - e[i - 1] < e[i - 1] - e[i] - tolerance) return false;
  return true;
}

OracleAllocation allocateOptimal(const std::vector<std::vector<double>>& curves, uint64_t slots,
                                 const OracleOptions& options) {
  OracleAllocation out;
  uint64_t fragments = 0;
  for (const std::vector<double>& e : curves) {
    fragments += e.size();
    out.nonconvexPixels += !errorCurveIsConvex(e);
  }
  if (fragments <= slots) {  // every fragment fits: the exact image
    out.k.resize(curves.size());
    for (size_t p = 0; p < curves.size(); ++p) out.k[p] = static_cast<uint32_t>(curves[p].size());
    out.error = out.lowerBound = out.lagrangianBound = allocationError(curves, out.k);
    out.exact = true;
    out.solver = "all-fit";
    return out;
  }

  HullSolution hull = hullAllocation(curves, slots);
  const double lambda = hull.lambda;
  // Lagrangian bound: sum_p min_k (err_p(k) + lambda k) - lambda F <= any feasible error
  std::vector<double> floorCost(curves.size(), 0.0);
  double bound = -lambda * static_cast<double>(slots);
  for (size_t p = 0; p < curves.size(); ++p) {
    const std::vector<double>& e = curves[p];
    if (e.empty()) continue;
    double m = std::numeric_limits<double>::infinity();
    for (uint32_t x = 1; x <= e.size(); ++x) m = std::min(m, e[x - 1] + lambda * x);
    floorCost[p] = m;
    bound += m;
  }
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
  std::vector<uint32_t> core;
  std::vector<std::vector<uint32_t>> coreOptions;
  uint64_t fixedSlots = 0;
  std::vector<uint32_t> candidates;
  for (size_t p = 0; p < curves.size(); ++p) {
    const std::vector<double>& e = curves[p];
    if (e.empty()) continue;
    candidates.clear();
    for (uint32_t x = 1; x <= e.size(); ++x)
      if (x == out.k[p] || e[x - 1] + lambda * x - floorCost[p] <= gap) candidates.push_back(x);
    if (candidates.size() == 1) {
      fixedSlots += out.k[p];
      continue;
    }
    core.push_back(static_cast<uint32_t>(p));
    coreOptions.push_back(candidates);
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

}  // namespace mfr
