// The report's conclusions (mfr/compare/report_ranking.hpp).
#include "mfr/compare/report_ranking.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "mfr/metrics/magma.hpp"

namespace mfr {

std::vector<size_t> rankRuns(const CompareBudget& budget) {
  std::vector<size_t> order;
  for (size_t i = 0; i < budget.runs.size(); ++i)
    if (budget.runs[i].ok()) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const CompareRun &ra = budget.runs[a], &rb = budget.runs[b];
    if (ra.metrics.flipMean != rb.metrics.flipMean)
      return ra.metrics.flipMean < rb.metrics.flipMean;
    return ra.stats.totalMs() < rb.stats.totalMs();
  });
  return order;
}

Recommendation recommend(const CompareBudget& budget) {
  const std::vector<size_t> order = rankRuns(budget);
  Recommendation r;
  if (order.empty()) return r;
  r.winner = order[0];
  if (order.size() < 2) return r;
  r.runnerUp = order[1];
  const CompareRun &w = budget.runs[order[0]], &s = budget.runs[order[1]];
  r.flipMargin = s.metrics.flipMean - w.metrics.flipMean;
  r.relativeMargin = s.metrics.flipMean > 0.0 ? r.flipMargin / s.metrics.flipMean : 0.0;
  r.timeMarginMs = s.stats.totalMs() - w.stats.totalMs();
  return r;
}

std::vector<bool> paretoFront(const std::vector<FrontPoint>& points) {
  std::vector<bool> front(points.size(), true);
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t j = 0; j < points.size() && front[i]; ++j) {
      const FrontPoint &p = points[i], &q = points[j];
      const bool noWorse = q.error <= p.error && q.cost <= p.cost;
      const bool better = q.error < p.error || q.cost < p.cost;
      if (j != i && noWorse && better) front[i] = false;
    }
  return front;
}

AxisScale chooseAxisScale(const std::vector<double>& values) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (double v : values)
    if (std::isfinite(v) && v > 0.0) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  AxisScale s;
  if (!std::isfinite(lo) || hi / lo < 10.0) return s;
  s.log = true;
  s.floor = std::pow(10.0, std::floor(std::log10(lo)) - 1.0);
  return s;
}

namespace {

// summed-area table with a zero row and column: sat[(y) * (w + 1) + x] = sum over [0, x) x [0, y)
std::vector<double> summedArea(const std::vector<float>& values, int width, int height) {
  const size_t w1 = static_cast<size_t>(width) + 1;
  std::vector<double> sat(w1 * (static_cast<size_t>(height) + 1), 0.0);
  for (int y = 0; y < height; ++y) {
    double row = 0.0;
    for (int x = 0; x < width; ++x) {
      row += values[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)];
      sat[(static_cast<size_t>(y) + 1) * w1 + static_cast<size_t>(x) + 1] =
          sat[static_cast<size_t>(y) * w1 + static_cast<size_t>(x) + 1] + row;
    }
  }
  return sat;
}

}  // namespace

ImageWindow worstWindow(const std::vector<float>& values, int width, int height, int size) {
  ImageWindow best;
  if (width <= 0 || height <= 0 || values.size() != static_cast<size_t>(width) * height)
    return best;
  const int s = std::clamp(size, 1, std::min(width, height));
  const std::vector<double> sat = summedArea(values, width, height);
  const size_t w1 = static_cast<size_t>(width) + 1;
  const auto at = [&](int x, int y) { return sat[static_cast<size_t>(y) * w1 + x]; };
  double bestSum = -1.0;
  for (int y = 0; y + s <= height; ++y)
    for (int x = 0; x + s <= width; ++x) {
      const double sum = at(x + s, y + s) - at(x, y + s) - at(x + s, y) + at(x, y);
      if (sum > bestSum + 1e-9) {
        bestSum = sum;
        best.x = x;
        best.y = y;
      }
    }
  best.size = s;
  best.mean = bestSum / (static_cast<double>(s) * s);
  return best;
}

int worstWindowSize(int width, int height) {
  const int side = std::min(width, height);
  return std::min({64, side, std::max(8, side / 2)});
}

namespace {

uint32_t rgbKey(uint8_t r, uint8_t g, uint8_t b) {
  return (uint32_t{r} << 16) | (uint32_t{g} << 8) | b;
}

int nearestMagma(uint8_t r, uint8_t g, uint8_t b) {
  int best = 0;
  long bestDistance = std::numeric_limits<long>::max();
  for (int i = 0; i < 256; ++i) {
    const auto c = magma8(i);
    const long dr = long{c[0]} - r, dg = long{c[1]} - g, db = long{c[2]} - b;
    const long d = dr * dr + dg * dg + db * db;
    if (d < bestDistance) {
      bestDistance = d;
      best = i;
    }
  }
  return best;
}

}  // namespace

std::vector<float> flipValuesOfImage(const Image8& image) {
  std::unordered_map<uint32_t, int> index;
  for (int i = 0; i < 256; ++i) {
    const auto c = magma8(i);
    index.emplace(rgbKey(c[0], c[1], c[2]), i);
  }
  const size_t pixels = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  std::vector<float> values(pixels, 0.0f);
  for (size_t p = 0; p < pixels && p * 4 + 2 < image.rgba.size(); ++p) {
    const uint8_t* c = &image.rgba[p * 4];
    const uint32_t key = rgbKey(c[0], c[1], c[2]);
    auto it = index.find(key);
    if (it == index.end()) it = index.emplace(key, nearestMagma(c[0], c[1], c[2])).first;
    values[p] = static_cast<float>(it->second) / 255.0f;
  }
  return values;
}

std::vector<std::string> fixedMemoryMethods(const CompareResult& result) {
  std::vector<std::string> fixed;
  if (result.budgets.size() < 2) return fixed;
  for (size_t m = 0; m < result.budgets[0].runs.size(); ++m) {
    const CompareRun* first = nullptr;
    bool same = true;
    int ran = 0;
    for (const CompareBudget& cb : result.budgets) {
      if (m >= cb.runs.size() || !cb.runs[m].ok()) continue;
      if (!first) first = &cb.runs[m];
      // the same bytes and the same F(M): an exact k-buffer that used less than a growing
      // budget is not fixed, its node pool grew with the budget
      same = same && cb.runs[m].stats.bytesUsed == first->stats.bytesUsed &&
             cb.runs[m].budgetSlots == first->budgetSlots;
      ++ran;
    }
    if (ran >= 2 && same) fixed.push_back(first->label);
  }
  return fixed;
}

}  // namespace mfr
