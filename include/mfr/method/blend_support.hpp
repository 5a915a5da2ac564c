// Which blend modes (core/blend_mode.hpp) a method composites, and the one check both engines run
// before a render. How the modes travel: core/color.hpp packBlendedColor (the node word's alpha
// byte says its kind) and method_math.h blendStep.
//
//   the k-buffer family, the A-buffer, linked lists (sorted nodes, compositeCore / resolve.comp):
//     every mode under --composite kbuffer, exactly (over, additive and multiply nodes each take
//     their own step in depth order); under --composite hybrid every mode but multiply (the tail
//     keeps one transmittance; an additive node in the tail is weighted like the tail's over
//     fragments)
//   the peer methods: their kBlendModes (peer_method.hpp peerBlendModes): depth peeling and AOIT
//     over, premultiplied and additive; the accumulators weighting each fragment by its alpha
//     (wboit, the mboit family, mlab) over and premultiplied
// A method given a scene with a mode it cannot represent fails with one line naming the method,
// the mode and what to use instead.
#pragma once

#include <cstdint>
#include <string>

#include "mfr/core/blend_mode.hpp"
#include "mfr/core/result.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/peer_method.hpp"

namespace mfr {

/// The blend modes `method` composites, as blendBit masks.
inline uint32_t blendModesOf(const MethodDesc& method) {
  uint32_t modes = 0;
  const bool peer = visitPeer(method.compositing, [&]<class Peer>() {
    modes = peerBlendModes<Peer>();
    if (method.peelTail) modes &= ~blendBit(BlendMode::Multiply);
  });
  if (peer) return modes;
  if (method.compositing == Compositing::Hybrid)
    return kEveryBlendMode & ~blendBit(BlendMode::Multiply);
  return kEveryBlendMode;
}

/// Error unless `method` composites every mode of `sceneModes` (Scene::blendModes).
inline Result<void> checkBlendSupport(const MethodDesc& method, uint32_t sceneModes) {
  const uint32_t missing = sceneModes & ~blendModesOf(method);
  if (missing == 0) return {};
  for (BlendMode mode : kBlendModes) {
    if ((missing & blendBit(mode)) == 0) continue;
    const bool hybridMultiply = mode == BlendMode::Multiply &&
                                (method.compositing == Compositing::Hybrid || method.peelTail);
    return makeError(
        method.name + ": the scene has " + toString(mode) + " materials, which " + method.name +
        (hybridMultiply ? "'s hybrid tail cannot represent (one transmittance, no colour): use "
                          "--composite kbuffer"
                        : std::string(" cannot represent: use ") +
                              (mode == BlendMode::Multiply
                                   ? "a k-buffer method with --composite kbuffer, linked-list or "
                                     "abuffer"
                                   : "a k-buffer method, linked-list, abuffer, peel or aoit") +
                              " (docs/METHODS.md, blend modes)"));
  }
  return {};
}

}  // namespace mfr
