// The methods' per-pixel maths, written once for both engines: this file is C++20 (glm) and GLSL
// 4.50 at the same time. The CPU engine includes it (namespace mfr::method_math, re-exported by
// compositing.hpp, wboit.hpp, mboit.hpp, mlab.hpp and importance.hpp); the shader embedding step
// prepends it to every shader after shared_layout.h (src/gl/gl_programs.cpp, composeSource). Every
// numeric constant of a method lives here; GlShaders.MethodConstantsOnlyInMethodMath checks that
// no shader repeats one.
//
// Sources of the formulas:
//   front-to-back "over" of sorted fragments: the k-buffer family's resolve (Vasilakis and Fudos,
//     k+-buffer; ../shared/papers/k-plus-buffer.txt);
//   hybrid tail: Maule, Comba, Torchelsen, Bastos, "Hybrid Transparency", I3D 2013, as used by
//     DHOIT sec. 3.3 (../shared/papers/deep-hybrid-oit.txt); see compositing.hpp;
//   WBOIT: McGuire and Bavoil, "Weighted Blended Order-Independent Transparency", JCGT 2(2), 2013,
//     Eq. 10 (weight) and the resolve's clamp of the denominator; see wboit.hpp;
//   MLAB: Salvi and Vaidyanathan, "Multi-layer Alpha Blending", I3D 2014 (the merge by "over");
//     see mlab.hpp;
//   depth peeling: Everitt, "Interactive Order-Independent Transparency", NVIDIA 2001; dual depth
//     peeling: Bavoil and Myers, "Order Independent Transparency with Dual Depth Peeling", NVIDIA
//     2008 (underStep, the back layers); see peel.hpp;
//   MBOIT: Muenstermann, Krumpen, Klein, Peters, "Moment-Based Order-Independent Transparency",
//     HPG 2018 (4 power moments, bias 5e-7, overestimation 0.25); see mboit.hpp;
//   importance: Vasilakis, Vardis, Papaioannou, Moustakas, "Variable k-buffer using Importance
//     Maps", sec. 3.2, Eqs. 3-6 (../shared/papers/variable-k-buffer-importance-maps.md); see
//     importance.hpp;
//   guard band: the CPU set-up's x/y clip planes (src/cpu/raster_frame.cpp, shaders/raster.geom).
//
// Bit-identity: each function performs the same float operations in the same order on both sides;
// every GLSL intermediate is `precise` (no fused multiply-add; C++20 without GNU extensions does
// not contract either). Where the two languages cannot share an operation it is a per-side
// primitive below (the host's correctly rounded float division, square root and powf against
// GLSL's double-precision equivalents; GLSL has no double exp), each documented.
//
// Common subset: float literals carry the `f` suffix (a float in both); an unsuffixed literal is
// only used where the value is exact in float and the expression is double (C++: a double, GLSL: a
// float converted exactly); min, max, clamp, pow, exp, log, sqrt and abs are GLSL's built-ins and
// std:: in C++.
#ifdef __cplusplus
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace mfr::method_math {
using uint = uint32_t;
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using std::abs;
using std::clamp;
using std::exp;
using std::log;
using std::max;
using std::min;
using std::pow;
using std::sqrt;
#define MFR_MATH_CONST(type, name, value) inline constexpr type name = value;
#define MFR_MATH_FN inline
#define MFR_INOUT(type) type&
#define MFR_IN_ARRAY(type, name, n) const type(&name)[n]
#define MFR_INOUT_ARRAY(type, name, n) type(&name)[n]
#define MFR_PRECISE
#else
#define MFR_MATH_CONST(type, name, value) const type name = value;
#define MFR_MATH_FN
#define MFR_INOUT(type) inout type
#define MFR_IN_ARRAY(type, name, n) type name[n]
#define MFR_INOUT_ARRAY(type, name, n) inout type name[n]
#define MFR_PRECISE precise
#endif

// ---- constants ---------------------------------------------------------------------------------

// WBOIT (McGuire and Bavoil 2013): Eq. 10's clamps of the depth weight, the resolve's clamp of the
// weighted alpha sum (the denominator)
MFR_MATH_CONST(float, kWboitMinWeight, 1e-2f)
MFR_MATH_CONST(float, kWboitMaxWeight, 3e3f)
MFR_MATH_CONST(float, kWboitMinDenominator, 1e-4f)
MFR_MATH_CONST(float, kWboitMaxDenominator, 5e4f)

// MBOIT (Muenstermann et al. 2018): the paper's bias for 4 power moments in float32, its
// overestimation, the alpha cap that keeps -ln(1 - a) finite, the biasing target of the normalised
// moments b1..b4, and the smallest root separation of the reconstruction (double)
MFR_MATH_CONST(float, kMboitBias, 5e-7f)
MFR_MATH_CONST(float, kMboitOverestimation, 0.25f)
MFR_MATH_CONST(float, kMboitMaxAlpha, 0.99999f)
MFR_MATH_CONST(float, kMboitBiasTarget1, 0.0f)
MFR_MATH_CONST(float, kMboitBiasTarget2, 0.375f)
MFR_MATH_CONST(float, kMboitBiasTarget3, 0.0f)
MFR_MATH_CONST(float, kMboitBiasTarget4, 0.375f)
// MBOIT with 6 and 8 power moments (the paper's sec. 3 generalisation): the bias for float32
// storage from the paper's supplementary table (6 moments 5e-6, 8 moments 5e-5; 4 moments 5e-7
// above) and the authors' biasing targets of the normalised even moments (their published shader
// code, MomentOIT.hlsl, as ported in chrismile/LineVis; the odd moments' targets are 0)
MFR_MATH_CONST(int, kMboitMaxMoments, 8)
MFR_MATH_CONST(float, kMboit6Bias, 5e-6f)
MFR_MATH_CONST(float, kMboit8Bias, 5e-5f)
MFR_MATH_CONST(float, kMboit6BiasTarget2, 0.48f)
MFR_MATH_CONST(float, kMboit6BiasTarget4, 0.451f)
MFR_MATH_CONST(float, kMboit6BiasTarget6, 0.45f)
MFR_MATH_CONST(float, kMboit8BiasTarget2, 0.75f)
MFR_MATH_CONST(float, kMboit8BiasTarget4, 0.67666666666666664f)
MFR_MATH_CONST(float, kMboit8BiasTarget6, 0.63f)
MFR_MATH_CONST(float, kMboit8BiasTarget8, 0.60030303030303034f)
// Laguerre's iteration for the support points: at most this many steps per root
MFR_MATH_CONST(int, kMboitRootIterations, 64)
// 1e-12 (GLSL has no token pasting for an `lf` suffix: the correctly rounded quotient of exact
// integers is the same double as the literal)
MFR_MATH_CONST(double, kMboitTiny, double(1) / (double(1000000) * double(1000000)))

// Importance (variable k-buffer, sec. 3.2): Eq. 4's diagonal scale 1.1 and factor 2, Eq. 5's
// Fresnel power 5 and halving, Eq. 6's noise centre; the noise xi is SplitMix64's finaliser of
// (seed, pixel) with these 64-bit constants as (lo, hi) 32-bit words, 24 bits to [0, 1)
MFR_MATH_CONST(float, kImportanceDiagonalScale, 1.1f)
MFR_MATH_CONST(float, kImportancePeripheryScale, 2.0f)
MFR_MATH_CONST(int, kImportanceFresnelPower, 5)
MFR_MATH_CONST(float, kImportanceFresnelScale, 0.5f)
MFR_MATH_CONST(float, kImportanceNoiseCentre, 0.5f)
MFR_MATH_CONST(float, kImportanceNoiseUnit, 1.0f / 16777216.0f)  // 2^-24
MFR_MATH_CONST(uint, kSplitMixGammaLo, 0x7F4A7C15u)              // 0x9E3779B97F4A7C15
MFR_MATH_CONST(uint, kSplitMixGammaHi, 0x9E3779B9u)
MFR_MATH_CONST(uint, kSplitMixOffsetLo, 0xD9B4E019u)  // 0x632BE59BD9B4E019
MFR_MATH_CONST(uint, kSplitMixOffsetHi, 0x632BE59Bu)
MFR_MATH_CONST(uint, kSplitMixMul1Lo, 0x1CE4E5B9u)  // 0xBF58476D1CE4E5B9
MFR_MATH_CONST(uint, kSplitMixMul1Hi, 0xBF58476Du)
MFR_MATH_CONST(uint, kSplitMixMul2Lo, 0x133111EBu)  // 0x94D049BB133111EB
MFR_MATH_CONST(uint, kSplitMixMul2Hi, 0x94D049BBu)
MFR_MATH_CONST(uint, kSplitMixShift1, 30u)
MFR_MATH_CONST(uint, kSplitMixShift2, 27u)
MFR_MATH_CONST(uint, kSplitMixShift3, 31u)
MFR_MATH_CONST(uint, kSplitMixKeepShift, 40u)  // the top 24 of 64 bits

// Guard band: clipping against x, y = +-kGuardBand w keeps fixed-point window coordinates below
// 2^25 at 16384 pixels; the set-up clamps NDC to kGuardBandMaxNdc (C++ part below)
MFR_MATH_CONST(float, kGuardBand, 8.0f)

// Texture wrap modes (mfr::TextureWrap's values; glTF REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT)
MFR_MATH_CONST(uint, kTextureWrapRepeat, 0u)
MFR_MATH_CONST(uint, kTextureWrapClamp, 1u)
MFR_MATH_CONST(uint, kTextureWrapMirror, 2u)

// ---- per-side primitives -----------------------------------------------------------------------
#ifdef __cplusplus
inline constexpr double kGuardBandMaxNdc = kGuardBand * 1.001;  // raster.geom: uniform uMaxNdc

/// a / b, correctly rounded (GLSL: through double).
inline float exactDivide(float a, float b) {
  return a / b;
}
/// sqrt(x), correctly rounded (GLSL: through double).
inline float exactSqrt(float x) {
  return std::sqrt(x);
}
/// powf(x, e). GLSL: with `eInt` >= 0 (e an integer) the product in double rounded to float (the
/// correctly rounded powf in all but rare cases, as glibc's), else GLSL's float pow.
inline float hostPow(float x, float e, int /*eInt*/) {
  return std::pow(x, e);
}
/// exp in double (GLSL has none: float exp of the argument rounded to float).
inline double doubleExp(double x) {
  return std::exp(x);
}
inline bool isFiniteDouble(double x) {
  return std::isfinite(x);
}
/// A 64-bit constant from its (lo, hi) words.
constexpr uint64_t words64(uint lo, uint hi) {
  return (uint64_t{hi} << 32) | lo;
}
#else
float exactDivide(float a, float b) {
  return float(double(a) / double(b));
}
float exactSqrt(float x) {
  return float(sqrt(double(x)));
}
float hostPow(float x, float e, int eInt) {
  if (eInt < 0) return pow(x, e);
  precise double r = 1.0lf;
  for (int i = 0; i < eInt; ++i) r *= double(x);
  return float(r);
}
double doubleExp(double x) {
  return double(exp(float(x)));
}
bool isFiniteDouble(double x) {
  return !isinf(x) && !isnan(x);
}
#endif

// ---- k-buffer family: front-to-back "over" and the hybrid tail ---------------------------------

/// One front-to-back "over" step of a sorted fragment (linear colour c, alpha a) onto the colour
/// sum (r, g, b) and the transmittance T in front of it:
///   w = a T,  (r, g, b) += c w,  T *= 1 - a.
/// Scalar channels: the CPU hot loop keeps them in registers (glm's vec3 kept them on the stack).
MFR_MATH_FN void overStep(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                          MFR_INOUT(float) T, float a, float cr, float cg, float cb) {
  MFR_PRECISE float w = a * T;
  MFR_PRECISE float nr = r + cr * w;
  MFR_PRECISE float ng = g + cg * w;
  MFR_PRECISE float nb = b + cb * w;
  MFR_PRECISE float nextT = T * (1.0f - a);
  r = nr;
  g = ng;
  b = nb;
  T = nextT;
}

/// Dual depth peeling's back side (Bavoil & Myers 2008, peel.hpp): a layer (linear colour c,
/// alpha a) blended back to front in front of the back colour (r, g, b) and its transmittance T:
///   (r, g, b) = c a + (1 - a) (r, g, b),  T *= 1 - a.
MFR_MATH_FN void underStep(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                           MFR_INOUT(float) T, float a, float cr, float cg, float cb) {
  MFR_PRECISE float keep = 1.0f - a;
  MFR_PRECISE float nr = cr * a + keep * r;
  MFR_PRECISE float ng = cg * a + keep * g;
  MFR_PRECISE float nb = cb * a + keep * b;
  MFR_PRECISE float nextT = T * keep;
  r = nr;
  g = ng;
  b = nb;
  T = nextT;
}

/// The composited colour in front plus the transmittance times what lies behind it.
MFR_MATH_FN vec3 overBackground(vec3 color, float T, vec3 behind) {
  MFR_PRECISE vec3 result = color + T * behind;
  return result;
}

/// mfr::HybridTail::add: a fragment (linear colour c, alpha a) not kept by the store joins the
/// pixel's order-independent tail: sums of a c and a, and the count t.
MFR_MATH_FN void hybridTailAdd(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                               MFR_INOUT(float) alphaSum, MFR_INOUT(uint) count, float a, float cr,
                               float cg, float cb) {
  MFR_PRECISE float nr = r + a * cr;
  MFR_PRECISE float ng = g + a * cg;
  MFR_PRECISE float nb = b + a * cb;
  MFR_PRECISE float na = alphaSum + a;
  r = nr;
  g = ng;
  b = nb;
  alphaSum = na;
  count = count + 1u;
}

/// What lies behind the sorted core in the hybrid rule: the tail (C_tail = sum(a c) / sum(a),
/// a_avg = sum(a) / t, alpha_tail = 1 - (1 - a_avg)^t) over the background; the background alone
/// when the tail is empty. pow: std::pow on the host, GLSL's pow (exp2(y log2 x)) on the GPU, so
/// the last bits of a non-empty tail may differ between the engines.
MFR_MATH_FN vec3 hybridBehind(vec3 tailSum, float tailAlphaSum, uint tailCount, vec3 background) {
  if (tailCount == 0u || tailAlphaSum <= 0.0f) return background;
  MFR_PRECISE vec3 tailColor = tailSum / tailAlphaSum;
  MFR_PRECISE float avgAlpha = tailAlphaSum / float(tailCount);
  MFR_PRECISE float tailAlpha = 1.0f - pow(max(0.0f, 1.0f - avgAlpha), float(tailCount));
  MFR_PRECISE vec3 mixed = tailAlpha * tailColor + (1.0f - tailAlpha) * background;
  return mixed;
}

// ---- weighted blended OIT ----------------------------------------------------------------------

/// Eq. 10 for window-space depth d: w(d, a) = a max(1e-2, 3e3 (1 - d)^3).
MFR_MATH_FN float wboitWeight(float depth, float alpha) {
  MFR_PRECISE float t = 1.0f - clamp(depth, 0.0f, 1.0f);
  MFR_PRECISE float w = alpha * max(kWboitMinWeight, kWboitMaxWeight * t * t * t);
  return w;
}

/// One fragment (linear colour c, alpha a, weight w) into the accumulators: (r, g, b) += c a w,
/// alphaSum += a w, revealage *= 1 - a.
MFR_MATH_FN void wboitAccumulate(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                                 MFR_INOUT(float) alphaSum, MFR_INOUT(float) revealage, vec3 c,
                                 float a, float w) {
  MFR_PRECISE float nr = r + c.r * a * w;
  MFR_PRECISE float ng = g + c.g * a * w;
  MFR_PRECISE float nb = b + c.b * a * w;
  MFR_PRECISE float na = alphaSum + a * w;
  MFR_PRECISE float nrev = revealage * (1.0f - a);
  r = nr;
  g = ng;
  b = nb;
  alphaSum = na;
  revealage = nrev;
}

/// The composite: sum / clamp(alphaSum, 1e-4, 5e4) (1 - revealage) + revealage background.
MFR_MATH_FN vec3 wboitComposite(vec3 sum, float alphaSum, float revealage, vec3 background) {
  if (alphaSum <= 0.0f) return background;
  MFR_PRECISE vec3 average = sum / clamp(alphaSum, kWboitMinDenominator, kWboitMaxDenominator);
  MFR_PRECISE vec3 mixed = average * (1.0f - revealage) + revealage * background;
  return mixed;
}

// ---- multi-layer alpha blending ----------------------------------------------------------------

/// A fragment's node colour: premultiplied c a (its transmittance is 1 - a, mlabTransmittance).
MFR_MATH_FN vec3 mlabPremultiplied(vec3 c, float a) {
  MFR_PRECISE vec3 premultiplied = c * a;
  return premultiplied;
}
MFR_MATH_FN float mlabTransmittance(float a) {
  MFR_PRECISE float t = 1.0f - a;
  return t;
}

/// The merge: the node (r, g, b, T) gets the node (farRgb, farT) composited behind it by "over".
MFR_MATH_FN void mlabMergeBehind(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                                 MFR_INOUT(float) T, vec3 farRgb, float farT) {
  MFR_PRECISE float nr = r + T * farRgb.r;
  MFR_PRECISE float ng = g + T * farRgb.g;
  MFR_PRECISE float nb = b + T * farRgb.b;
  MFR_PRECISE float nextT = T * farT;
  r = nr;
  g = ng;
  b = nb;
  T = nextT;
}

/// One resolve step over a sorted node (premultiplied rgb, transmittance t).
MFR_MATH_FN void mlabCompositeStep(MFR_INOUT(vec3) color, MFR_INOUT(float) T, vec3 rgb, float t) {
  MFR_PRECISE vec3 sum = color + T * rgb;
  MFR_PRECISE float nextT = T * t;
  color = sum;
  T = nextT;
}

// ---- moment-based OIT --------------------------------------------------------------------------

/// Window-space depth to the warped depth z = 2 d - 1 in [-1, 1].
MFR_MATH_FN float mboitWarpDepth(float depth) {
  MFR_PRECISE float z = 2.0f * clamp(depth, 0.0f, 1.0f) - 1.0f;
  return z;
}

/// Absorbance -ln(1 - a), a capped at kMboitMaxAlpha.
MFR_MATH_FN float mboitAbsorbance(float alpha) {
  MFR_PRECISE float A = -log(1.0f - min(alpha, kMboitMaxAlpha));
  return A;
}

/// Pass 1: b0 += A, b_j += A z^j (j = 1..4).
MFR_MATH_FN void mboitAddMoments(MFR_INOUT(float) b0, MFR_INOUT(float) b1, MFR_INOUT(float) b2,
                                 MFR_INOUT(float) b3, MFR_INOUT(float) b4, float A, float z) {
  MFR_PRECISE float z2 = z * z;
  MFR_PRECISE float s0 = b0 + A;
  MFR_PRECISE float s1 = b1 + A * z;
  MFR_PRECISE float s2 = b2 + A * z2;
  MFR_PRECISE float s3 = b3 + A * z2 * z;
  MFR_PRECISE float s4 = b4 + A * z2 * z2;
  b0 = s0;
  b1 = s1;
  b2 = s2;
  b3 = s3;
  b4 = s4;
}

/// Transmittance in front of the warped depth z from b0 and b1..b4 (not normalised), with the given
/// bias and overestimation (mboit.hpp: the biased Hankel system solved in double, the canonical
/// 3-point distribution; its weight in front of z is the normalised absorbance).
MFR_MATH_FN float mboitTransmittance(float b0, float m1, float m2, float m3, float m4, float z,
                                     float bias, float overestimation) {
  if (b0 <= 0.0f) return 1.0f;
  // normalise and bias
  const double beta = double(bias);
  MFR_PRECISE double n1 =
      (1.0 - beta) * (double(m1) / double(b0)) + beta * double(kMboitBiasTarget1);
  MFR_PRECISE double n2 =
      (1.0 - beta) * (double(m2) / double(b0)) + beta * double(kMboitBiasTarget2);
  MFR_PRECISE double n3 =
      (1.0 - beta) * (double(m3) / double(b0)) + beta * double(kMboitBiasTarget3);
  MFR_PRECISE double n4 =
      (1.0 - beta) * (double(m4) / double(b0)) + beta * double(kMboitBiasTarget4);
  // LDL^T of the Hankel matrix [[1, n1, n2], [n1, n2, n3], [n2, n3, n4]]
  MFR_PRECISE double d1 = n2 - n1 * n1;
  MFR_PRECISE double l21 = (n3 - n1 * n2) / d1;
  MFR_PRECISE double d2 = n4 - n2 * n2 - l21 * l21 * d1;
  // solve B c = (1, z, z^2)
  const double z0 = double(z);
  MFR_PRECISE double c1 = z0 - n1;
  MFR_PRECISE double c2 = z0 * z0 - n2 - l21 * c1;
  c1 /= d1;
  c2 /= d2;
  c1 -= l21 * c2;
  MFR_PRECISE double c0 = 1.0 - n1 * c1 - n2 * c2;
  // the roots of c0 + c1 x + c2 x^2
  MFR_PRECISE double p = c1 / c2;
  MFR_PRECISE double q = c0 / c2;
  MFR_PRECISE double r = sqrt(max(0.0, 0.25 * p * p - q));
  MFR_PRECISE double z1 = -0.5 * p - r;
  MFR_PRECISE double z2 = -0.5 * p + r;
  // the quadratic through (z0, f0), (z1, f1), (z2, f2), by divided differences; its expectation
  // under the moments is the normalised absorbance in front of z0
  const double f0 = double(overestimation);
  const double f1 = z1 < z0 ? 1.0 : 0.0;
  const double f2 = z2 < z0 ? 1.0 : 0.0;
  if (abs(z1 - z0) < kMboitTiny) z1 = z0 - kMboitTiny;
  if (abs(z2 - z0) < kMboitTiny) z2 = z0 + kMboitTiny;
  if (abs(z2 - z1) < kMboitTiny) z2 = z1 + kMboitTiny;
  MFR_PRECISE double f01 = (f1 - f0) / (z1 - z0);
  MFR_PRECISE double f12 = (f2 - f1) / (z2 - z1);
  MFR_PRECISE double f012 = (f12 - f01) / (z2 - z0);
  // P(x) = f0 + f01 (x - z0) + f012 (x - z0)(x - z1)
  MFR_PRECISE double p2 = f012;
  MFR_PRECISE double p1 = f01 - f012 * (z0 + z1);
  MFR_PRECISE double p0 = f0 - f01 * z0 + f012 * z0 * z1;
  MFR_PRECISE double absorbance = p0 + p1 * n1 + p2 * n2;
  MFR_PRECISE double t = doubleExp(-double(b0) * absorbance);
  if (!isFiniteDouble(t)) return 1.0f;
  return float(clamp(t, 0.0, 1.0));
}

/// Pass 2: a fragment (linear colour c) weighted by ta = T(z) a: (r, g, b) += ta c, alphaSum += ta.
MFR_MATH_FN void mboitAddColor(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                               MFR_INOUT(float) alphaSum, vec3 c, float ta) {
  MFR_PRECISE float nr = r + ta * c.r;
  MFR_PRECISE float ng = g + ta * c.g;
  MFR_PRECISE float nb = b + ta * c.b;
  MFR_PRECISE float na = alphaSum + ta;
  r = nr;
  g = ng;
  b = nb;
  alphaSum = na;
}

/// The composite: T_total = exp(-b0), (1 - T_total) sum / alphaSum + T_total background.
MFR_MATH_FN vec3 mboitComposite(float b0, vec3 sum, float alphaSum, vec3 background) {
  if (b0 <= 0.0f || alphaSum <= 0.0f) return background;
  const float total = exp(-b0);
  MFR_PRECISE vec3 mixed = (1.0f - total) * sum / alphaSum + total * background;
  return mixed;
}

// ---- moment-based OIT with 2n = 4, 6 or 8 power moments ----------------------------------------
// The reconstruction of moment shadow mapping generalised as the MBOIT paper does (sec. 3.1): the
// normalised moments m_0 = 1, m_1..m_2n, biased towards the targets above, form the Hankel matrix
// B = (m_{i+j}) (n + 1 square); the kernel polynomial c with B c = (1, z, .., z^n) has n real
// roots z_1..z_n, which with z_0 = z are the support of the canonical representation; the
// polynomial through (z_0, overestimation) and (z_i, [z_i < z_0]) has the normalised absorbance in
// front of z as its expectation, sum_j p_j m_j. Everything in double; the roots by Laguerre's
// method from above the largest (it converges monotonically when every root is real, as here),
// then deflation. The 4-moment function above is the closed form of the n = 2 case and stays the
// one mboit calls.

/// The biasing target of normalised moment j (1..count) for `count` (4, 6 or 8) power moments.
MFR_MATH_FN float mboitBiasTarget(int count, int j) {
  if (j % 2 == 1) return 0.0f;
  if (count == 4) return j == 2 ? kMboitBiasTarget2 : kMboitBiasTarget4;
  if (count == 6)
    return j == 2 ? kMboit6BiasTarget2 : (j == 4 ? kMboit6BiasTarget4 : kMboit6BiasTarget6);
  return j == 2
             ? kMboit8BiasTarget2
             : (j == 4 ? kMboit8BiasTarget4 : (j == 6 ? kMboit8BiasTarget6 : kMboit8BiasTarget8));
}

/// The bias for `count` (4, 6 or 8) power moments in float32.
MFR_MATH_FN float mboitPowerBias(int count) {
  return count == 4 ? kMboitBias : (count == 6 ? kMboit6Bias : kMboit8Bias);
}

/// Pass 1 with `count` power moments: b0 += A, moments[j - 1] += A z^j (j = 1..count).
MFR_MATH_FN void mboitAddPowerMoments(int count, MFR_INOUT(float) b0,
                                      MFR_INOUT_ARRAY(float, moments, kMboitMaxMoments), float A,
                                      float z) {
  MFR_PRECISE float s0 = b0 + A;
  b0 = s0;
  MFR_PRECISE float zj = 1.0f;
  for (int j = 0; j < count; ++j) {
    MFR_PRECISE float next = zj * z;
    zj = next;
    MFR_PRECISE float sj = moments[j] + A * zj;
    moments[j] = sj;
  }
}

/// Transmittance in front of the warped depth z from b0 and moments b_1..b_count (count 4, 6 or 8;
/// not normalised), with the given bias and overestimation.
MFR_MATH_FN float mboitTransmittancePower(int count, float b0,
                                          MFR_IN_ARRAY(float, moments, kMboitMaxMoments), float z,
                                          float bias, float overestimation) {
  if (b0 <= 0.0f) return 1.0f;
  const int n = count / 2;
  const double beta = double(bias);
  // normalised, biased moments m[0..count]
  double m[9];
  m[0] = 1.0;
  for (int j = 1; j <= count; ++j)
    m[j] = (1.0 - beta) * (double(moments[j - 1]) / double(b0)) +
           beta * double(mboitBiasTarget(count, j));
  // LDL^T of the Hankel matrix B = (m[i + j]), forward and back substitution of B c = (1, .., z^n)
  const double z0 = double(z);
  double L[25];
  double D[5];
  double c[5];
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j < i; ++j) {
      MFR_PRECISE double v = m[i + j];
      for (int k = 0; k < j; ++k) v -= L[i * 5 + k] * L[j * 5 + k] * D[k];
      L[i * 5 + j] = v / D[j];
    }
    MFR_PRECISE double d = m[2 * i];
    for (int k = 0; k < i; ++k) d -= L[i * 5 + k] * L[i * 5 + k] * D[k];
    D[i] = d;
  }
  MFR_PRECISE double power = 1.0;
  for (int i = 0; i <= n; ++i) {
    MFR_PRECISE double v = power;
    for (int k = 0; k < i; ++k) v -= L[i * 5 + k] * c[k];
    c[i] = v;
    power *= z0;
  }
  for (int i = 0; i <= n; ++i) c[i] /= D[i];
  for (int i = n; i >= 0; --i)
    for (int k = i + 1; k <= n; ++k) c[i] -= L[k * 5 + i] * c[k];
  // the support: z0, then the n roots of c (largest first)
  double x[5];
  double f[5];
  x[0] = z0;
  f[0] = double(overestimation);
  double a[5];
  for (int i = 0; i <= n; ++i) a[i] = c[i];
  int degree = n;
  for (int r = 1; r <= n; ++r) {
    MFR_PRECISE double root;
    if (degree == 1) {
      root = -a[0] / a[1];
    } else {
      // Cauchy's bound: every root lies below it
      MFR_PRECISE double bound = 0.0;
      for (int i = 0; i < degree; ++i) bound = max(bound, abs(a[i] / a[degree]));
      root = 1.0 + bound;
      const double dd = double(degree);
      for (int it = 0; it < kMboitRootIterations; ++it) {
        MFR_PRECISE double value = a[degree];
        MFR_PRECISE double slope = 0.0;
        MFR_PRECISE double curve = 0.0;
        for (int i = degree - 1; i >= 0; --i) {
          curve = curve * root + slope;
          slope = slope * root + value;
          value = value * root + a[i];
        }
        if (value == 0.0) break;
        MFR_PRECISE double G = slope / value;
        MFR_PRECISE double H = G * G - 2.0 * curve / value;
        MFR_PRECISE double s = sqrt(max(0.0, (dd - 1.0) * (dd * H - G * G)));
        MFR_PRECISE double den = G >= 0.0 ? G + s : G - s;
        if (den == 0.0) break;
        MFR_PRECISE double step = dd / den;
        root -= step;
        if (abs(step) <= kMboitTiny * max(1.0, abs(root))) break;
      }
      // deflate: a / (x - root)
      MFR_PRECISE double carry = a[degree];
      for (int i = degree - 1; i >= 0; --i) {
        MFR_PRECISE double next = a[i] + carry * root;
        a[i] = carry;
        carry = next;
      }
    }
    x[r] = root;
    f[r] = root < z0 ? 1.0 : 0.0;
    degree -= 1;
  }
  // separate coincident support points (as the 4-moment closed form does)
  for (int i = 1; i <= n; ++i) {
    if (abs(x[i] - z0) < kMboitTiny) x[i] = f[i] > 0.5 ? z0 - kMboitTiny : z0 + kMboitTiny;
    for (int k = 1; k < i; ++k)
      if (abs(x[i] - x[k]) < kMboitTiny) x[i] = x[k] - kMboitTiny;
  }
  // Newton's divided differences, then the monomial coefficients p of the interpolant
  double dv[5];
  for (int i = 0; i <= n; ++i) dv[i] = f[i];
  for (int level = 1; level <= n; ++level)
    for (int i = n; i >= level; --i) dv[i] = (dv[i] - dv[i - 1]) / (x[i] - x[i - level]);
  double poly[5];
  for (int i = 0; i <= n; ++i) poly[i] = 0.0;
  poly[0] = dv[n];
  for (int k = n - 1; k >= 0; --k) {
    // poly = poly (x - x_k) + dv[k], low coefficients first (the coefficients above the degree
    // are 0; Mesa 22.3's llvmpipe miscompiled the high-first loop `i = n - k .. 1`: 0 in every
    // coefficient but the constant)
    MFR_PRECISE double carry = dv[k];
    for (int i = 0; i <= n; ++i) {
      MFR_PRECISE double old = poly[i];
      poly[i] = carry - x[k] * old;
      carry = old;
    }
  }
  MFR_PRECISE double absorbance = 0.0;
  for (int j = 0; j <= n; ++j) absorbance += poly[j] * m[j];
  MFR_PRECISE double t = doubleExp(-double(b0) * absorbance);
  if (!isFiniteDouble(t)) return 1.0f;
  return float(clamp(t, 0.0, 1.0));
}

