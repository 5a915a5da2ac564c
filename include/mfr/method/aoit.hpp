// Adaptive Transparency.
//   M. Salvi, J. Montgomery, A. Lefohn. "Adaptive Transparency". Proceedings of the ACM SIGGRAPH
//   Symposium on High Performance Graphics (HPG) 2011, pp. 119-126.
//
// Two geometry passes and a per-pixel compressed visibility function of N nodes (N = 4, 8, 16:
// aoit4, aoit8, aoit16), float32, method_math.h's aoitInsert / aoitVisibility / aoitAddColor /
// aoitComposite (the same functions in aoit_visibility.frag, aoit_color.frag, aoit_resolve.comp):
//   1. visibility: each fragment (depth z, alpha a) is inserted as a node (z, T) among the
//      depth-sorted nodes: T = T(the node before) (1 - a), and every node behind z is multiplied
//      by (1 - a). With N + 1 nodes the compression removes the node i in 1..N whose removal
//      changes the area under the visibility curve least, (d_i - d_{i-1}) (T_{i-1} - T_i): node
//      i - 1 takes T_i, i.e. the removed node's step moves forward to d_{i-1} (the paper's
//      compression; moving the step forward keeps the total transmittance and only ever
//      underestimates visibility). The candidates and the tie-break are mfr's choice, stated
//      here: the nearest node is never removed (its step has no node in front to move to); ties
//      go to the smallest i (strict <), so the rule is deterministic for a given node array.
//      Unused nodes sit at kAoitEmptyDepth with the running total transmittance, so node N - 1
//      always holds the pixel's total transmittance.
//   2. capture: each fragment's premultiplied colour is weighted by vis(z), the T of the farthest
//      node strictly in front of z (1 if none), and summed:  acc += vis(z) a c.
//   composite: acc + T_total * background, T_total = T of node N - 1 (the product of all 1 - a).
// Equal depths: a fragment at a node's depth is not attenuated by that node (vis looks strictly in
// front), so coincident fragments do not occlude each other (the A-buffer composites them in its
// node order instead); a fragment inserted at an existing depth goes in front of those nodes, and
// the zero-width step between them is the first the compression removes (area 0).
// Exactness: with at most N fragments in a pixel (distinct depths) nothing is removed and the
// image is the A-buffer's up to float rounding; with N + 1 the one removal happens after all
// N + 1 fragments are in, whatever their order; beyond that the removals depend on the arrival
// order (the CPU engine's tile-owned capture: primitive order; fragment-parallel and GL: any).
// Checked against the public AOIT sample code's insertion (the index past the nodes strictly in
// front, the nodes behind multiplied by 1 - a, empty nodes at a far depth). Not implemented: that
// code's variants (8-bit transmittance, compressing only the farther half of the nodes for
// N >= 8, the later single-pass "AOIT update" that keeps colour per node and always merges the two
// farthest nodes). Alpha-0 fragments are skipped in both passes (a node that absorbs nothing).
// Per-pixel storage: N nodes of (depth, T) (8 N B) and the colour sum (12 B): 44 B (aoit4), 76 B
// (aoit8), 140 B (aoit16), plus the lock word when the capture is fragment-parallel (and on GL).
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

using method_math::kAoitEmptyDepth;
using method_math::kAoitMaxNodes;

/// One node of the visibility function: depth and the transmittance just behind it.
struct AoitNode {
  float depth = kAoitEmptyDepth;
  float trans = 1.0f;
};

/// One pixel's buffers with N nodes: 8 N + 12 bytes.
template <int N>
struct AoitPixel {
  static_assert(N >= 2 && N <= kAoitMaxNodes);
  AoitNode nodes[N];
  float r = 0.0f, g = 0.0f, b = 0.0f;  // pass 2: sum vis a c

