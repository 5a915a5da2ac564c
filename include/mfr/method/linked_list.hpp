// Per-pixel linked lists with a fixed node pool: J. C. Yang, J. Hensley, H. Gruen, N. Thibieroz,
// "Real-Time Concurrent Linked List Construction on the GPU", EGSR 2010 (Computer Graphics Forum
// 29(4)). The preset `linked-list` is a composition (method.hpp): the Pool allocation (one pool of
// F(M) nodes for the whole image, handed out by a counter) and the LinkedList store (a head word
// per pixel, each node linking to the pixel's previous head), with the k-buffer family's
// compositing rules: the resolve walks a pixel's list, sorts its nodes by the FragmentNode key
// (depth bits, colour word) and composites front to back (kbuffer), or, under hybrid compositing,
// over the order-independent tail of the fragments the full pool turned away.
//
// Memory (memory_model.hpp): heads 4 B per pixel + the pool counter 4 B + F(M) nodes of 12 B
// (+ the hybrid tail's 20 B per pixel); F(M) = floor((M - |P| * S_p - 4) / 12).
//
// Which fragments get a node when the pool runs out is defined as a serial GPU would hand them
// out: in primitive order, and within a triangle (its clipped pieces in set-up order) in its
// scanline order (rows top to bottom, left to right). Both CPU captures follow it for any number
// of threads (src/cpu/linked_list.cpp); the GL engine's atomic counter hands them out in its own
// arrival order, so it admits the same set only while the pool does not overflow.
#pragma once

#include <bit>
#include <cstdint>

#include "mfr/method/fragment_node.hpp"

namespace mfr {

/// One pool node: 12 bytes, as the GL engine's pool buffer lays it out (three uint words).
struct LinkedNode {
  uint32_t depthBits;  // float32 window-space depth, as bits
  uint32_t rgba;       // packFragmentColor(): sRGB8 colour, linear alpha8
  uint32_t next;       // the pixel's previous head (kListEnd: none)
};
static_assert(sizeof(LinkedNode) == 12);

/// The head word of an empty pixel and the next index of a list's last node.
inline constexpr uint32_t kListEnd = 0xFFFFFFFFu;

/// The node's sort key: the stores' FragmentNode (depth bits high, colour low).
inline FragmentNode sortKey(const LinkedNode& n) {
  return (static_cast<uint64_t>(n.depthBits) << 32) | n.rgba;
}

inline LinkedNode makeLinkedNode(float depth, uint32_t rgba, uint32_t next) {
  return {std::bit_cast<uint32_t>(depth), rgba, next};
}

}  // namespace mfr
