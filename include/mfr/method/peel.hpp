// Depth peeling and dual depth peeling.
//   C. Everitt. "Interactive Order-Independent Transparency". NVIDIA technical report, 2001.
//   L. Bavoil, K. Myers. "Order Independent Transparency with Dual Depth Peeling". NVIDIA
//   technical report, 2008.
//
// Exact order-independent transparency in constant memory per pixel: every geometry pass renders
// the whole scene and keeps, per pixel, the nearest fragment behind the layers peeled so far (peel)
// or the nearest and the farthest of the fragments not yet peeled (dual-peel); between passes a
// per-pixel step blends the layer found into the pixel's colour and advances the bounds. Time grows
// with the depth complexity: peel needs L passes, dual-peel ceil(L / 2), for L distinct layers.
//
// The order is mfr's total order of fragments, the 64-bit key (depth bits, colour word) of
// fragment_node.hpp, so equal depths are peeled in a fixed order. Fragments equal in both depth
// and colour are one key: each pass counts the key's multiplicity m, and the step composites that
// layer m times. Peeling every layer then makes the same "over" steps, in the same order, as the
// A-buffer's resolve (compositing.hpp): peel's image is the A-buffer's, bit for bit; dual-peel
// blends its back layers back to front ("under") and combines the two sides at the end, which
// equals the A-buffer's image within float rounding.
//
// Per pixel (uint32 words, float32 colour; the same words on the GL engine, shared_layout.h):
//   peel       bound (2 words: the next layer's key is >= bound, 0 at first), candidate key
//              (2 words, all ones: none), multiplicity, front colour r g b and transmittance T:
//              9 words, 36 B
//   dual-peel  lo (2: keys >= lo remain), hi (2: keys < hi remain), nearest and farthest
//              candidate keys (2 + 2), their multiplicities (1 + 1), front r g b T, back r g b T:
//              18 words, 72 B
// --max-peels P bounds the geometry passes (dual-peel: P passes peel up to 2P layers, P from the
// front and P from the back); the fragments still in range after them are dropped (lost), or with
// --composite hybrid blended into the hybrid tail (one more geometry pass; 20 B per pixel), which
// lies behind the front layers (and, for dual-peel, in front of the back layers).
//
// Passes: without --max-peels, peel runs until a pass peels every fragment still in range (a
// frame-wide count of the fragments in range against those peeled, so no empty pass is needed):
// max over pixels of the distinct keys, L, passes; dual-peel ceil(L / 2).
#pragma once

#include <array>
#include <bit>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/compositing.hpp"
#include "mfr/method/fragment_node.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

/// The largest --max-peels (a bound on the geometry passes of one frame).
inline constexpr int64_t kMaxPeels = 65536;

inline constexpr uint64_t kNoPeelKey = ~uint64_t{0};  // no candidate (above every real key)

/// A 64-bit key kept as two words (depth bits first, like the GL engine's nodes).
struct PeelKey {
  uint32_t hi = 0, lo = 0;
  uint64_t get() const { return (uint64_t{hi} << 32) | lo; }
  void set(uint64_t k) {
    hi = static_cast<uint32_t>(k >> 32);
    lo = static_cast<uint32_t>(k);
  }
};

/// One layer of multiplicity m composited front to back onto (r, g, b, T): m steps of its kind
/// (over or additive, method_math.h blendStepScalar), the A-buffer resolve's operations for m
/// equal fragments.
inline void peelOverLayer(float& r, float& g, float& b, float& T, FragmentNode key, uint32_t m) {
  const uint32_t rgba = nodeColor(key);
  const ColorTables& t = ColorTables::get();
  const float a = static_cast<float>(rgba >> 24) * (1.0f / 255.0f);
  for (uint32_t i = 0; i < m; ++i)
    method_math::blendStepScalar(r, g, b, T, rgba >> 24, a, t.srgb8ToLinear[rgba & 0xffu],
                                 t.srgb8ToLinear[(rgba >> 8) & 0xffu],
                                 t.srgb8ToLinear[(rgba >> 16) & 0xffu]);
}

