// Moment-Based Order-Independent Transparency.
//   C. Münstermann, S. Krumpen, R. Klein, C. Peters. "Moment-Based Order-Independent
//   Transparency". Proceedings of the ACM on Computer Graphics and Interactive Techniques (HPG)
//   1(1), 2018, article 7.
//
// Two passes, no fragment nodes (power moments, 4 moments + the zeroth, float32):
//   1. moments: per fragment, absorbance A_i = -ln(1 - a_i) and warped depth z_i = 2 d_i - 1 in
//      [-1, 1] (d: window-space depth, which the frame fits to the scene's near/far):
//        b_0 += A_i,   b_j += A_i z_i^j  (j = 1..4)
//   2. resolve: per fragment the transmittance T(z_i) in front of it is reconstructed from the
//      moments and accumulated:  acc.rgb += T(z_i) a_i c_i,  acc.a += T(z_i) a_i
//   composite: T_total = exp(-b_0),
//        final = (1 - T_total) * acc.rgb / acc.a + T_total * background.
// Reconstruction (the paper's sec. 3 / the Hamburger four-moment bound of moment shadow mapping):
// the normalised moments b_j / b_0 are biased towards (0, 0.375, 0, 0.375) with the paper's
// recommended bias for 4 power moments in 32-bit floats, beta = 5e-7; the 3x3 Hankel system
// B c = (1, z, z^2) gives the polynomial whose roots z_1, z_2 and the query z carry the canonical
// 3-point distribution with these moments; the absorbance in front of z is the weight at the
// points nearer than z plus `overestimation` (0.25, the paper's setting) times the weight at z
// (0: a lower bound on the absorbance, so T above the truth; 1: an upper bound).
// Per-pixel storage: b_0 and b_1..b_4 (20 B) for pass 1 and the RGBA accumulator (16 B) of
// pass 2: 36 B, float32 (the paper's 16-bit quantised variants are not implemented).
//
// mboit6 and mboit8: the same two passes with 6 and 8 power moments (the paper's sec. 3.1: the
// reconstruction with n + 1 = 4 and 5 support points, so 3 and 4 separated layers are
// represented exactly up to the bias), method_math.h's mboitAddPowerMoments and
// mboitTransmittancePower; bias 5e-6 and 5e-5 (the paper's supplementary table for float32) and
// the authors' biasing vectors (their published shader code). Storage 44 and 52 B per pixel.
// mboit-trig3 and mboit-trig4: the same two passes with 3 and 4 trigonometric moments (the
// paper's sec. 3.2): the depth as a phase on the unit circle (a wrapping zone of pi / 10), the
// moments A e^(i k phi) as real and imaginary parts, the Toeplitz reconstruction of the authors'
// TrigonometricMomentMath (method_math.h's mboitAddTrigMoments and mboitTransmittanceTrig; roots
// by Weierstrass' iteration in double); bias 8e-7 and 1.5e-6 (the supplementary's float32 rows).
// Storage 44 and 52 B per pixel, as mboit6 and mboit8.
// The -q16 forms (mboit-q16, mboit6-q16, mboit8-q16, mboit-trig3-q16, mboit-trig4-q16): the
// paper's 16-bit storage of those moment sets, b0 in float32 and the normalised moments as 16-bit
// unorm codes in the authors' storage basis, updated read-modify-write per fragment
// (method_math.h's mboitAddQuantizedMoments, mboitDequantizeMoments); the 16-bit biases of the
// supplementary (6e-5, 6e-4, 2.5e-3; 6.5e-4, 8.5e-4). Storage 28, 32 and 36 B per pixel.
// The 4-moment constants were checked against the same sources: bias 5e-7 and the target
// (0, 0.375, 0, 0.375) are the supplementary's and the authors' code's; overestimation 0.25 is
// the setting of the authors' demo and of the public ports (PixelSyncOIT, LineVis's first
// version, inviwo).
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

