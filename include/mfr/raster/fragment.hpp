// What the rasterizer hands to a capture pass, and the 8-byte node every fragment store keeps.
#pragma once

#include <bit>
#include <cstdint>

namespace mfr {

/// One rasterized fragment (a triangle covering a pixel centre).
struct Fragment {
  uint32_t pixel;  // y * width + x, row 0 at the top
  float depth;     // window-space depth in [0, 1] (gl_FragCoord.z)
  uint32_t rgba;   // packFragmentColor(): sRGB8 colour, linear alpha8 (0 in coverage-only passes)
  float ndotv;     // signed cosine between the interpolated normal and the direction to the eye
  uint32_t prim;   // triangle index in the scene (clipped pieces keep their parent's index)
};

/// The fragment node of every store: 8 bytes, float32 depth in the high word and the RGBA8 colour
/// in the low word. Depths are non-negative, so the unsigned 64-bit order of the node is the order
/// (depth, colour): equal depths are broken by the colour word, deterministically and independently
/// of arrival order (primitive ids are not stored in the 8-byte node; two fragments with equal
/// depth and equal colour are interchangeable, so any order of them gives identical images).
using FragmentNode = uint64_t;

inline FragmentNode makeNode(float depth, uint32_t rgba) {
  return (static_cast<uint64_t>(std::bit_cast<uint32_t>(depth)) << 32) | rgba;
}
inline FragmentNode makeNode(const Fragment& f) {
  return makeNode(f.depth, f.rgba);
}
inline float nodeDepth(FragmentNode node) {
  return std::bit_cast<float>(static_cast<uint32_t>(node >> 32));
}
inline uint32_t nodeColor(FragmentNode node) {
  return static_cast<uint32_t>(node);
}

/// The "empty" node: farther than any real fragment (depth bits of +inf).
inline constexpr FragmentNode kFarNode = 0x7f800000ull << 32;

}  // namespace mfr