/// One layer of multiplicity m blended back to front in front of the back colour (r, g, b, T).
inline void peelUnderLayer(float& r, float& g, float& b, float& T, FragmentNode key, uint32_t m) {
  const uint32_t rgba = nodeColor(key);
  const ColorTables& t = ColorTables::get();
  const float a = static_cast<float>(rgba >> 24) * (1.0f / 255.0f);
  for (uint32_t i = 0; i < m; ++i)
    method_math::blendUnderStepScalar(r, g, b, T, rgba >> 24, a, t.srgb8ToLinear[rgba & 0xffu],
                                      t.srgb8ToLinear[(rgba >> 8) & 0xffu],
                                      t.srgb8ToLinear[(rgba >> 16) & 0xffu]);
}

/// Depth peeling's pixel: 36 bytes.
struct PeelPixel {
  PeelKey bound;                       // keys >= bound are not peeled yet
  PeelKey candidate{~0u, ~0u};         // this pass's nearest key >= bound (none: all ones)
  uint32_t multiplicity = 0;           // fragments with that key in this pass
  float r = 0.0f, g = 0.0f, b = 0.0f;  // front colour, premultiplied
  float T = 1.0f;                      // front transmittance

  bool remains(FragmentNode key) const { return key >= bound.get(); }
  /// Whether a fragment of this depth may still be to peel (the early test before shading).
  bool mayRemain(float depth) const { return std::bit_cast<uint32_t>(depth) >= bound.hi; }
  /// One fragment of a pass: true when it is still to peel.
  bool add(FragmentNode key) {
    if (!remains(key)) return false;
    const uint64_t c = candidate.get();
    if (key < c) {
      candidate.set(key);
      multiplicity = 1;
    } else if (key == c) {
      ++multiplicity;
    }
    return true;
  }
  /// After a pass: the layer found blended, the bound advanced; the fragments peeled.
  uint32_t endPass() {
    const uint64_t c = candidate.get();
    if (c == kNoPeelKey) return 0;
    peelOverLayer(r, g, b, T, c, multiplicity);
    bound.set(c + 1);
    const uint32_t m = multiplicity;
    candidate.set(kNoPeelKey);
    multiplicity = 0;
    return m;
  }
  glm::vec3 composite(const HybridTail* tail, glm::vec3 background) const {
    const glm::vec3 behind = tail ? method_math::hybridBehind(glm::vec3(tail->r, tail->g, tail->b),
                                                              tail->alpha, tail->count, background)
                                  : background;
    return method_math::overBackground(glm::vec3(r, g, b), T, behind);
  }
};
static_assert(sizeof(PeelPixel) == 36);

/// Dual depth peeling's pixel: 72 bytes.
struct DualPeelPixel {
  PeelKey lo;                 // keys >= lo ...
  PeelKey hi{~0u, ~0u};       // ... and < hi are not peeled yet
  PeelKey nearest{~0u, ~0u};  // this pass's smallest key in range (none: ones)
  PeelKey farthest;           // its largest key in range (valid with nearest)
  uint32_t nearMultiplicity = 0, farMultiplicity = 0;
  float fr = 0.0f, fg = 0.0f, fb = 0.0f, fT = 1.0f;  // front layers, front to back
  float br = 0.0f, bg = 0.0f, bb = 0.0f, bT = 1.0f;  // back layers, back to front