// the constants and the reconstruction are method_math.h's (also mboit_*.frag, mboit_resolve.comp)
using method_math::kMboitBias;
using method_math::kMboitMaxAlpha;
using method_math::kMboitOverestimation;
using method_math::mboitAbsorbance;
using method_math::mboitWarpDepth;

/// Transmittance in front of `z` (warped depth) from b_0 and the moments b_1..b_4 (not
/// normalised), with the given bias and overestimation.
inline float mboitTransmittance(float b0, const float* moments, float z, float bias = kMboitBias,
                                float overestimation = kMboitOverestimation) {
  return method_math::mboitTransmittance(b0, moments[0], moments[1], moments[2], moments[3], z,
                                         bias, overestimation);
}

/// One pixel's buffers: 36 bytes.
struct MboitPixel {
  float b0 = 0.0f;
  float moments[4] = {0.0f, 0.0f, 0.0f, 0.0f};   // b_1..b_4
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;  // pass 2: sum T a c, sum T a

  void addMoments(float depth, float alpha) {
    if (alpha <= 0.0f) return;
    method_math::mboitAddMoments(b0, moments[0], moments[1], moments[2], moments[3],
                                 mboitAbsorbance(alpha), mboitWarpDepth(depth));
  }
  float transmittanceAt(float depth) const {
    return mboitTransmittance(b0, moments, mboitWarpDepth(depth));
  }
  void addColor(float depth, glm::vec4 c) {
    if (c.a <= 0.0f) return;
    method_math::mboitAddColor(r, g, b, a, glm::vec3(c), transmittanceAt(depth) * c.a);
  }
  void addColor(float depth, uint32_t rgba) { addColor(depth, unpackFragmentColor(rgba)); }

  glm::vec3 composite(glm::vec3 background) const {
    return method_math::mboitComposite(b0, glm::vec3(r, g, b), a, background);
  }
};
static_assert(sizeof(MboitPixel) == 36);

/// One pixel's buffers with Count (6 or 8) power moments: (1 + Count + 4) floats.
template <int Count>
struct PowerMomentPixel {
  static_assert(Count == 6 || Count == 8);
  float b0 = 0.0f;
  float moments[Count] = {};                     // b_1..b_Count
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;  // pass 2: sum T a c, sum T a

  void addMoments(float depth, float alpha) {
    if (alpha <= 0.0f) return;
    float all[method_math::kMboitMaxMoments] = {};
    for (int j = 0; j < Count; ++j) all[j] = moments[j];
    method_math::mboitAddPowerMoments(Count, b0, all, mboitAbsorbance(alpha),
                                      mboitWarpDepth(depth));
    for (int j = 0; j < Count; ++j) moments[j] = all[j];
  }
  float transmittanceAt(float depth) const {
    float all[method_math::kMboitMaxMoments] = {};
    for (int j = 0; j < Count; ++j) all[j] = moments[j];
    return method_math::mboitTransmittancePower(Count, b0, all, mboitWarpDepth(depth),
                                                method_math::mboitPowerBias(Count),
                                                kMboitOverestimation);
  }
};
static_assert(sizeof(PowerMomentPixel<6>) == 44 && sizeof(PowerMomentPixel<8>) == 52);

/// One pixel's buffers with Count (3 or 4) trigonometric moments: b0, the moments' real and
/// imaginary parts, the four accumulators: (1 + 2 Count + 4) floats, the sizes of mboit6 / mboit8.
template <int Count>
struct TrigMomentPixel {
  static_assert(Count == 3 || Count == 4);
  float b0 = 0.0f;
  float moments[2 * Count] = {};                 // Re b_1, Im b_1, .., Re b_Count, Im b_Count
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;  // pass 2: sum T a c, sum T a

