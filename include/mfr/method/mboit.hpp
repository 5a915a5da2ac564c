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
// pass 2: 36 B, float32 (the paper's 16-bit quantised variant is not implemented).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

inline constexpr float kMboitBias = 5e-7f;            // 4 power moments, float32
inline constexpr float kMboitOverestimation = 0.25f;  // towards the upper absorbance bound
inline constexpr float kMboitMaxAlpha = 0.99999f;     // keeps -ln(1 - a) finite

inline float mboitWarpDepth(float depth) {
  return 2.0f * std::clamp(depth, 0.0f, 1.0f) - 1.0f;
}

inline float mboitAbsorbance(float alpha) {
  return -std::log(1.0f - std::min(alpha, kMboitMaxAlpha));
}

/// Transmittance in front of `z` (warped depth) from b_0 and the moments b_1..b_4 (not
/// normalised), with the given bias and overestimation.
inline float mboitTransmittance(float b0, const float* moments, float z, float bias = kMboitBias,
                                float overestimation = kMboitOverestimation) {
  if (b0 <= 0.0f) return 1.0f;
  // normalise and bias (double for the solve; the moments are stored as float32)
  const double beta = bias;
  const double v[4] = {0.0, 0.375, 0.0, 0.375};
  double b[4];
  for (int j = 0; j < 4; ++j)
    b[j] = (1.0 - beta) * (moments[j] / static_cast<double>(b0)) + beta * v[j];
  // LDL^T of the Hankel matrix [[1, b1, b2], [b1, b2, b3], [b2, b3, b4]]
  const double d1 = b[1] - b[0] * b[0];
  const double l21 = (b[2] - b[0] * b[1]) / d1;
  const double d2 = b[3] - b[1] * b[1] - l21 * l21 * d1;
  // solve B c = (1, z, z^2)
  const double z0 = z;
  double c1 = z0 - b[0];
  double c2 = z0 * z0 - b[1] - l21 * c1;
  c1 /= d1;
  c2 /= d2;
  c1 -= l21 * c2;
  const double c0 = 1.0 - b[0] * c1 - b[1] * c2;
  // the roots of c0 + c1 x + c2 x^2
  const double p = c1 / c2, q = c0 / c2;
  const double r = std::sqrt(std::max(0.0, 0.25 * p * p - q));
  double z1 = -0.5 * p - r, z2 = -0.5 * p + r;
  // the quadratic through (z0, f0), (z1, f1), (z2, f2), by divided differences; its expectation
  // under the moments is the normalised absorbance in front of z0
  const double f0 = overestimation, f1 = z1 < z0 ? 1.0 : 0.0, f2 = z2 < z0 ? 1.0 : 0.0;
  constexpr double kTiny = 1e-12;
  if (std::fabs(z1 - z0) < kTiny) z1 = z0 - kTiny;
  if (std::fabs(z2 - z0) < kTiny) z2 = z0 + kTiny;
  if (std::fabs(z2 - z1) < kTiny) z2 = z1 + kTiny;
  const double f01 = (f1 - f0) / (z1 - z0);
  const double f12 = (f2 - f1) / (z2 - z1);
  const double f012 = (f12 - f01) / (z2 - z0);
  // P(x) = f0 + f01 (x - z0) + f012 (x - z0)(x - z1)
  const double p2 = f012;
  const double p1 = f01 - f012 * (z0 + z1);
  const double p0 = f0 - f01 * z0 + f012 * z0 * z1;
  const double absorbance = p0 + p1 * b[0] + p2 * b[1];
  const double t = std::exp(-static_cast<double>(b0) * absorbance);
  if (!std::isfinite(t)) return 1.0f;
  return static_cast<float>(std::clamp(t, 0.0, 1.0));
}

/// One pixel's buffers: 36 bytes.
struct MboitPixel {
  float b0 = 0.0f;
  float moments[4] = {0.0f, 0.0f, 0.0f, 0.0f};   // b_1..b_4
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;  // pass 2: sum T a c, sum T a

  void addMoments(float depth, float alpha) {
    if (alpha <= 0.0f) return;
    const float A = mboitAbsorbance(alpha);
    const float z = mboitWarpDepth(depth), z2 = z * z;
    b0 += A;
    moments[0] += A * z;
    moments[1] += A * z2;
    moments[2] += A * z2 * z;
    moments[3] += A * z2 * z2;
  }
  float transmittanceAt(float depth) const {
    return mboitTransmittance(b0, moments, mboitWarpDepth(depth));
  }
  void addColor(float depth, glm::vec4 c) {
    if (c.a <= 0.0f) return;
    const float ta = transmittanceAt(depth) * c.a;
    r += ta * c.r;
    g += ta * c.g;
    b += ta * c.b;
    a += ta;
  }
  void addColor(float depth, uint32_t rgba) { addColor(depth, unpackFragmentColor(rgba)); }

  glm::vec3 composite(glm::vec3 background) const {
    if (b0 <= 0.0f || a <= 0.0f) return background;
    const float total = std::exp(-b0);
    return (1.0f - total) * glm::vec3(r, g, b) / a + total * background;
  }
};
static_assert(sizeof(MboitPixel) == 36);

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