// ---- importance (variable k-buffer) ------------------------------------------------------------

/// Eq. 3: I_d = alpha + (1 - alpha) min(1, n / N_limit); oneMinusAlpha = 1 - alpha as rounded by
/// the caller.
MFR_MATH_FN float importanceDepth(float alpha, float oneMinusAlpha, uint n, float nLimit) {
  MFR_PRECISE float id = alpha + oneMinusAlpha * min(1.0f, exactDivide(float(n), nLimit));
  return id;
}

/// Eq. 4's denominator: 1.1 sqrt(w^2 + h^2).
MFR_MATH_FN float importanceDiagonal(float width, float height) {
  MFR_PRECISE float d = kImportanceDiagonalScale * exactSqrt(width * width + height * height);
  return d;
}

/// Eq. 4 at pixel (x, y) (its centre x + 0.5, y + 0.5): I_per = 1 - (2 |p - o| / diagonal)^d;
/// exponentInt: d when an integer in [0, 64], else -1 (hostPow).
MFR_MATH_FN float importancePeriphery(uint x, uint y, vec2 fovea, float diagonal, float exponent,
                                      int exponentInt) {
  MFR_PRECISE float dx = (float(x) + 0.5f) - fovea.x;
  MFR_PRECISE float dy = (float(y) + 0.5f) - fovea.y;
  MFR_PRECISE float length2 = dx * dx + dy * dy;
  const float len = exactSqrt(length2);
  MFR_PRECISE float base = exactDivide(kImportancePeripheryScale * len, diagonal);
  MFR_PRECISE float iper = 1.0f - hostPow(base, exponent, exponentInt);
  return iper;
}