  void addMoments(float depth, float alpha) {
    if (alpha <= 0.0f) return;
    float all[method_math::kMboitMaxMoments] = {};
    for (int j = 0; j < 2 * Count; ++j) all[j] = moments[j];
    method_math::mboitAddTrigMoments(Count, b0, all, mboitAbsorbance(alpha), mboitWarpDepth(depth));
    for (int j = 0; j < 2 * Count; ++j) moments[j] = all[j];
  }
  float transmittanceAt(float depth) const {
    float all[method_math::kMboitMaxMoments] = {};
    for (int j = 0; j < 2 * Count; ++j) all[j] = moments[j];
    return method_math::mboitTransmittanceTrig(Count, b0, all, mboitWarpDepth(depth),
                                               method_math::mboitTrigBias(Count),
                                               kMboitOverestimation);
  }
};
static_assert(sizeof(TrigMomentPixel<3>) == 44 && sizeof(TrigMomentPixel<4>) == 52);

/// One pixel's buffers with 16-bit storage of `Count` floats of moments (4, 6, 8 power moments, or
/// 6, 8 for 3, 4 trigonometric ones): b0 in float32, the moments as 16-bit unorm codes of the
/// storage basis, the four float32 accumulators: 4 + 2 Count + 16 bytes.
template <int Count, bool Trigonometric>
struct QuantizedMomentPixel {
  static_assert(Count == 4 || Count == 6 || Count == 8);
  static_assert(!Trigonometric || Count != 4);
  float b0 = 0.0f;
  uint16_t codes[Count] = {};                    // unorm16 codes (method_math.h's storage basis)
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;  // pass 2: sum T a c, sum T a

  void unorm(float (&u)[method_math::kMboitMaxMoments]) const {
    for (int j = 0; j < Count; ++j) u[j] = static_cast<float>(codes[j]) / method_math::kUnorm16Max;
  }
  void addMoments(float depth, float alpha) {
    if (alpha <= 0.0f) return;
    float u[method_math::kMboitMaxMoments] = {};
    unorm(u);  // with b0 = 0 the stored values weigh nothing
    method_math::mboitAddQuantizedMoments(Count, Trigonometric, b0, u, mboitAbsorbance(alpha),
                                          mboitWarpDepth(depth));
    for (int j = 0; j < Count; ++j)
      codes[j] = static_cast<uint16_t>(method_math::unorm16Code(u[j]));
  }
  float transmittanceAt(float depth) const {
    float u[method_math::kMboitMaxMoments] = {};
    unorm(u);
    float moments[method_math::kMboitMaxMoments] = {};
    method_math::mboitDequantizeMoments(Count, Trigonometric, b0, u, moments);
    const float bias = method_math::mboitQuantizedBias(Count, Trigonometric);
    if constexpr (Trigonometric)
      return method_math::mboitTransmittanceTrig(Count / 2, b0, moments, mboitWarpDepth(depth),
                                                 bias, kMboitOverestimation);
    return method_math::mboitTransmittancePower(Count, b0, moments, mboitWarpDepth(depth), bias,
                                                kMboitOverestimation);
  }
};
static_assert(sizeof(QuantizedMomentPixel<4, false>) == 28 &&
              sizeof(QuantizedMomentPixel<6, false>) == 32 &&
              sizeof(QuantizedMomentPixel<8, true>) == 36);

/// The moments pass, then the capture weighting each fragment by its reconstructed transmittance:
/// what every moment peer method with a Pixel of b0, moments and the four sums (r, g, b, a) does
/// (its addMoments and transmittanceAt are the moment set's own; the colour pass and the
/// composite are shared).
template <class Pixel>
struct MomentPasses {
  using Slot = Pixel;
  static constexpr bool kNodes = false;
  static constexpr std::array<const char*, 1> kExtraPasses{"moments"};
  template <class PeerPixel>
  static void add(PeerPixel px, int pass, float depth, uint32_t rgba) {
    if (pass == 0) {
      px.slots->addMoments(depth, static_cast<float>(rgba >> 24) / 255.0f);
      return;
    }
    Pixel& p = *px.slots;
    ++px.count;
    const glm::vec4 c = unpackFragmentColor(rgba);
    if (c.a <= 0.0f) return;
    method_math::mboitAddColor(p.r, p.g, p.b, p.a, glm::vec3(c), p.transmittanceAt(depth) * c.a);
  }
  static glm::vec3 composite(const Pixel* slots, uint32_t, glm::vec3 background) {
    return method_math::mboitComposite(slots->b0, glm::vec3(slots->r, slots->g, slots->b), slots->a,
                                       background);
  }
};

