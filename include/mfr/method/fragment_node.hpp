// The 8-byte fragment node every store of both engines keeps (the CPU engine's stores, the GL
// engine's node buffers): float32 depth in the high word, the RGBA8 colour in the low word.
#pragma once

#include <bit>
#include <cstdint>

namespace mfr {

/// Depths are non-negative, so the unsigned 64-bit order of the node is the order (depth, colour):
/// equal depths are broken by the colour word, deterministically and independently of arrival
/// order (primitive ids are not stored in the 8-byte node; two fragments with equal depth and equal
/// colour are interchangeable, so any order of them gives identical images).
using FragmentNode = uint64_t;

inline FragmentNode makeNode(float depth, uint32_t rgba) {
  return (static_cast<uint64_t>(std::bit_cast<uint32_t>(depth)) << 32) | rgba;
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
