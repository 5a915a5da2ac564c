// The peer methods as types: the transparency methods engines ship instead of k-buffers, each
// described by one type in its own header beside its per-pixel state and rules (wboit.hpp,
// mboit.hpp, mlab.hpp, aoit.hpp, dfaoit.hpp, stochastic.hpp, hashed_alpha.hpp). A peer type says
//
//   kRule          the Compositing value that names it, kRuleName its name (toString)
//   preset()       its row of the preset table (name, paper, summary)
//   Slot           its per-pixel state (an accumulator), or one node of its per-pixel nodes
//   kNodes         false: one Slot per pixel; true: k(p) Slots at the fixed-k allocation's offsets
//   kExtraPasses   its geometry passes before the capture, by name (mboit: "moments", aoit:
//                  "visibility")
//   add(px, pass, depth, rgba)   one fragment in pass `pass` (0..extra-1, then the capture's);
//                or add(px, pass, const PeerFragment&) for a peer that needs more of the fragment
//                (its pixel, primitive id; with kNeedsPosition its surface point:
//                peer_fragment.hpp)
//   composite(slots, count, bg)  the pixel's colour over the background
//
// A peer whose capture is repeated a number of times decided at run time (depth peeling,
// peel.hpp) also says
//
//   kRepeatsCapture      true: the engine runs the capture pass again and again; add() returns
//                        whether the fragment is still to process (counted over the frame)
//   endPass(slot)        the per-pixel step after each pass (blend the layer found, advance);
//                        returns the fragments it took, added to the pixel's count
//   mayRemain(slot, z)   the early test before shading: false when the depth alone puts the
//                        fragment outside what is still to process
//   remains(slot, z, c)  after the last pass: the fragment was not taken (to the hybrid tail)
//   composite(slot, tail, bg)  the colour with the pixel's hybrid tail (null: none)
//
// and the engine stops after the pass that took every fragment still to process, or after
// MethodDesc::maxPeels passes; then, under MethodDesc::peelTail, one more pass adds the fragments
// that remain to the pixel's hybrid tail (peerRepeatsCapture below tells the two kinds apart).
//
// and the memory model, the pass plan and the CPU engine's one template (src/cpu/peer_methods.cpp)
// read everything else from it. visitPeer is the one switch from a rule to its type.
//
// A new peer method: its header (state, rules, type with its preset's name, paper and summary), a
// Compositing value (method.hpp) and its type in PeerMethods below; on the GL engine its shaders
// and their dispatch (src/gl/gl_engine.cpp).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/method/aoit.hpp"
#include "mfr/method/dfaoit.hpp"
#include "mfr/method/hashed_alpha.hpp"
#include "mfr/method/mboit.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/mlab.hpp"
#include "mfr/method/peel.hpp"
#include "mfr/method/peer_fragment.hpp"
#include "mfr/method/stochastic.hpp"
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

/// Every peer method, in the preset table's order. A new peer method is one more type here.
template <class... Peers>
struct PeerList {
  template <class F>
  static void forEach(F&& f) {
    (f.template operator()<Peers>(), ...);
  }
};
using PeerMethods = PeerList<WboitMethod, MboitMethod, Mboit6Method, Mboit8Method, MboitTrig3Method,
                             MboitTrig4Method, Mboit16Method, Mboit6_16Method, Mboit8_16Method,
                             MboitTrig3_16Method, MboitTrig4_16Method, MlabMethod, Aoit4Method,
                             Aoit8Method, Aoit16Method, PeelMethod, DualPeelMethod, DfaoitMethod,
                             Stochastic8Method, StochasticStrat8Method, HashedAlphaMethod>;

/// The blend modes a peer composites (core/blend_mode.hpp), as blendBit masks: its kBlendModes,
/// else over and premultiplied (a premultiplied fragment reaches the rule as an over fragment of
/// straight colour; its emission at alpha 0 is an additive node, which a rule weighting by alpha
/// ignores, as its paper's premultiplied form does).
template <class Peer>
constexpr uint32_t peerBlendModes() {
  if constexpr (requires { Peer::kBlendModes; })
    return Peer::kBlendModes;
  else
    return blendBit(BlendMode::Over) | blendBit(BlendMode::Premultiplied);
}

/// Whether a peer's add() takes the whole fragment (peer_fragment.hpp: its primitive id, and its
/// surface point under kNeedsPosition) instead of its depth and colour word.
template <class Peer>
constexpr bool peerTakesFragment() {
  return requires(PeerPixel<typename Peer::Slot> px, const PeerFragment& f) {
    Peer::add(px, 0, f);
  };
}

/// Whether a peer reads PeerFragment::position and footprint; false when it does not say.
template <class Peer>
constexpr bool peerNeedsPosition() {
  if constexpr (requires { Peer::kNeedsPosition; })
    return Peer::kNeedsPosition;
  else
    return false;
}

/// Whether a peer's capture repeats (depth peeling's kRepeatsCapture); false when it does not say.
template <class Peer>
constexpr bool peerRepeatsCapture() {
  if constexpr (requires { Peer::kRepeatsCapture; })
    return Peer::kRepeatsCapture;
  else
    return false;
}

/// Calls `f.template operator()<Peer>()` with the peer type of `rule`; false (and no call) for
/// the k-buffer family's rules.
template <class F>
bool visitPeer(Compositing rule, F&& f) {
  bool found = false;
  PeerMethods::forEach([&]<class Peer>() {
    if (!found && Peer::kRule == rule) {
      found = true;
      f.template operator()<Peer>();
    }
  });
  return found;
}

/// The preset of a peer method: its own allocation and store (no nodes for an accumulator; fixed
/// k, the multi-layer store and the k+ family's lock word for nodes) and its rule.
template <class Peer>
void configurePeerPreset(MethodDesc& m) {
  if constexpr (Peer::kNodes) {
    m.allocation = AllocationPolicy::FixedK;  // k nodes per pixel from the budget, like fkb
    m.store = StoreChoice::MultiLayer;
    m.perPixelLock = true;
  } else {
    m.allocation = AllocationPolicy::NoNodes;
    m.store = StoreChoice::None;
  }
  m.compositing = Peer::kRule;
}

}  // namespace mfr