/// mboit6: 6 power moments, 44 bytes per pixel.
struct Mboit6Method : MomentPasses<PowerMomentPixel<6>> {
  static constexpr Compositing kRule = Compositing::MomentBased6;
  static constexpr const char* kRuleName = "moment-based-6";
  static PresetInfo preset() {
    return {"mboit6", "moment-based OIT, 6 power moments (Muenstermann et al. 2018)",
            "6 power moments of ln-transmittance per pixel, no fragment nodes"};
  }
};

/// mboit8: 8 power moments, 52 bytes per pixel.
struct Mboit8Method : MomentPasses<PowerMomentPixel<8>> {
  static constexpr Compositing kRule = Compositing::MomentBased8;
  static constexpr const char* kRuleName = "moment-based-8";
  static PresetInfo preset() {
    return {"mboit8", "moment-based OIT, 8 power moments (Muenstermann et al. 2018)",
            "8 power moments of ln-transmittance per pixel, no fragment nodes"};
  }
};

/// mboit-trig3: 3 trigonometric moments, 44 bytes per pixel.
struct MboitTrig3Method : MomentPasses<TrigMomentPixel<3>> {
  static constexpr Compositing kRule = Compositing::MomentBasedTrig3;
  static constexpr const char* kRuleName = "moment-based-trig-3";
  static PresetInfo preset() {
    return {"mboit-trig3", "moment-based OIT, 3 trigonometric moments (Muenstermann et al. 2018)",
            "3 trigonometric moments of ln-transmittance per pixel, no fragment nodes"};
  }
};

/// mboit-trig4: 4 trigonometric moments, 52 bytes per pixel.
struct MboitTrig4Method : MomentPasses<TrigMomentPixel<4>> {
  static constexpr Compositing kRule = Compositing::MomentBasedTrig4;
  static constexpr const char* kRuleName = "moment-based-trig-4";
  static PresetInfo preset() {
    return {"mboit-trig4", "moment-based OIT, 4 trigonometric moments (Muenstermann et al. 2018)",
            "4 trigonometric moments of ln-transmittance per pixel, no fragment nodes"};
  }
};

/// A 16-bit moment preset: the storage's Count floats of moments, its preset row.
template <Compositing Rule, int Count, bool Trigonometric>
struct Quantized16Method : MomentPasses<QuantizedMomentPixel<Count, Trigonometric>> {
  static constexpr Compositing kRule = Rule;
};

