// Sorting one pixel's captured nodes for the resolve (k+-buffer paper sec. 3.3: the k nearest are
// sorted once per pixel before compositing). Small stores (k <= 8, the common budgets) go through a
// branchless sorting network on registers; larger ones through std::sort on the caller's scratch.
// The node order is total (depth, then colour), so every sort gives the same sequence.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "mfr/method/fragment_node.hpp"

namespace mfr::detail {

/// The largest count sortNodes() handles with the network.
inline constexpr uint32_t kSortNetworkSize = 8;

inline void compareExchange(uint64_t& a, uint64_t& b) {
  const uint64_t lo = a < b ? a : b;  // cmov, no branch
  const uint64_t hi = a < b ? b : a;
  a = lo;
  b = hi;
}

/// Knuth's 19-comparator network for 8 inputs (TAOCP vol. 3, 5.3.4), on registers.
inline void sortingNetwork8(uint64_t (&v)[8]) {
  compareExchange(v[0], v[2]);
  compareExchange(v[1], v[3]);
  compareExchange(v[4], v[6]);
  compareExchange(v[5], v[7]);
  compareExchange(v[0], v[4]);
  compareExchange(v[1], v[5]);
  compareExchange(v[2], v[6]);
  compareExchange(v[3], v[7]);
  compareExchange(v[0], v[1]);
  compareExchange(v[2], v[3]);
  compareExchange(v[4], v[5]);
  compareExchange(v[6], v[7]);
  compareExchange(v[2], v[4]);
  compareExchange(v[3], v[5]);
  compareExchange(v[1], v[4]);
  compareExchange(v[3], v[6]);
  compareExchange(v[1], v[2]);
  compareExchange(v[3], v[4]);
  compareExchange(v[5], v[6]);
}

/// The `n` nodes at `nodes`, sorted nearest first, in `out` (kSortNetworkSize or more slots) when
/// n <= kSortNetworkSize, else in `scratch` (reused: no allocation once it has grown). Returns the
/// sorted sequence.
inline const FragmentNode* sortNodes(const FragmentNode* nodes, uint32_t n,
                                     FragmentNode (&out)[kSortNetworkSize],
                                     std::vector<FragmentNode>& scratch) {
  if (n <= kSortNetworkSize) {
    // pad with the largest key: it sorts last and is never read
    for (uint32_t i = 0; i < kSortNetworkSize; ++i) out[i] = i < n ? nodes[i] : ~FragmentNode{0};
    sortingNetwork8(out);
    return out;
  }
  scratch.assign(nodes, nodes + n);
  std::sort(scratch.begin(), scratch.end());
  return scratch.data();
}

}  // namespace mfr::detail
