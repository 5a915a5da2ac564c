// Multi-Layer Alpha Blending.
//   M. Salvi, K. Vaidyanathan. "Multi-layer Alpha Blending". Proceedings of the ACM SIGGRAPH
//   Symposium on Interactive 3D Graphics and Games (I3D) 2014, pp. 151-158.
//
// k nodes per pixel, each (depth, premultiplied colour, transmittance), kept sorted front to back.
// A fragment (z, a, c) becomes the node (z, a c, 1 - a) and is inserted in depth order (after
// nodes of equal depth); when that makes k + 1 nodes, the two farthest are merged by "over":
//   merged.rgb = near.rgb + near.T * far.rgb,  merged.T = near.T * far.T,  merged.z = near.z.
// (method_math.h's mlabMergeBehind, shared with shaders/mlab.frag)
// The resolve composites the nodes front to back over the background:
//   C = sum_i rgb_i prod_{j<i} T_j + prod_j T_j * background.
// Nothing is merged while a pixel has at most k fragments, so MLAB with k >= n(p) is the A-buffer
// (up to float rounding: a c T vs. c (a T)). The merge depends on arrival order; tile-owned
// capture delivers a pixel's fragments in primitive order, so the result does not depend on the
// thread count. The paper packs a node into 8 bytes (RGBA8 colour + transmittance, float depth);
// mfr keeps float32 (20 bytes: depth, r, g, b, T) and charges those 20 bytes per node.
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

struct MlabNode {
  float depth = 0.0f;
  float r = 0.0f, g = 0.0f, b = 0.0f;  // premultiplied linear colour
  float transmittance = 1.0f;

  static MlabNode fromFragment(float depth, glm::vec4 c) {
    const glm::vec3 premultiplied = method_math::mlabPremultiplied(glm::vec3(c), c.a);
    return {depth, premultiplied.r, premultiplied.g, premultiplied.b,
            method_math::mlabTransmittance(c.a)};
  }
  static MlabNode fromFragment(float depth, uint32_t rgba) {
    return fromFragment(depth, unpackFragmentColor(rgba));
  }
  /// `far` composited behind this node.
  void mergeBehind(const MlabNode& far) {
    method_math::mlabMergeBehind(r, g, b, transmittance, glm::vec3(far.r, far.g, far.b),
                                 far.transmittance);
  }
};
static_assert(sizeof(MlabNode) == 20);
inline constexpr uint64_t kMlabNodeBytes = sizeof(MlabNode);

/// Inserts `f` into the sorted `nodes` (count of capacity k >= 1); returns true when the two
/// farthest were merged (the store was full).
inline bool mlabInsert(MlabNode* nodes, uint32_t& count, uint32_t k, const MlabNode& f) {
  uint32_t pos = count;
  while (pos > 0 && nodes[pos - 1].depth > f.depth) --pos;
  if (count < k) {
    for (uint32_t i = count; i > pos; --i) nodes[i] = nodes[i - 1];
    nodes[pos] = f;
    ++count;
    return false;
  }
  if (pos == k) {  // behind every node: merged into the last one
    nodes[k - 1].mergeBehind(f);
    return true;
  }
  const MlabNode last = nodes[k - 1];
  for (uint32_t i = k - 1; i > pos; --i) nodes[i] = nodes[i - 1];
  nodes[pos] = f;
  nodes[k - 1].mergeBehind(last);
  return true;
}

/// Front-to-back over of the sorted nodes and the background.
inline glm::vec3 compositeMlab(const MlabNode* nodes, uint32_t count, glm::vec3 background) {
  glm::vec3 color(0.0f);
  float T = 1.0f;
  for (uint32_t i = 0; i < count; ++i)
    method_math::mlabCompositeStep(color, T, glm::vec3(nodes[i].r, nodes[i].g, nodes[i].b),
                                   nodes[i].transmittance);
  return method_math::overBackground(color, T, background);
}

/// mlab as a peer method (peer_method.hpp): k(p) blended nodes of 20 bytes at the fixed-k
/// allocation's offsets; the count is the nodes in use.
struct MlabMethod {
  static constexpr Compositing kRule = Compositing::MultiLayerAlpha;
  static constexpr const char* kRuleName = "multi-layer-alpha";
  static PresetInfo preset() {
    return {"mlab", "multi-layer alpha blending (Salvi & Vaidyanathan 2014)",
            "k depth-ordered layers per pixel, the two farthest merged when full"};
  }
  using Slot = MlabNode;
  static constexpr bool kNodes = true;
  static constexpr std::array<const char*, 0> kExtraPasses{};
  template <class Pixel>
  static void add(Pixel px, int /*pass*/, float depth, uint32_t rgba) {
    (void)mlabInsert(px.slots, px.count, px.capacity, MlabNode::fromFragment(depth, rgba));
  }
  static glm::vec3 composite(const MlabNode* nodes, uint32_t count, glm::vec3 background) {
    return compositeMlab(nodes, count, background);
  }
};

}  // namespace mfr