  void insert(float depth, float alpha) {
    if (alpha <= 0.0f) return;
    float d[kAoitMaxNodes + 1] = {};
    float t[kAoitMaxNodes + 1] = {};
    for (int i = 0; i < N; ++i) {
      d[i] = nodes[i].depth;
      t[i] = nodes[i].trans;
    }
    method_math::aoitInsert(N, d, t, depth, 1.0f - alpha);
    for (int i = 0; i < N; ++i) nodes[i] = {d[i], t[i]};
  }
  float visibility(float depth) const {
    float d[kAoitMaxNodes + 1] = {};
    float t[kAoitMaxNodes + 1] = {};
    for (int i = 0; i < N; ++i) {
      d[i] = nodes[i].depth;
      t[i] = nodes[i].trans;
    }
    return method_math::aoitVisibility(N, d, t, depth);
  }
  void addColor(float depth, uint32_t rgba) {
    const glm::vec4 c = unpackFragmentColor(rgba);
    // an additive node (alpha byte 0) adds its emission times vis(z) and no visibility node
    const float weight = (rgba >> 24) == kAdditiveAlphaByte ? 1.0f : c.a;
    if (weight <= 0.0f || rgba == 0u) return;  // the word 0: an additive node adding nothing
    method_math::aoitAddColor(r, g, b, glm::vec3(c), weight, visibility(depth));
  }
  /// nodes in use (depth below kAoitEmptyDepth)
  int used() const {
    int n = 0;
    for (const AoitNode& x : nodes) n += x.depth != kAoitEmptyDepth ? 1 : 0;
    return n;
  }
  glm::vec3 composite(glm::vec3 background) const {
    return method_math::aoitComposite(glm::vec3(r, g, b), nodes[N - 1].trans, background);
  }
};
static_assert(sizeof(AoitPixel<4>) == 44 && sizeof(AoitPixel<8>) == 76 &&
              sizeof(AoitPixel<16>) == 140);

/// The visibility pass, then the capture weighting each fragment by vis(z): every AOIT preset.
template <int N>
struct AoitPasses {
  using Slot = AoitPixel<N>;
  static constexpr int kNodeCount = N;
  static constexpr bool kNodes = false;
  static constexpr std::array<const char*, 1> kExtraPasses{"visibility"};
  /// Additive nodes add e vis(z) (no visibility node); multiply needs a per-channel visibility.
  static constexpr uint32_t kBlendModes = kEveryBlendMode & ~blendBit(BlendMode::Multiply);
  template <class PeerPixel>
  static void add(PeerPixel px, int pass, float depth, uint32_t rgba) {
    if (pass == 0) {
      // the same alpha as the capture's (unpackFragmentColor): x * (1 / 255)
      px.slots->insert(depth, static_cast<float>(rgba >> 24) * (1.0f / 255.0f));
      return;
    }
    px.slots->addColor(depth, rgba);
    ++px.count;
  }
  static glm::vec3 composite(const Slot* slots, uint32_t, glm::vec3 background) {
    return slots->composite(background);
  }
};

/// aoit4: 4 nodes, 44 bytes per pixel.
struct Aoit4Method : AoitPasses<4> {
  static constexpr Compositing kRule = Compositing::Adaptive4;
  static constexpr const char* kRuleName = "adaptive-4";
  static PresetInfo preset() {
    return {"aoit4", "adaptive transparency, 4 nodes (Salvi et al. 2011)",
            "visibility function of 4 (depth, transmittance) nodes per pixel, area-based removal"};
  }
};

/// aoit8: 8 nodes, 76 bytes per pixel.
struct Aoit8Method : AoitPasses<8> {
  static constexpr Compositing kRule = Compositing::Adaptive8;
  static constexpr const char* kRuleName = "adaptive-8";
  static PresetInfo preset() {
    return {"aoit8", "adaptive transparency, 8 nodes (Salvi et al. 2011)",
            "visibility function of 8 (depth, transmittance) nodes per pixel, area-based removal"};
  }
};

/// aoit16: 16 nodes, 140 bytes per pixel.
struct Aoit16Method : AoitPasses<16> {
  static constexpr Compositing kRule = Compositing::Adaptive16;
  static constexpr const char* kRuleName = "adaptive-16";
  static PresetInfo preset() {
    return {"aoit16", "adaptive transparency, 16 nodes (Salvi et al. 2011)",
            "visibility function of 16 (depth, transmittance) nodes per pixel, area-based removal"};
  }
};

/// The nodes an adaptive-transparency rule keeps: 4, 8, 16; 0 for any other rule. The GL
/// engine's one AOIT technique runs all three by this count.
inline int aoitNodeCount(Compositing c) {
  return c == Compositing::Adaptive4    ? 4
         : c == Compositing::Adaptive8  ? 8
         : c == Compositing::Adaptive16 ? 16
                                        : 0;
}

}  // namespace mfr