/// Eq. 5: I_f = 1 - (1 - |n.v|)^5 / 2, the cosine already clamped to [0, 1].
MFR_MATH_FN float importanceFresnel(float cosine) {
  MFR_PRECISE float ifr =
      1.0f - hostPow(1.0f - cosine, float(kImportanceFresnelPower), kImportanceFresnelPower) *
                 kImportanceFresnelScale;
  return ifr;
}

/// Eq. 6's noise term lambda (xi - 0.5).
MFR_MATH_FN float importanceNoiseTerm(float lambda, float xi) {
  MFR_PRECISE float noise = lambda * (xi - kImportanceNoiseCentre);
  return noise;
}

/// Eq. 6: I = max(0, I_per I_d I_f + noise); NaN -> 0.
MFR_MATH_FN float importanceCombine(float iper, float id, float ifr, float noise) {
  MFR_PRECISE float v = iper * id * ifr + noise;
  return v > 0.0f ? v : 0.0f;
}

// ---- texture sampling -------------------------------------------------------------------------

/// Texel index v (any int of magnitude below 2^30) of an axis of n texels wrapped into [0, n) by
/// `mode` (kTextureWrap*): repeat takes v mod n; clamp to edge takes the nearest of 0 and n - 1;
/// mirrored repeat runs 0..n-1 then n-1..0 (period 2n), as GL's MIRRORED_REPEAT. The CPU engine's
/// detail::sampleTexture and raster_common.glsl's sampleTexture both call this.
MFR_MATH_FN int wrapTexel(int v, int n, uint mode) {
  if (v >= 0 && v < n) return v;
  if (mode == kTextureWrapClamp) return v < 0 ? 0 : n - 1;
  const int period = mode == kTextureWrapMirror ? 2 * n : n;
  const int r = v >= 0 ? v % period : period - 1 - ((-v - 1) % period);
  return r < n ? r : period - 1 - r;
}

#ifdef __cplusplus
}  // namespace mfr::method_math
#endif
