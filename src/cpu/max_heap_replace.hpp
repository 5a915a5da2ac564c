// Replacing the root of a full max-heap without data-dependent branches (k+-buffer paper,
// Vasilakis & Fudos 2014, Algorithm 2, the full-store case of max-heap insertion).
//
// maxHeapInsert (mfr/cpu/fragment_stores.hpp) leaves the down-heap as soon as no child is larger
// than the new node: one unpredictable branch per level, which costs more than the level itself
// when most fragments evict (layered scenes at k = 8). Here every level of the heap runs (there
// are floor(log2 n) of them), each with conditional moves only: once the node has found its
// place, the remaining levels rewrite slots with their own values. The final heap, slot by slot,
// is the one maxHeapInsert leaves (the same child choice: the right one only when strictly larger).
#pragma once

#include <bit>
#include <cstdint>

#include "mfr/method/fragment_node.hpp"

namespace mfr::detail {

/// `slots` holds a max-heap of n >= 1 nodes and node < slots[0]: puts node in, returns the old
/// root (the evicted maximum).
inline FragmentNode maxHeapReplaceRoot(FragmentNode* slots, uint32_t n, FragmentNode node) {
  const FragmentNode evicted = slots[0];
  const int levels = std::bit_width(n) - 1;
  uint32_t i = 0;
  bool placed = false;
  for (int level = 0; level < levels; ++level) {
    const uint32_t left = 2 * i + 1, right = left + 1;
    const uint32_t l = left < n ? left : i;  // in range even when i is a leaf (then unused)
    const uint32_t r = right < n ? right : l;
    const FragmentNode sl = slots[l], sr = slots[r];
    const uint32_t child = sr > sl ? r : l;
    const FragmentNode sc = sr > sl ? sr : sl;
    const bool move = !placed && left < n && sc > node;
    slots[i] = move ? sc : slots[i];
    i = move ? child : i;
    placed = !move;
  }
  slots[i] = node;
  return evicted;
}

}  // namespace mfr::detail
