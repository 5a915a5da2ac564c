// Per-pixel fragment stores of the k-buffer family (k+-buffer paper, Vasilakis & Fudos 2014,
// sec. 3.2 and Algorithm 2): the max-array and the max-heap keep the k nearest fragments of a pixel
// in any arrival order, with the current maximum always in slot 0 so the culling test is O(1); the
// append store is the S-buffer's exact-size array used by the A-buffer.
//
// One pixel's region, `capacity` nodes of 8 bytes (see FragmentNode), and its counter:
//
//        slot:    0        1        2             count-1            capacity-1
//              +--------+--------+--------+ ... +--------+--------+ ... +--------+
//   max-array  |  max   | any    | any    |     | any    | unused |     | unused |
//   max-heap   |  root  | child of 0      |     | heap order (parent >= children)  |
//   append     | arrival order, never full-replaced (capacity == exact fragment count) |
//              +--------+--------+--------+ ... +--------+--------+ ... +--------+
//   node (8 B): bits 63..32 float32 depth, bits 31..0 RGBA8 (R low byte)
//   "empty": slots >= count are never read; count == 0 is an empty pixel.
//
// Insertion into a full store replaces the maximum and returns it as `evicted` (hybrid
// transparency moves it to the tail). Slot 0 and the counter are the only words read outside a
// pixel's critical section (the k+ culling test), so they are written through the Access policy:
// plain stores in tile-owned capture, relaxed atomics in fragment-parallel capture.
#pragma once

#include <atomic>
#include <cstdint>
#include <utility>

#include "mfr/method/fragment_node.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

/// Plain memory access (one owner per pixel).
struct PlainAccess {
  template <class T>
  static T load(const T& v) {
    return v;
  }
  template <class T>
  static void store(T& v, T x) {
    v = x;
  }
  static uint32_t loadCount(const uint32_t& c) { return c; }
  static void publishCount(uint32_t& c, uint32_t x) { c = x; }
};

/// Atomic access of the words read outside the critical section. The counter is published with
/// release after slot 0 is written and read with acquire before slot 0 is read, so a reader that
/// sees a full store also sees the slot 0 of that full store (never an older, smaller maximum
/// that would cull a fragment wrongly on weakly ordered machines).
struct AtomicAccess {
  template <class T>
  static T load(const T& v) {
    return std::atomic_ref<T>(const_cast<T&>(v)).load(std::memory_order_relaxed);
  }
  template <class T>
  static void store(T& v, T x) {
    std::atomic_ref<T>(v).store(x, std::memory_order_relaxed);
  }
  static uint32_t loadCount(const uint32_t& c) {
    return std::atomic_ref<uint32_t>(const_cast<uint32_t&>(c)).load(std::memory_order_acquire);
  }
  static void publishCount(uint32_t& c, uint32_t x) {
    std::atomic_ref<uint32_t>(c).store(x, std::memory_order_release);
  }
};

enum class InsertOutcome : uint8_t { Inserted, Replaced, Rejected };

/// The k+ culling test: false when the store is full and the node is not nearer than the maximum
/// (a pixel with no slots, capacity 0, rejects everything).
template <class Access = PlainAccess>
inline bool passesKPlusTest(const FragmentNode* slots, const uint32_t& count, uint32_t capacity,
                            FragmentNode node) {
  const uint32_t n = Access::loadCount(count);
  return n < capacity || (n > 0 && node < Access::load(slots[0]));
}

/// Append (S-buffer / A-buffer): capacity is the pixel's exact fragment count, so it never
/// overflows.
inline InsertOutcome appendInsert(FragmentNode* slots, uint32_t& count, FragmentNode node) {
  slots[count++] = node;
  return InsertOutcome::Inserted;
}

/// Max-array insertion: O(1) while not full; when full, replace the maximum and find the new one
/// by a linear scan (O(k)).
template <class Access = PlainAccess>
inline InsertOutcome maxArrayInsert(FragmentNode* slots, uint32_t& count, uint32_t capacity,
                                    FragmentNode node, FragmentNode& evicted) {
  const uint32_t n = count;
  if (n < capacity) {
    if (n > 0 && node > slots[0]) {  // new maximum goes to slot 0
      slots[n] = slots[0];
      Access::store(slots[0], node);
    } else if (n == 0) {
      Access::store(slots[0], node);
    } else {
      slots[n] = node;
    }
    Access::publishCount(count, n + 1);
    return InsertOutcome::Inserted;
  }
  if (n == 0 || !(node < slots[0])) return InsertOutcome::Rejected;
  evicted = slots[0];
  uint32_t maxIndex = 0;
  FragmentNode maxNode = node;
  for (uint32_t i = 1; i < n; ++i)
    if (slots[i] > maxNode) {
      maxNode = slots[i];
      maxIndex = i;
    }
  if (maxIndex != 0) slots[maxIndex] = node;
  Access::store(slots[0], maxNode);
  return InsertOutcome::Replaced;
}

/// Max-heap insertion (Algorithm 2): up-heap while not full, replace the root and down-heap when
/// full; O(log k).
template <class Access = PlainAccess>
inline InsertOutcome maxHeapInsert(FragmentNode* slots, uint32_t& count, uint32_t capacity,
                                   FragmentNode node, FragmentNode& evicted) {
  const uint32_t n = count;
  if (n < capacity) {
    uint32_t i = n;
    while (i > 0) {  // up-heap: move parents down into the hole
      const uint32_t parent = (i - 1) / 2;
      if (!(node > slots[parent])) break;
      if (parent == 0)
        slots[i] = slots[0];
      else
        slots[i] = slots[parent];
      i = parent;
    }
    if (i == 0)
      Access::store(slots[0], node);
    else
      slots[i] = node;
    Access::publishCount(count, n + 1);
    return InsertOutcome::Inserted;
  }
  if (n == 0 || !(node < slots[0])) return InsertOutcome::Rejected;
  evicted = slots[0];
  uint32_t i = 0;  // down-heap: move the larger child up into the hole
  for (;;) {
    const uint32_t left = 2 * i + 1;
    if (left >= n) break;
    const uint32_t right = left + 1;
    const uint32_t child = (right < n && slots[right] > slots[left]) ? right : left;
    if (!(slots[child] > node)) break;
    if (i == 0)
      Access::store(slots[0], slots[child]);
    else
      slots[i] = slots[child];
    i = child;
  }
  if (i == 0)
    Access::store(slots[0], node);
  else
    slots[i] = node;
  return InsertOutcome::Replaced;
}

template <class Access = PlainAccess>
inline InsertOutcome storeInsert(StoreKind kind, FragmentNode* slots, uint32_t& count,
                                 uint32_t capacity, FragmentNode node, FragmentNode& evicted) {
  switch (kind) {
    case StoreKind::Append:
      return appendInsert(slots, count, node);
    case StoreKind::MaxArray:
      return maxArrayInsert<Access>(slots, count, capacity, node, evicted);
    case StoreKind::MaxHeap:
      return maxHeapInsert<Access>(slots, count, capacity, node, evicted);
  }
  return InsertOutcome::Rejected;  // not reached: every StoreKind is a case (-Wswitch)
}

}  // namespace mfr
