// Hashed alpha testing.
//   C. Wyman, M. McGuire. "Hashed Alpha Testing". Proceedings of the ACM SIGGRAPH Symposium on
//   Interactive 3D Graphics and Games (I3D) 2017, article 7; extended as "Improved Alpha Testing
//   Using Hashed Sampling", IEEE Transactions on Visualization and Computer Graphics 25(2), 2019.
//
// One geometry pass into a z-buffer (preset hashed-alpha): a fragment of alpha a = alpha8 / 255 is
// kept, as an opaque surface, when a >= h, h in (0, 1] a hash of the surface point that is stable
// under camera motion; per pixel the nearest kept fragment's colour, alpha forced to 1; no kept
// fragment: the background. Each fragment is kept with probability a independently of the others,
// so the nearest kept one is fragment i with probability a_i prod_{j in front} (1 - a_j): the
// expected colour is the exact front-to-back composite. Its noise is the point: one frame is a
// dithered sample of it, and the pattern stays on the surface as the camera moves.
//
// The threshold (the paper's isotropic hashed alpha, its Listing 3), hashedAlphaThreshold:
//   footprint w = the world-space size of one pixel at the point, pixScale = 1 / (kScale w)
//   L = log2(pixScale); the point is quantised at the two neighbouring powers of two,
//   x0 = hash(prim, floor(2^floor(L) p)), x1 = hash(prim, floor(2^ceil(L) p)),  uniform in [0, 1),
//   x = (1 - f) x0 + f x1, f = fract(L), and x is mapped through the CDF of that blend of two
//   uniforms (a = min(f, 1 - f)):
//     x < a:          x^2 / (2 a (1 - a))
//     x < 1 - a:      (x - a / 2) / (1 - a)
//     otherwise:      1 - (1 - x)^2 / (2 a (1 - a))
//   so h is uniform again; h is clamped to [1e-6, 1] (alpha 0 never kept, alpha 1 always).
//   The cells are about one pixel wide (kScale = 1, the paper's default hash scale) and their
//   scale moves continuously with the distance: the pattern neither swims when the camera moves
//   nor flickers when it zooms.
// What is hashed, mfr's choice: mfr's fragment carries no object-space position, so the point p
// is the world-space position of the surface seen at the pixel centre, reconstructed from the
// pixel, the depth and the frame's camera (PeerFragment::position). For mfr's static scenes world
// space is object space up to a fixed transform, so the decision at a surface point does not
// change when the camera moves (tested: a lateral move by whole pixels keeps the decisions). The
// primitive id is hashed with the cell (the paper hashes the cell only) so that two surfaces
// within one cell (stacked layers, a thin shell's two sides) get independent thresholds; a shared
// threshold would keep or drop them together and bias the expectation. The price: a scene whose
// triangles are renumbered (a shuffled draw order) gets another dither pattern, with the same
// expectation; the draw order itself does not matter (a z-buffer). The footprint is the
// screen-parallel one, view depth times the pixel's width at unit depth (the paper takes the
// larger screen-space derivative of p, which grows on slanted surfaces): on a slanted surface
// the cells are finer than its pixel footprint along the slant, the noise there less coherent
// from frame to frame; the expectation is unchanged. The hash is fragment_hash.hpp's integer PCG
// over the cell's integer coordinates (the paper's is a float sine hash).
// Ties: at equal depths the smaller colour word wins, so the image does not depend on the arrival
// order. Storage: the nearest kept depth (f32) and colour word: 8 bytes per pixel.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/fragment_hash.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/peer_fragment.hpp"

namespace mfr {

// The threshold's maths are method_math.h's, which the GL engine's shaders share.
using method_math::hashedAlphaCell;
using method_math::hashedAlphaThreshold;
using method_math::kHashedAlphaMinThreshold;
using method_math::kHashedAlphaScale;
/// The depth of a pixel no kept fragment reached.
inline constexpr float kHashedAlphaFarDepth = method_math::kStochasticFarDepth;

/// Whether a fragment of alpha `alpha8` (0..255) at that point is kept.
inline bool hashedAlphaKeeps(uint32_t alpha8, uint32_t prim, glm::vec3 p, float footprint) {
  // the same alpha as the capture's (unpackFragmentColor): x * (1 / 255)
  return method_math::hashedAlphaKeeps(static_cast<float>(alpha8) * (1.0f / 255.0f), prim, p,
                                       footprint);
}

/// One pixel's z-buffer: 8 bytes.
struct HashedAlphaPixel {
  float depth = kHashedAlphaFarDepth;
  uint32_t rgba = 0u;  // the nearest kept fragment's colour word

  void keep(float z, uint32_t word) {
    if (z < depth || (z == depth && word < rgba)) {
      depth = z;
      rgba = word;
    }
  }
  glm::vec3 composite(glm::vec3 background) const {
    if (depth == kHashedAlphaFarDepth) return background;
    return glm::vec3(unpackFragmentColor(rgba));
  }
};
static_assert(sizeof(HashedAlphaPixel) == 8);

/// hashed-alpha as a peer method (peer_method.hpp): one pass into an 8-byte z-buffer per pixel.
/// Its count is the fragments tested, like the accumulating peers' (none is lost to memory: the
/// ones the test drops are the method's sampling, not an overflow).
struct HashedAlphaMethod {
  static constexpr Compositing kRule = Compositing::HashedAlpha;
  static constexpr const char* kRuleName = "hashed-alpha";
  static PresetInfo preset() {
    return {"hashed-alpha", "hashed alpha testing (Wyman & McGuire 2017)",
            "z-buffer of fragments kept when alpha >= a stable hash of the surface point, noisy"};
  }
  using Slot = HashedAlphaPixel;
  static constexpr bool kNodes = false;
  static constexpr bool kNeedsPosition = true;
  static constexpr std::array<const char*, 0> kExtraPasses{};
  template <class PeerPixel>
  static void add(PeerPixel px, int /*pass*/, const PeerFragment& f) {
    ++px.count;
    if (hashedAlphaKeeps(f.rgba >> 24, f.prim, f.position, f.footprint))
      px.slots->keep(f.depth, f.rgba);
  }
  static glm::vec3 composite(const HashedAlphaPixel* slots, uint32_t, glm::vec3 background) {
    return slots->composite(background);
  }
};

}  // namespace mfr
