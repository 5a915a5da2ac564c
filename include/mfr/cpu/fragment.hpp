// What the CPU rasterizer hands to a capture pass. The node the stores keep is in
// mfr/method/fragment_node.hpp (shared with the GL engine).
#pragma once

#include <cstdint>

#include "mfr/method/fragment_node.hpp"

namespace mfr {

/// One rasterized fragment (a triangle covering a pixel centre).
struct Fragment {
  uint32_t pixel;  // y * width + x, row 0 at the top
  float depth;     // window-space depth in [0, 1] (gl_FragCoord.z)
  uint32_t rgba;   // packFragmentColor(): sRGB8 colour, linear alpha8 (0 in coverage-only passes)
  float ndotv;     // signed cosine between the interpolated normal and the direction to the eye
  uint32_t prim;   // triangle index in the scene (clipped pieces keep their parent's index)
};

inline FragmentNode makeNode(const Fragment& f) {
  return makeNode(f.depth, f.rgba);
}

}  // namespace mfr
