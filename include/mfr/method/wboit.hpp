// Weighted Blended Order-Independent Transparency.
//   M. McGuire, L. Bavoil. "Weighted Blended Order-Independent Transparency". Journal of Computer
//   Graphics Techniques (JCGT) 2(2), 2013, pp. 122-141.
//
// One accumulation pass, no fragment nodes. Per pixel (20 bytes, float32; the paper's targets are
// RGBA16F + R8, mfr keeps float32 and charges what it stores):
//   accum.rgb += C_i * w(z_i, a_i)       C_i = a_i c_i, the premultiplied linear colour
//   accum.a   += a_i * w(z_i, a_i)
//   revealage *= (1 - a_i)
// and the composite (the paper's Eq. 6 with its resolve-shader clamp of the denominator):
//   final = accum.rgb / clamp(accum.a, 1e-4, 5e4) * (1 - revealage) + revealage * background.
// The depth weight is the paper's Eq. 10, the one written for window-space depth d = gl_FragCoord.z
// (the fragments' depth here), with its lower clamp:
//   w(z, a) = a * max(1e-2, 3e3 * (1 - d)^3)          (the upper clamp 3e3 is implied: d >= 0)
// Sums are accumulated in the order fragments reach the pixel: primitive order in tile-owned
// capture (the same for any thread count); in another submission order the float sums may differ
// in the last bits (relative 1e-6 per fragment, see docs/METHODS.md).
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

// the weight, its clamps and the composite are method_math.h's (also wboit.frag,
// wboit_resolve.comp)
using method_math::kWboitMaxDenominator;
using method_math::kWboitMaxWeight;
using method_math::kWboitMinDenominator;
using method_math::kWboitMinWeight;
using method_math::wboitWeight;

/// One pixel's accumulators: 20 bytes.
struct WboitPixel {
  float r = 0.0f, g = 0.0f, b = 0.0f;  // sum of C_i w_i (premultiplied colour times weight)
  float a = 0.0f;                      // sum of a_i w_i
  float revealage = 1.0f;              // product of (1 - a_i)

  void add(float depth, glm::vec4 c) {  // c: linear colour, alpha
    if (c.a <= 0.0f) return;
    method_math::wboitAccumulate(r, g, b, a, revealage, glm::vec3(c), c.a, wboitWeight(depth, c.a));
  }
  void add(float depth, uint32_t rgba) { add(depth, unpackFragmentColor(rgba)); }

  glm::vec3 composite(glm::vec3 background) const {
    return method_math::wboitComposite(glm::vec3(r, g, b), a, revealage, background);
  }
};
static_assert(sizeof(WboitPixel) == 20);

/// wboit as a peer method (peer_method.hpp): one accumulation pass into 20 bytes per pixel.
struct WboitMethod {
  static constexpr Compositing kRule = Compositing::WeightedBlended;
  static constexpr const char* kRuleName = "weighted-blended";
  static PresetInfo preset() {
    return {"wboit", "weighted blended OIT (McGuire & Bavoil 2013)",
            "weighted sums and revealage per pixel, no fragment nodes"};
  }
  using Slot = WboitPixel;
  static constexpr bool kNodes = false;
  static constexpr std::array<const char*, 0> kExtraPasses{};
  template <class Pixel>
  static void add(Pixel px, int /*pass*/, float depth, uint32_t rgba) {
    px.slots->add(depth, rgba);
    ++px.count;
  }
  static glm::vec3 composite(const WboitPixel* slots, uint32_t, glm::vec3 background) {
    return slots->composite(background);
  }
};

}  // namespace mfr
