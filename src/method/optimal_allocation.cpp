// Optimal k-buffer allocators (DHOIT sec. 3.1.2, Algorithm 1); see optimal_allocation.hpp.
#include "mfr/method/optimal_allocation.hpp"

#include <algorithm>
#include <cmath>
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

std::vector<uint32_t> allocateOptimalHull(const std::vector<std::vector<double>>& curves,
                                          uint64_t slots) {
  std::vector<uint32_t> k(curves.size(), 0);
  uint64_t used = 0;
  struct Segment {
    double dropPerSlot;
    uint32_t pixel, from, to;  // k values
  };
  std::vector<Segment> segments;
  for (size_t p = 0; p < curves.size(); ++p) {
    const std::vector<double>& e = curves[p];
    if (e.empty()) continue;
    k[p] = 1;
    ++used;
    // lower convex hull of (k, e(k)), k = 1..n (monotone chain)
    std::vector<uint32_t> hull;
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
  for (const Segment& s : segments) {
    if (used >= slots) break;
    if (k[s.pixel] != s.from) continue;  // an earlier segment of this pixel was cut short
    const uint64_t cost = s.to - s.from;
    if (used + cost <= slots) {
      k[s.pixel] = s.to;
      used += cost;
      continue;
    }
    // partial: the best k in (from, from + affordable]
    const std::vector<double>& e = curves[s.pixel];
    uint32_t best = s.from;
    for (uint32_t x = s.from + 1; x <= s.from + (slots - used); ++x)
      if (e[x - 1] < e[best - 1]) best = x;
    used += best - s.from;
    k[s.pixel] = best;
  }
  return k;
}

}  // namespace mfr
