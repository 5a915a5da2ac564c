// Compositing rules of the resolve pass, on linear RGB.
//
// kbuffer: front-to-back "over" of the depth-sorted captured fragments, then the background:
//   C = sum_i c_i a_i T_i,  T_i = prod_{j<i} (1 - a_j),  final = C + T_n * background.
// Nodes of the other blend modes (core/blend_mode.hpp) take their own step (method_math.h
// blendStep): an additive node adds e_i T_i, a multiply node multiplies T per channel.
//
// hybrid (hybrid transparency, Maule et al. 2013, as used by DHOIT sec. 3.3): the sorted core as
// above gives C_core and 1 - alpha_core = T_k; the t = n - k fragments not kept (culled, rejected
// or evicted) were accumulated order-independently into sum(a_i c_i), sum(a_i) and t, so
//   C_tail = sum(a_i c_i) / sum(a_i),  a_avg = sum(a_i) / t,  alpha_tail = 1 - (1 - a_avg)^t
//   final = C_core + (1 - alpha_core) * (alpha_tail * C_tail + (1 - alpha_tail) * background).
// The tail colour is weighted by the tail's opacity alpha_tail (the public DHOIT shader forgets
// this factor). With an empty tail the result is bit-identical to the kbuffer rule. An additive
// node in the tail adds its emission to sum(a_i c_i) and nothing to sum(a_i): it is weighted as
// the tail's over fragments are (alpha_tail / sum(a_i)), and added unweighted when the tail has no
// alpha. Multiply nodes need a per-channel tail transmittance, which hybrid does not keep: the
// rule refuses multiply materials (method/blend_support.hpp).
// The steps are method_math.h's (overStep, hybridTailAdd, hybridBehind), which the GL engine's
// shaders run too.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/core/samples.hpp"
#include "mfr/method/fragment_node.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

/// Hybrid tail accumulators of one pixel: 20 bytes.
struct HybridTail {
  float r = 0.0f, g = 0.0f, b = 0.0f;  // sum of alpha * linear colour
  float alpha = 0.0f;                  // sum of alpha
  uint32_t count = 0;                  // t

  void add(uint32_t rgba) {
    const glm::vec4 c = unpackFragmentColor(rgba);
    method_math::hybridTailAddNode(r, g, b, alpha, count, rgba >> 24, c.a, c.r, c.g, c.b);
  }
  /// A node of per-pixel multisampled storage (core/samples.hpp) into the pixel's one tail: its
  /// alpha (an additive node: its emission) weighted by the share of the samples it covers.
  void addCovered(FragmentNode node, int samples) {
    const uint32_t rgba = nodeColor(node);
    const float share = static_cast<float>(std::popcount(coverageOf(nodeDepth(node), samples))) /
                        static_cast<float>(samples);
    const glm::vec4 c = unpackFragmentColor(rgba);
    method_math::hybridTailAddCovered(r, g, b, alpha, count, rgba >> 24, c.a, c.r, c.g, c.b, share);
  }
};
static_assert(sizeof(HybridTail) == 20);

/// Front-to-back composite of `n` sorted nodes of any blend kind (method_math.h blendStep);
/// returns the colour and leaves the per-channel transmittance in T.
inline glm::vec3 compositeCore(const FragmentNode* sorted, uint32_t n, glm::vec3& transmittance) {
  // scalar channels in registers (glm's vec3 kept the sums on the stack: a store-to-load in
  // every step of this dependency chain); the same operations, in the same order
  const ColorTables& t = ColorTables::get();
  float r = 0.0f, g = 0.0f, b = 0.0f, tr = 1.0f, tg = 1.0f, tb = 1.0f;
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t rgba = nodeColor(sorted[i]);
    const float a = static_cast<float>(rgba >> 24) * (1.0f / 255.0f);
    method_math::blendStep(r, g, b, tr, tg, tb, rgba >> 24, a, t.srgb8ToLinear[rgba & 0xffu],
                           t.srgb8ToLinear[(rgba >> 8) & 0xffu],
                           t.srgb8ToLinear[(rgba >> 16) & 0xffu]);
  }
  transmittance = glm::vec3(tr, tg, tb);
  return {r, g, b};
}

/// What lies behind the sorted core under the hybrid rule: the pixel's tail over the background.
inline glm::vec3 tailBehind(const HybridTail& tail, glm::vec3 background) {
  return method_math::hybridBehind(glm::vec3(tail.r, tail.g, tail.b), tail.alpha, tail.count,
                                   background);
}

/// A multisampled pixel of per-pixel storage (core/samples.hpp): each sample composited from the
/// sorted nodes whose coverage mask holds it over `behind` (the background, or the hybrid tail over
/// it), then the samples averaged (the box filter): method_math.h's SampleSums, which the GL
/// engine's resolve runs too.
inline glm::vec3 compositeSamples(const FragmentNode* sorted, uint32_t n, int samples,
                                  glm::vec3 behind) {
  const ColorTables& t = ColorTables::get();
  method_math::SampleSums sums = method_math::emptySampleSums(samples);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t rgba = nodeColor(sorted[i]);
    const float a = static_cast<float>(rgba >> 24) * (1.0f / 255.0f);
    method_math::blendSampleNode(sums, std::bit_cast<uint32_t>(nodeDepth(sorted[i])), rgba >> 24, a,
                                 t.srgb8ToLinear[rgba & 0xffu],
                                 t.srgb8ToLinear[(rgba >> 8) & 0xffu],
                                 t.srgb8ToLinear[(rgba >> 16) & 0xffu]);
  }
  return method_math::resolveSampleSums(sums, behind);
}

inline glm::vec3 compositeKBuffer(const FragmentNode* sorted, uint32_t n, glm::vec3 background) {
  glm::vec3 T;
  const glm::vec3 core = compositeCore(sorted, n, T);
  return method_math::overBackground(core, T, background);
}

inline glm::vec3 compositeHybrid(const FragmentNode* sorted, uint32_t n, const HybridTail& tail,
                                 glm::vec3 background) {
  glm::vec3 T;
  const glm::vec3 core = compositeCore(sorted, n, T);
  return method_math::overBackground(core, T, tailBehind(tail, background));
}

}  // namespace mfr