  bool remains(FragmentNode key) const { return key >= lo.get() && key < hi.get(); }
  bool mayRemain(float depth) const {
    const uint32_t bits = std::bit_cast<uint32_t>(depth);
    return bits >= lo.hi && bits <= hi.hi;
  }
  bool add(FragmentNode key) {
    if (!remains(key)) return false;
    const uint64_t n = nearest.get();
    if (key < n) {
      nearest.set(key);
      nearMultiplicity = 1;
    } else if (key == n) {
      ++nearMultiplicity;
    }
    const uint64_t f = farthest.get();
    if (n == kNoPeelKey || key > f) {
      farthest.set(key);
      farMultiplicity = 1;
    } else if (key == f) {
      ++farMultiplicity;
    }
    return true;
  }
  uint32_t endPass() {
    const uint64_t n = nearest.get(), f = farthest.get();
    if (n == kNoPeelKey) return 0;
    uint32_t peeled = nearMultiplicity;
    peelOverLayer(fr, fg, fb, fT, n, nearMultiplicity);
    if (f != n) {  // both sides met on one layer: composited once, from the front
      peelUnderLayer(br, bg, bb, bT, f, farMultiplicity);
      peeled += farMultiplicity;
    }
    lo.set(n + 1);
    hi.set(f);  // (n == f: lo > hi, nothing remains)
    nearest.set(kNoPeelKey);
    farthest.set(0);
    nearMultiplicity = farMultiplicity = 0;
    return peeled;
  }
  glm::vec3 composite(const HybridTail* tail, glm::vec3 background) const {
    glm::vec3 behind = method_math::overBackground(glm::vec3(br, bg, bb), bT, background);
    if (tail)
      behind = method_math::hybridBehind(glm::vec3(tail->r, tail->g, tail->b), tail->alpha,
                                         tail->count, behind);
    return method_math::overBackground(glm::vec3(fr, fg, fb), fT, behind);
  }
};
static_assert(sizeof(DualPeelPixel) == 72);

/// What peel and dual-peel share as peer methods (peer_method.hpp): no extra passes, a repeated
/// capture (kRepeatsCapture) of add / endPass, and the composite with the optional hybrid tail.
template <class Pixel>
struct PeelPasses {
  using Slot = Pixel;
  static constexpr bool kNodes = false;
  static constexpr bool kRepeatsCapture = true;
  static constexpr std::array<const char*, 0> kExtraPasses{};
  /// Over and additive layers (blendStepScalar); multiply needs a per-channel T in the pixel.
  static constexpr uint32_t kBlendModes = kEveryBlendMode & ~blendBit(BlendMode::Multiply);
  /// A fragment of a peel pass; true when it is still to peel (counted frame-wide).
  template <class PeerPixel>
  static bool add(PeerPixel px, int /*pass*/, float depth, uint32_t rgba) {
    return px.slots->add(makeNode(depth, rgba));
  }
  /// The per-pixel step after a pass: the fragments it peeled (added to the pixel's count).
  static uint32_t endPass(Pixel* slot) { return slot->endPass(); }
  static bool mayRemain(const Pixel* slot, float depth) { return slot->mayRemain(depth); }
  static bool remains(const Pixel* slot, float depth, uint32_t rgba) {
    return slot->remains(makeNode(depth, rgba));
  }
  static glm::vec3 composite(const Pixel* slot, uint32_t, glm::vec3 background) {
    return slot->composite(nullptr, background);
  }
  static glm::vec3 composite(const Pixel* slot, const HybridTail* tail, glm::vec3 background) {
    return slot->composite(tail, background);
  }
};

/// peel as a peer method: one nearest layer per pass, 36 bytes per pixel.
struct PeelMethod : PeelPasses<PeelPixel> {
  static constexpr Compositing kRule = Compositing::Peel;
  static constexpr const char* kRuleName = "depth-peeling";
  static PresetInfo preset() {
    return {"peel", "depth peeling (Everitt 2001)",
            "one layer per geometry pass, exact; --max-peels P bounds the passes"};
  }
};

/// dual-peel as a peer method: the nearest and the farthest layer per pass, 72 bytes per pixel.
struct DualPeelMethod : PeelPasses<DualPeelPixel> {
  static constexpr Compositing kRule = Compositing::DualPeel;
  static constexpr const char* kRuleName = "dual-depth-peeling";
  static PresetInfo preset() {
    return {"dual-peel", "dual depth peeling (Bavoil & Myers 2008)",
            "front and back layer per geometry pass, exact; --max-peels P: 2P layers"};
  }
};

/// True for the depth-peeling rules (peel, dual-peel).
inline bool peelingRule(Compositing c) {
  return c == Compositing::Peel || c == Compositing::DualPeel;
}

}  // namespace mfr
