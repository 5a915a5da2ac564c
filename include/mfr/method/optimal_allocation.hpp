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
//     on the counterexamples of tests/test_optimal_allocation.cpp.
// Presets optimal / optimal-greedy run them on an exact A-buffer pre-pass (optimal_oracle.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/method/method.hpp"
#include "mfr/raster/fragment.hpp"

namespace mfr {

/// err(k) for k = 1..n of one pixel (index k - 1), squared linear-RGB distance of the hybrid
/// result with k core fragments to the exact result; `sorted` nearest first.
std::vector<double> hybridErrorCurve(const FragmentNode* sorted, uint32_t n, glm::vec3 background);

/// The same for either compositing rule: with kbuffer compositing the fragments beyond k are
/// dropped (the oracle is then optimal for the k-buffer's resolve instead).
std::vector<double> errorCurve(const FragmentNode* sorted, uint32_t n, glm::vec3 background,
                               Compositing compositing);

/// Sum of err over pixels for an allocation (k = 0 only for empty curves).
double allocationError(const std::vector<std::vector<double>>& curves,
                       const std::vector<uint32_t>& k);

std::vector<uint32_t> allocateOptimalGreedy(const std::vector<std::vector<double>>& curves,
                                            uint64_t slots);
std::vector<uint32_t> allocateOptimalHull(const std::vector<std::vector<double>>& curves,
                                          uint64_t slots);

}  // namespace mfr
