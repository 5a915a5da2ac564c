// What a peer method may read of a fragment beyond its depth and colour word (peer_method.hpp). A
// peer whose type declares
//
//   add(px, pass, const PeerFragment& f)
//
// gets this instead of add(px, pass, depth, rgba) (the engine detects the overload with
// `requires`, so the other peers are untouched); one that also says kNeedsPosition = true gets
// the surface point and its pixel footprint filled in (they cost a reconstruction per fragment).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace mfr {

struct PeerFragment {
  uint32_t pixel = 0;  // y * width + x
  float depth = 0.0f;  // window-space depth in [0, 1]
  uint32_t rgba = 0;   // packFragmentColor's word
  uint32_t prim = 0;   // the scene triangle's index (clipped pieces keep their parent's)
  /// World-space point of the surface seen at the pixel centre, reconstructed from the pixel and
  /// the depth with the frame's camera (kNeedsPosition only; otherwise 0).
  glm::vec3 position{0.0f};
  /// World-space width of one pixel at `position` on a surface parallel to the image plane: the
  /// view depth times the pixel's width at unit depth (kNeedsPosition only; otherwise 0).
  float footprint = 0.0f;
};

}  // namespace mfr
