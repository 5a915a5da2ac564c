// The optimal k-buffer of Deep Hybrid OIT (Tsopouridis, Vasilakis, Fudos, sec. 3.1.2, Algorithm 1,
// Eq. 2): given every pixel's depth-sorted fragments, choose k(p) >= 1 per covered pixel with
// sum k(p) <= F(M) minimising sum_p |C_u(p) - C(p, k(p))|^2, where C(p, k) is hybrid transparency
// with the first k fragments as core and the rest as tail (compositing.hpp).
//
// Two allocators over the per-pixel error curves err_p(k), k = 1..n(p) (err_p(n) = 0):
//   - allocateOptimalGreedy: Algorithm 1 as published: start from k = n, repeatedly remove the
//     farthest core fragment of the pixel whose error *after* the removal is smallest (min-heap),
//     never below one fragment, until sum k <= F. Optimal only when the curves are convex.
//   - allocateOptimalHull: each curve's lower convex hull gives segments of decreasing error drop
//     per slot; from k = 1 everywhere the steepest segments are bought first, and the last one
//     partially at its best affordable k. Exact on convex curves, and never worse than the greedy
//     when every curve is convex, but not in general: real hybrid curves need not be convex
//     (moving a fragment from the tail to the core can raise the error).
//   - allocateOptimal: the oracle of the `optimal` preset. The hull solution at the critical
//     multiplier lambda gives the Lagrangian lower bound
//         LB = sum_p min_k (err_p(k) + lambda k) - lambda F  <=  minimum total error,
//     and every allocation can be written as LB + lambda (F - sum k) + sum_p r_p(k_p) with reduced
//     costs r_p(k) = err_p(k) + lambda k - min_j (err_p(j) + lambda j) >= 0. An allocation better
//     than the hull's (error A) therefore only uses values with r_p(k) < A - LB (the gap): pixels
//     with a single such value are fixed, and an exact dynamic programme over the others (the
//     "core", a few pixels near the multiplier, where non-convex curves matter) finds the true
//     minimum. When the core is too large for the programme's cell limit, the better of the hull
//     and the published greedy is returned and the bound with its gap is reported.
// Under hybrid compositing a pixel may keep no slot at all (its tail alone, issue 28): the curves
// then start at k = 0 (OracleOptions::firstK = 0, index k) and allocateOptimal and
// allocateOptimalHull solve the same problem over k' = k + 1 with F + (covered pixels) slots,
// which is the same minimum (the bound too) with every covered pixel's k one lower.
// Presets optimal / optimal-greedy run them on an exact A-buffer pre-pass (optimal_oracle.hpp).
// allocateOptimalHull and allocateOptimal run their per-pixel passes on the calling oneTBB task
// arena's workers (the CPU engine calls them in an arena of its thread count); the result is the
// same bits for any number of workers.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/method/fragment_node.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

/// err(k) for k = 1..n of one pixel (index k - 1), squared linear-RGB distance of the hybrid
/// result with k core fragments to the exact result; `sorted` nearest first.
std::vector<double> hybridErrorCurve(const FragmentNode* sorted, uint32_t n, glm::vec3 background);

/// The same for either compositing rule: with kbuffer compositing the fragments beyond k are
/// dropped (the oracle is then optimal for the k-buffer's resolve instead). `firstK` 0 starts the
/// curve at k = 0 (index k; err(0) is the tail alone under hybrid compositing), n + 1 values;
/// empty for n = 0 either way.
std::vector<double> errorCurve(const FragmentNode* sorted, uint32_t n, glm::vec3 background,
                               Compositing compositing, uint32_t firstK = 1);

/// Sum of err over pixels for an allocation of curves starting at k = firstK (k = 0 for empty
/// curves).
double allocationError(const std::vector<std::vector<double>>& curves,
                       const std::vector<uint32_t>& k, uint32_t firstK = 1);

std::vector<uint32_t> allocateOptimalGreedy(const std::vector<std::vector<double>>& curves,
                                            uint64_t slots);
std::vector<uint32_t> allocateOptimalHull(const std::vector<std::vector<double>>& curves,
                                          uint64_t slots);

/// A pixel's curve is convex when its drops err(k) - err(k + 1) never increase (beyond rounding).
bool errorCurveIsConvex(const std::vector<double>& curve);

struct OracleOptions {
  /// Cells (core pixels' options x slot range) the exact step may visit; above, no exact step.
  uint64_t maxDpCells = uint64_t{1} << 28;
  /// Published greedy (DHOIT Algorithm 1) instead of the exact oracle; the bound is still given.
  bool publishedGreedy = false;
  /// The hull allocator sorts the segments below the critical one in chunks of at least this
  /// many (the result does not depend on it; tests lower it to cover the chunking).
  uint64_t hullChunkSegments = uint64_t{1} << 20;
  /// The k of each curve's first value: 1 (every covered pixel keeps a slot), or 0 (hybrid
  /// compositing: a pixel may keep none, err(0) being its tail alone; see the top).
  uint32_t firstK = 1;
};

/// allocateOptimalHull with the chunking of `options` (the same k for any chunk size).
std::vector<uint32_t> allocateOptimalHull(const std::vector<std::vector<double>>& curves,
                                          uint64_t slots, const OracleOptions& options);

/// An allocation with what is known of its distance to the true minimum.
struct OracleAllocation {
  std::vector<uint32_t> k;  // per pixel; 0 for empty curves (and tail-only pixels, firstK = 0)
  double error = 0.0;       // sum_p err_p(k_p)
  /// Proven lower bound on the minimum total error: the minimum itself when `exact`, else the
  /// Lagrangian (hull) bound. error - lowerBound is the reported gap (0 when exact).
  double lowerBound = 0.0;
  double lagrangianBound = 0.0;  // the hull relaxation's bound, always computed
  bool exact = false;            // error is the minimum (proven)
  uint64_t nonconvexPixels = 0;  // pixels whose curve is not convex
  uint64_t corePixels = 0;       // pixels left free for the exact step
  const char* solver = "";       // "all-fit", "hull", "hull+dp", "greedy"
  double gap() const { return error - lowerBound; }
};

/// The optimal k-buffer's allocation with its bound (see the comment at the top). With
/// options.firstK = 1 it requires slots >= the number of non-empty curves (one fragment per
/// covered pixel); with firstK = 0 any slots.
OracleAllocation allocateOptimal(const std::vector<std::vector<double>>& curves, uint64_t slots,
                                 const OracleOptions& options = {});

}  // namespace mfr