/// mboit-q16, mboit6-q16, mboit8-q16, mboit-trig3-q16, mboit-trig4-q16: the 16-bit storage of
/// the paper's sec. 4 (b0 float32, 28 to 36 bytes per pixel).
struct Mboit16Method : Quantized16Method<Compositing::MomentBased16, 4, false> {
  static constexpr const char* kRuleName = "moment-based-16";
  static PresetInfo preset() {
    return {"mboit-q16", "moment-based OIT, 4 power moments in 16 bits (Muenstermann et al. 2018)",
            "4 power moments in 16-bit unorm + float b0 per pixel, no fragment nodes"};
  }
};
struct Mboit6_16Method : Quantized16Method<Compositing::MomentBased6_16, 6, false> {
  static constexpr const char* kRuleName = "moment-based-6-16";
  static PresetInfo preset() {
    return {"mboit6-q16", "moment-based OIT, 6 power moments in 16 bits (Muenstermann et al. 2018)",
            "6 power moments in 16-bit unorm + float b0 per pixel, no fragment nodes"};
  }
};
struct Mboit8_16Method : Quantized16Method<Compositing::MomentBased8_16, 8, false> {
  static constexpr const char* kRuleName = "moment-based-8-16";
  static PresetInfo preset() {
    return {"mboit8-q16", "moment-based OIT, 8 power moments in 16 bits (Muenstermann et al. 2018)",
            "8 power moments in 16-bit unorm + float b0 per pixel, no fragment nodes"};
  }
};
struct MboitTrig3_16Method : Quantized16Method<Compositing::MomentBasedTrig3_16, 6, true> {
  static constexpr const char* kRuleName = "moment-based-trig-3-16";
  static PresetInfo preset() {
    return {"mboit-trig3-q16",
            "moment-based OIT, 3 trigonometric moments in 16 bits (Muenstermann et al. 2018)",
            "3 trigonometric moments in 16-bit unorm + float b0 per pixel, no fragment nodes"};
  }
};
struct MboitTrig4_16Method : Quantized16Method<Compositing::MomentBasedTrig4_16, 8, true> {
  static constexpr const char* kRuleName = "moment-based-trig-4-16";
  static PresetInfo preset() {
    return {"mboit-trig4-q16",
            "moment-based OIT, 4 trigonometric moments in 16 bits (Muenstermann et al. 2018)",
            "4 trigonometric moments in 16-bit unorm + float b0 per pixel, no fragment nodes"};
  }
};

/// The floats of moments a moment-based rule keeps besides b0: 4 (mboit), 6 (mboit6, and
/// mboit-trig3's three complex moments), 8 (mboit8, mboit-trig4); 0 for any other rule. The GL
/// engine's one moment technique runs all five by this count and mboitTrigonometric.
inline int mboitMomentCount(Compositing c) {
  switch (c) {
    case Compositing::MomentBased:
    case Compositing::MomentBased16:
      return 4;
    case Compositing::MomentBased6:
    case Compositing::MomentBasedTrig3:
    case Compositing::MomentBased6_16:
    case Compositing::MomentBasedTrig3_16:
      return 6;
    case Compositing::MomentBased8:
    case Compositing::MomentBasedTrig4:
    case Compositing::MomentBased8_16:
    case Compositing::MomentBasedTrig4_16:
      return 8;
    default:
      return 0;
  }
}

/// True for the trigonometric moment rules.
inline bool mboitTrigonometric(Compositing c) {
  return c == Compositing::MomentBasedTrig3 || c == Compositing::MomentBasedTrig4 ||
         c == Compositing::MomentBasedTrig3_16 || c == Compositing::MomentBasedTrig4_16;
}

/// True for the 16-bit moment rules.
inline bool mboitQuantized(Compositing c) {
  return c == Compositing::MomentBased16 || c == Compositing::MomentBased6_16 ||
         c == Compositing::MomentBased8_16 || c == Compositing::MomentBasedTrig3_16 ||
         c == Compositing::MomentBasedTrig4_16;
}

/// mboit as a peer method (peer_method.hpp): the moments pass, then the capture weighting each
/// fragment by the reconstructed transmittance, 36 bytes per pixel.
struct MboitMethod {
  static constexpr Compositing kRule = Compositing::MomentBased;
  static constexpr const char* kRuleName = "moment-based";
  static PresetInfo preset() {
    return {"mboit", "moment-based OIT (Muenstermann et al. 2018)",
            "4 power moments of ln-transmittance per pixel, no fragment nodes"};
  }
  using Slot = MboitPixel;
  static constexpr bool kNodes = false;
  static constexpr std::array<const char*, 1> kExtraPasses{"moments"};
  template <class Pixel>
  static void add(Pixel px, int pass, float depth, uint32_t rgba) {
    if (pass == 0) {
      px.slots->addMoments(depth, static_cast<float>(rgba >> 24) / 255.0f);
      return;
    }
    px.slots->addColor(depth, rgba);
    ++px.count;
  }
  static glm::vec3 composite(const MboitPixel* slots, uint32_t, glm::vec3 background) {
    return slots->composite(background);
  }
};

}  // namespace mfr
