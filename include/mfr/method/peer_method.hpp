// The peer methods as types: the transparency methods engines ship instead of k-buffers, each
// described by one type in its own header beside its per-pixel state and rules (wboit.hpp,
// mboit.hpp, mlab.hpp). A peer type says
//
//   kRule          the Compositing value that names it
//   Slot           its per-pixel state (an accumulator), or one node of its per-pixel nodes
//   kNodes         false: one Slot per pixel; true: k(p) Slots at the fixed-k allocation's offsets
//   kExtraPasses   its geometry passes before the capture, by name (mboit: "moments")
//   add(px, pass, depth, rgba)   one fragment in pass `pass` (0..extra-1, then the capture's)
//   composite(slots, count, bg)  the pixel's colour over the background
//
// and the memory model, the pass plan and the CPU engine's one template (src/cpu/peer_methods.cpp)
// read everything else from it. visitPeer is the one switch from a rule to its type.
//
// A new peer method: its header (state, rules, type), a Compositing value and toString
// (method.hpp, method.cpp), its preset row (method.cpp), its case below; on the GL engine its
// shaders and technique.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/method/mboit.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/mlab.hpp"
#include "mfr/method/wboit.hpp"

namespace mfr {

/// One pixel's state as add() sees it: its Slots, the count of fragments it holds (nodes in use,
/// or fragments accumulated) and, for a method of nodes, k(p).
template <class Slot>
struct PeerPixel {
  Slot* slots;
  uint32_t& count;
  uint32_t capacity;
};

/// Calls `f.template operator()<Peer>()` with the peer type of `rule`; false (and no call) for
/// the k-buffer family's rules.
template <class F>
bool visitPeer(Compositing rule, F&& f) {
  switch (rule) {
    case Compositing::WeightedBlended:
      f.template operator()<WboitMethod>();
      return true;
    case Compositing::MomentBased:
      f.template operator()<MboitMethod>();
      return true;
    case Compositing::MultiLayerAlpha:
      f.template operator()<MlabMethod>();
      return true;
    case Compositing::KBuffer:
    case Compositing::Hybrid:
      return false;
  }
  return false;
}

}  // namespace mfr
