// What the comparison report concludes from a CompareResult (report_html.cpp): the methods ranked
// per budget and the winner with its margin, the error-vs-cost Pareto fronts, the methods whose
// memory the budget does not move, where each run's error is worst, and whether an error axis
// wants a log scale. Pure functions of the result, so they can be tested on hand-made values.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "mfr/compare/compare.hpp"
#include "mfr/core/image.hpp"

namespace mfr {

/// The indices of `budget`'s successful runs, best first: by mean FLIP, ties by total time, then
/// by the runs' order. Failed runs are not ranked.
std::vector<size_t> rankRuns(const CompareBudget& budget);

/// The winner of a budget and how far ahead of the runner-up it is.
struct Recommendation {
  std::optional<size_t> winner;    // index into the budget's runs; none: no run succeeded
  std::optional<size_t> runnerUp;  // none: one run succeeded
  double flipMargin = 0.0;      // runner-up's mean FLIP - the winner's (0: a tie, decided by time)
  double relativeMargin = 0.0;  // flipMargin / the runner-up's FLIP (0 when that is 0)
  double timeMarginMs = 0.0;    // runner-up's total ms - the winner's (may be negative)
};

/// rankRuns' first two runs and their margins.
Recommendation recommend(const CompareBudget& budget);

/// One run as a point of an error-vs-cost plane (cost: bytes, or milliseconds).
struct FrontPoint {
  double error = 0.0;
  double cost = 0.0;
};

/// Pareto front membership, one flag per point: a point is on the front when no other point
/// dominates it, i.e. has error <= and cost <= with at least one of them strictly less. Equal
/// points do not dominate each other (both are on the front or neither is).
std::vector<bool> paretoFront(const std::vector<FrontPoint>& points);

/// How an axis of non-negative values is scaled.
struct AxisScale {
  bool log = false;
  /// Log axes only: where a value of 0 is drawn (marked "exact"): the decade below the smallest
  /// positive value (10^(floor(log10(min positive)) - 1)). 0 on a linear axis.
  double floor = 0.0;
};

/// A log axis when the positive values span a decade or more (largest / smallest positive >= 10),
/// zeros then drawn at AxisScale::floor; linear otherwise (also with fewer than two positive
/// values). Non-finite values are ignored.
AxisScale chooseAxisScale(const std::vector<double>& values);

/// A square window of an image.
struct ImageWindow {
  int x = 0, y = 0;   // top-left pixel
  int size = 0;       // width and height in pixels
  double mean = 0.0;  // mean of the values in it
};

/// The size x size window (size clamped to the image) whose values have the highest mean; ties:
/// the topmost, then leftmost. `values` holds width * height values, rows top to bottom. A
/// window of size 0 for an empty image.
ImageWindow worstWindow(const std::vector<float>& values, int width, int height, int size);

/// The side of the worst-region window for a width x height image: half the smaller side, at
/// least 8 (or the whole side if smaller) and at most 64.
int worstWindowSize(int width, int height);

/// The FLIP values of a FLIP error image (flipErrorImage: magma index round(255 e)) read back
/// through the magma table: e to within 1/510. A colour not in the table reads as its nearest.
std::vector<float> flipValuesOfImage(const Image8& flipImage);

/// Methods whose memory the budget does not move: the method succeeded at two budgets or more and
/// used the same bytes with the same F(M) at each (failed runs, e.g. a budget below its fixed
/// need, do not count; an exact k-buffer using less than a growing node pool is not fixed).
/// In the methods' order (the first budget's runs).
std::vector<std::string> fixedMemoryMethods(const CompareResult& result);

}  // namespace mfr
