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
//   AOIT: Salvi, Montgomery, Lefohn, "Adaptive Transparency", HPG 2011 (the visibility function's
//     insertion and area-based compression, the colour pass's weight); see aoit.hpp;
//   DFAOIT: Tsopouridis, Vasilakis, Fudos, "Deep and Fast Approximate Order Independent
//     Transparency", CGF 2024 (the accumulated sums, the network's inputs, the composite); see
//     dfaoit.hpp;
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
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using dvec2 = glm::dvec2;
using std::abs;
using std::clamp;
using std::exp;
using std::exp2;
using std::floor;
using std::log;
using std::log2;
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

// Multisampling's per-pixel storage (core/samples.hpp): a node's coverage mask rides in the low
// `samples` bits of its depth word; depths at and above 1 become the largest float below 1 first,
// so that the unsigned order of the words stays the order of the depths
MFR_MATH_CONST(uint, kLargestDepthBelowOne, 0x3f7fffffu)

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
// MBOIT with 3 and 4 trigonometric moments (the paper's sec. 3.2): the bias for float32 storage
// from the paper's supplementary table (2, 3, 4 trigonometric moments: 4e-7, 8e-7, 1.5e-6; the
// values PixelSyncOIT's OIT_MBOIT.cpp records beside its own settings); the wrapping zone of
// angle pi / 10 (the authors' default, momentsingraphics.de "A brief postscript on MBOIT",
// 2018, which gives their computeWrappingZoneParameters): a warped depth z in [-1, 1] maps to the
// phase (z + 1) (pi - angle / 2) in [0, 2 pi - angle]; a support point whose circle parameter
// (mboitCircleParameter, in [0, 8)) lies in the zone [zone begin, 7] adds a linear ramp
// kMboitTrigZoneSlope x + kMboitTrigZoneOffset to its weight. The constants are those of the
// authors' function for that angle: phase scale pi - pi / 20, zone begin = 6 + cos(pi / 10) -
// sin(pi / 10), slope 1 / (7 - begin), offset 1 - 7 slope.
MFR_MATH_CONST(float, kMboitTrig3Bias, 8e-7f)
MFR_MATH_CONST(float, kMboitTrig4Bias, 1.5e-6f)
MFR_MATH_CONST(float, kMboitTrigPhaseScale, 2.9845130209103035f)
MFR_MATH_CONST(float, kMboitTrigZoneSlope, 2.7936044933348416f)
MFR_MATH_CONST(float, kMboitTrigZoneOffset, -18.555231453343893f)
// pi in double: the float nearest pi less its (float-rounded) excess, the same double on both
// sides (within 4e-15 of pi)
MFR_MATH_CONST(double, kMboitPi, double(3.14159274f) - double(8.74227766e-8f))
// terms of the sine and cosine series (|t| <= pi: the next term is below 1e-18)
MFR_MATH_CONST(int, kMboitSeriesTerms, 16)
// MBOIT's 16-bit storage (the paper's sec. 4 and supplementary; the authors' MomentMath.hlsli
// quantizeMoments / offsetMoments, as published with the paper under CC0): the normalised power
// moments, split into the odd (z, z^3, ..) and even (z^2, z^4, ..) vectors, are stored in the
// basis Q v (column convention; the authors write 4 and 6 moments as v Q^T) plus an offset, which
// puts every moment vector of a single depth into [0, 1] for UNORM16 storage; b0 stays float32.
// Trigonometric moments are stored as b / b0 / 2 + 1/2. The bias for 16-bit storage, from the
// supplementary's table (as recorded in PixelSyncOIT's OIT_MBOIT.cpp): 4, 6, 8 power moments
// 6e-5, 6e-4, 2.5e-3; 3 and 4 trigonometric moments 6.5e-4 and 8.5e-4.
#define MFR_MBOIT_Q4_ODD 1.5f, -2.0f, 0.866025403784f, -0.384900179460f
#define MFR_MBOIT_Q4_EVEN 4.0f, -4.0f, 0.5f, 0.5f
#define MFR_MBOIT_Q6_ODD                                                                \
  2.5f, -10.0f, 8.0f, -1.87499864450f, 4.20757543111f, -1.83257678661f, 1.26583039016f, \
      -1.47644882902f, 0.71061660238f
#define MFR_MBOIT_Q6_EVEN \
  4.0f, -4.0f, 0.0f, 9.0f, -24.0f, 16.0f, -0.57759806484f, 4.61936647543f, -3.07953906655f
#define MFR_MBOIT_Q8_ODD                                                                           \
  3.48044635732474f, -27.5760737514826f, 55.1267384344761f, -31.5311110403183f, 1.26797185782836f, \
      -0.928755808743913f, -2.07520453231032f, 1.23598848322588f, -2.1671560004294f,               \
      6.17950199592966f, -0.276515571579297f, -4.23583042392097f, 0.974332879165755f,              \
      -0.443426830933027f, -0.360491648368785f, 0.310149466050223f
#define MFR_MBOIT_Q8_EVEN                                                            \
  0.280504133158527f, -0.757633844606942f, 0.392179589334688f, -0.887531871812237f,  \
      -2.01362265883247f, 0.221551373038988f, -1.06107954265125f, 2.83887201588367f, \
      -7.31010494985321f, 13.9855979699139f, -0.114305766176437f, -7.4361899359832f, \
      -15.8954215629556f, 79.6186327084103f, -127.457278992502f, 63.7349456687829f
#define MFR_MBOIT_Q8_EVEN_OFFSET 0.972481993925964f, 1.0f, 0.999179192513328f, 0.991778293073131f
#ifdef __cplusplus
inline constexpr float kMboitQ4Odd[4] = {MFR_MBOIT_Q4_ODD};
inline constexpr float kMboitQ4Even[4] = {MFR_MBOIT_Q4_EVEN};
inline constexpr float kMboitQ6Odd[9] = {MFR_MBOIT_Q6_ODD};
inline constexpr float kMboitQ6Even[9] = {MFR_MBOIT_Q6_EVEN};
inline constexpr float kMboitQ8Odd[16] = {MFR_MBOIT_Q8_ODD};
inline constexpr float kMboitQ8Even[16] = {MFR_MBOIT_Q8_EVEN};
inline constexpr float kMboitQ8EvenOffset[4] = {MFR_MBOIT_Q8_EVEN_OFFSET};
#else
const float kMboitQ4Odd[4] = float[4](MFR_MBOIT_Q4_ODD);
const float kMboitQ4Even[4] = float[4](MFR_MBOIT_Q4_EVEN);
const float kMboitQ6Odd[9] = float[9](MFR_MBOIT_Q6_ODD);
const float kMboitQ6Even[9] = float[9](MFR_MBOIT_Q6_EVEN);
const float kMboitQ8Odd[16] = float[16](MFR_MBOIT_Q8_ODD);
const float kMboitQ8Even[16] = float[16](MFR_MBOIT_Q8_EVEN);
const float kMboitQ8EvenOffset[4] = float[4](MFR_MBOIT_Q8_EVEN_OFFSET);
#endif
MFR_MATH_CONST(float, kMboitQ6EvenOffset3, 0.018888946f)
MFR_MATH_CONST(float, kMboit16Bias, 6e-5f)
MFR_MATH_CONST(float, kMboit6_16Bias, 6e-4f)
MFR_MATH_CONST(float, kMboit8_16Bias, 2.5e-3f)
MFR_MATH_CONST(float, kMboitTrig3_16Bias, 6.5e-4f)
MFR_MATH_CONST(float, kMboitTrig4_16Bias, 8.5e-4f)
MFR_MATH_CONST(float, kUnorm16Max, 65535.0f)
// Laguerre's iteration for the support points: at most this many steps per root
MFR_MATH_CONST(int, kMboitRootIterations, 64)
// 1e-12 (GLSL has no token pasting for an `lf` suffix: the correctly rounded quotient of exact
// integers is the same double as the literal)
MFR_MATH_CONST(double, kMboitTiny, double(1) / (double(1000000) * double(1000000)))

// Adaptive transparency (Salvi, Montgomery, Lefohn 2011): the most nodes a preset keeps (aoit16)
// and the depth of an unused node, beyond every window depth in [0, 1] (the authors keep unused
// nodes at a far depth too; their value is the largest float, any depth above 1 works alike)
MFR_MATH_CONST(int, kAoitMaxNodes, 16)
MFR_MATH_CONST(float, kAoitEmptyDepth, 3.0e38f)

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
/// The high word of the 64-bit product a b (GLSL: umulExtended).
inline uint mulHigh32(uint a, uint b) {
  return static_cast<uint>((static_cast<uint64_t>(a) * b) >> 32);
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
uint mulHigh32(uint a, uint b) {
  uint hi, lo;
  umulExtended(a, b, hi, lo);
  return hi;
}
#endif

// ---- k-buffer family: front-to-back "over" and the hybrid tail ---------------------------------

/// The low `samples` bits of a word (a coverage mask of that many samples).
MFR_MATH_FN uint sampleBits(int samples) {
  return (1u << uint(samples)) - 1u;
}

/// A depth word (the float's bits) carrying the coverage mask `mask` of `samples` samples in its
/// low bits (per-pixel multisampled storage; see kLargestDepthBelowOne).
MFR_MATH_FN uint withCoverageBits(uint depthBits, uint mask, int samples) {
  const uint low = sampleBits(samples);
  const uint bits = depthBits > kLargestDepthBelowOne ? kLargestDepthBelowOne : depthBits;
  return (bits & ~low) | (mask & low);
}

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

// ---- blend modes: the node's alpha byte says its kind (core/color.hpp packBlendedColor) -------
MFR_MATH_CONST(uint, kAdditiveNode, 0u)  // rgb: the emission, added times T
MFR_MATH_CONST(uint, kMultiplyNode, 1u)  // rgb: the factor, multiplied into T per channel

/// One front-to-back step of a sorted node of any kind (alpha byte a8, its alpha a = a8 / 255 as
/// the caller computes it, decoded linear colour c)
/// onto the colour sum (r, g, b) and the per-channel transmittance (tr, tg, tb) in front of it:
///   over (a8 >= 2, a = a8 / 255):  (r, g, b) += c a T,  T *= 1 - a   (overStep per channel)
///   additive (a8 = 0):             (r, g, b) += c T
///   multiply (a8 = 1):             T *= c
/// With equal channels of T and over nodes only, every channel is overStep's operations.
MFR_MATH_FN void blendStep(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                           MFR_INOUT(float) tr, MFR_INOUT(float) tg, MFR_INOUT(float) tb, uint a8,
                           float a, float cr, float cg, float cb) {
  if (a8 == kAdditiveNode) {
    MFR_PRECISE float nr = r + cr * tr;
    MFR_PRECISE float ng = g + cg * tg;
    MFR_PRECISE float nb = b + cb * tb;
    r = nr;
    g = ng;
    b = nb;
  } else if (a8 == kMultiplyNode) {
    MFR_PRECISE float nr = tr * cr;
    MFR_PRECISE float ng = tg * cg;
    MFR_PRECISE float nb = tb * cb;
    tr = nr;
    tg = ng;
    tb = nb;
  } else {
    MFR_PRECISE float wr = a * tr;
    MFR_PRECISE float wg = a * tg;
    MFR_PRECISE float wb = a * tb;
    MFR_PRECISE float nr = r + cr * wr;
    MFR_PRECISE float ng = g + cg * wg;
    MFR_PRECISE float nb = b + cb * wb;
    MFR_PRECISE float ntr = tr * (1.0f - a);
    MFR_PRECISE float ntg = tg * (1.0f - a);
    MFR_PRECISE float ntb = tb * (1.0f - a);
    r = nr;
    g = ng;
    b = nb;
    tr = ntr;
    tg = ntg;
    tb = ntb;
  }
}

/// blendStep with one transmittance for the methods that keep one (depth peeling): over and
/// additive nodes (a multiply node is not reached: those methods refuse multiply materials,
/// method/blend_support.hpp).
MFR_MATH_FN void blendStepScalar(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                                 MFR_INOUT(float) T, uint a8, float a, float cr, float cg,
                                 float cb) {
  if (a8 == kAdditiveNode) {
    MFR_PRECISE float nr = r + cr * T;
    MFR_PRECISE float ng = g + cg * T;
    MFR_PRECISE float nb = b + cb * T;
    r = nr;
    g = ng;
    b = nb;
  } else {
    overStep(r, g, b, T, a, cr, cg, cb);
  }
}

/// underStep (back to front) of a node of any kind but multiply: an additive node adds its
/// emission in front of what lies behind, (r, g, b) += c, T unchanged.
MFR_MATH_FN void blendUnderStepScalar(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                                      MFR_INOUT(float) T, uint a8, float a, float cr, float cg,
                                      float cb) {
  if (a8 == kAdditiveNode) {
    MFR_PRECISE float nr = cr + r;
    MFR_PRECISE float ng = cg + g;
    MFR_PRECISE float nb = cb + b;
    r = nr;
    g = ng;
    b = nb;
  } else {
    underStep(r, g, b, T, a, cr, cg, cb);
  }
}

/// overBackground with a per-channel transmittance.
MFR_MATH_FN vec3 overBackground(vec3 color, vec3 T, vec3 behind) {
  MFR_PRECISE vec3 result = color + T * behind;
  return result;
}

// ---- multisampled per-pixel storage: each sample from the nodes that cover it ------------------

/// The front-to-back sums of a pixel's samples (per-pixel multisampled storage, core/samples.hpp):
/// sample i composites the sorted nodes whose coverage mask holds bit i; one sum (every node)
/// with `samples` 1.
MFR_MATH_CONST(int, kMaxSampleSums, 8)
struct SampleSums {
  float r[kMaxSampleSums], g[kMaxSampleSums], b[kMaxSampleSums];
  float tr[kMaxSampleSums], tg[kMaxSampleSums], tb[kMaxSampleSums];
  int samples;
};

MFR_MATH_FN SampleSums emptySampleSums(int samples) {
  SampleSums s;
  s.samples = samples > 1 ? samples : 1;
  for (int i = 0; i < kMaxSampleSums; ++i) {
    s.r[i] = 0.0f;
    s.g[i] = 0.0f;
    s.b[i] = 0.0f;
    s.tr[i] = 1.0f;
    s.tg[i] = 1.0f;
    s.tb[i] = 1.0f;
  }
  return s;
}

/// blendStep of the next sorted node (its depth word, which carries the mask, and its colour)
/// onto each sample it covers.
MFR_MATH_FN void blendSampleNode(MFR_INOUT(SampleSums) s, uint depthBits, uint a8, float a,
                                 float cr, float cg, float cb) {
  for (int i = 0; i < s.samples; ++i)
    if (s.samples == 1 || ((depthBits >> uint(i)) & 1u) != 0u)
      blendStep(s.r[i], s.g[i], s.b[i], s.tr[i], s.tg[i], s.tb[i], a8, a, cr, cg, cb);
}

/// Each sample's sum over what lies behind (the background, or the hybrid tail over it), then the
/// mean of the samples (the box filter).
MFR_MATH_FN vec3 resolveSampleSums(SampleSums s, vec3 behind) {
  if (s.samples == 1)
    return overBackground(vec3(s.r[0], s.g[0], s.b[0]), vec3(s.tr[0], s.tg[0], s.tb[0]), behind);
  vec3 sum = vec3(0.0f);
  for (int i = 0; i < s.samples; ++i) {
    MFR_PRECISE vec3 next =
        sum + overBackground(vec3(s.r[i], s.g[i], s.b[i]), vec3(s.tr[i], s.tg[i], s.tb[i]), behind);
    sum = next;
  }
  MFR_PRECISE vec3 mean = sum / float(s.samples);
  return mean;
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

/// hybridTailAdd of a node of any kind but multiply (refused under hybrid compositing, method/
/// blend_support.hpp): an additive node adds its emission to the colour sum and nothing to the
/// alpha sum, so hybridBehind weights it like the tail's over fragments (alpha_tail / sum(a)).
MFR_MATH_FN void hybridTailAddNode(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                                   MFR_INOUT(float) alphaSum, MFR_INOUT(uint) count, uint a8,
                                   float a, float cr, float cg, float cb) {
  if (a8 == kAdditiveNode) {
    MFR_PRECISE float nr = r + cr;
    MFR_PRECISE float ng = g + cg;
    MFR_PRECISE float nb = b + cb;
    r = nr;
    g = ng;
    b = nb;
    count = count + 1u;
  } else {
    hybridTailAdd(r, g, b, alphaSum, count, a, cr, cg, cb);
  }
}

/// hybridTailAddNode of a node of per-pixel multisampled storage (core/samples.hpp), whose
/// triangle covers `share` of the pixel's samples (the covered count over the sample count): its
/// alpha, or an additive node's emission, weighted by that share, into the pixel's one tail.
MFR_MATH_FN void hybridTailAddCovered(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                                      MFR_INOUT(float) alphaSum, MFR_INOUT(uint) count, uint a8,
                                      float a, float cr, float cg, float cb, float share) {
  if (a8 == kAdditiveNode) {
    MFR_PRECISE float sr = cr * share;
    MFR_PRECISE float sg = cg * share;
    MFR_PRECISE float sb = cb * share;
    hybridTailAddNode(r, g, b, alphaSum, count, a8, a, sr, sg, sb);
  } else {
    MFR_PRECISE float sa = a * share;
    hybridTailAddNode(r, g, b, alphaSum, count, a8, sa, cr, cg, cb);
  }
}

/// What lies behind the sorted core in the hybrid rule: the tail (C_tail = sum(a c) / sum(a),
/// a_avg = sum(a) / t, alpha_tail = 1 - (1 - a_avg)^t) over the background; the background alone
/// when the tail is empty. pow: std::pow on the host, GLSL's pow (exp2(y log2 x)) on the GPU, so
/// the last bits of a non-empty tail may differ between the engines.
MFR_MATH_FN vec3 hybridBehind(vec3 tailSum, float tailAlphaSum, uint tailCount, vec3 background) {
  if (tailCount == 0u) return background;
  if (tailAlphaSum <= 0.0f) {  // additive nodes only (or invisible ones): their emission, in front
    MFR_PRECISE vec3 lit = background + tailSum;
    return lit;
  }
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

// ---- moment-based OIT with n = 3 or 4 trigonometric moments -------------------------------------
// The paper's sec. 3.2: the moments b_k = sum_i A_i e^(i k phi_i) (k = 1..n, stored as their real
// and imaginary parts, float32) of the absorbance on the unit circle; the reconstruction is that
// of the authors' TrigonometricMomentMath: the normalised moments scaled by 1 - bias form the
// Hermitian Toeplitz matrix T = (b_(i - j)) (n + 1 square, b_(-k) = conj(b_k)); its LDL^H
// factorisation solves T c = (1, w, .., w^n) at the query point w = e^(i phi); the polynomial
// sum_k conj(c_k) x^k has n roots on the unit circle, which with w carry the canonical
// representation; the polynomial through (w, overestimation) and (root, weight of the root: 1 in
// front of w by the circle parameter, plus the wrapping zone's ramp) has the normalised absorbance
// in front of w as its expectation Re sum_k p_k b_k. Everything in double (complex numbers as
// dvec2); the roots by the Weierstrass (Durand-Kerner) iteration; e^(i phi) by the series below,
// the same double operations on both sides.

MFR_MATH_FN dvec2 complexMul(dvec2 a, dvec2 b) {
  MFR_PRECISE double re = a.x * b.x - a.y * b.y;
  MFR_PRECISE double im = a.x * b.y + a.y * b.x;
  return dvec2(re, im);
}

MFR_MATH_FN dvec2 complexDiv(dvec2 a, dvec2 b) {
  MFR_PRECISE double n = b.x * b.x + b.y * b.y;
  MFR_PRECISE double re = (a.x * b.x + a.y * b.y) / n;
  MFR_PRECISE double im = (a.y * b.x - a.x * b.y) / n;
  return dvec2(re, im);
}

MFR_MATH_FN dvec2 complexConj(dvec2 a) {
  return dvec2(a.x, -a.y);
}

/// e^(i phase) for phase in [0, 2 pi]: the series of cos and sin of phase - pi, negated.
MFR_MATH_FN dvec2 mboitCircle(double phase) {
  MFR_PRECISE double t = phase - kMboitPi;
  MFR_PRECISE double t2 = t * t;
  MFR_PRECISE double c = 1.0;
  MFR_PRECISE double s = t;
  MFR_PRECISE double termC = 1.0;
  MFR_PRECISE double termS = t;
  for (int k = 1; k <= kMboitSeriesTerms; ++k) {
    const double twoK = double(2 * k);
    termC = -termC * t2 / ((twoK - 1.0) * twoK);
    termS = -termS * t2 / (twoK * (twoK + 1.0));
    c += termC;
    s += termS;
  }
  return dvec2(-c, -s);
}

/// The phase of the warped depth z: (z + 1) kMboitTrigPhaseScale.
MFR_MATH_FN double mboitTrigPhase(float z) {
  MFR_PRECISE double phase = (double(z) + 1.0) * double(kMboitTrigPhaseScale);
  return phase;
}

/// The authors' circleToParameter: grows monotonically with the angle of the unit vector p over
/// [0, 2 pi), in [0, 8).
MFR_MATH_FN double mboitCircleParameter(dvec2 p) {
  MFR_PRECISE double r = abs(p.y) - abs(p.x);
  r = p.x < 0.0 ? 2.0 - r : r;
  r = p.y < 0.0 ? 6.0 - r : r;
  return r;
}

/// The bias for `count` (3 or 4) trigonometric moments in float32.
MFR_MATH_FN float mboitTrigBias(int count) {
  return count == 3 ? kMboitTrig3Bias : kMboitTrig4Bias;
}

/// Pass 1 with `count` (3 or 4) trigonometric moments: b0 += A, moments[2k - 2] += A cos(k phi),
/// moments[2k - 1] += A sin(k phi) (k = 1..count), phi the phase of z.
MFR_MATH_FN void mboitAddTrigMoments(int count, MFR_INOUT(float) b0,
                                     MFR_INOUT_ARRAY(float, moments, kMboitMaxMoments), float A,
                                     float z) {
  MFR_PRECISE float s0 = b0 + A;
  b0 = s0;
  const dvec2 w = mboitCircle(mboitTrigPhase(z));
  dvec2 wk = w;
  for (int k = 0; k < count; ++k) {
    MFR_PRECISE float re = moments[2 * k] + A * float(wk.x);
    MFR_PRECISE float im = moments[2 * k + 1] + A * float(wk.y);
    moments[2 * k] = re;
    moments[2 * k + 1] = im;
    wk = complexMul(wk, w);
  }
}

/// Transmittance in front of the warped depth z from b0 and `count` (3 or 4) trigonometric
/// moments (not normalised; real and imaginary parts), with the given bias and overestimation.
MFR_MATH_FN float mboitTransmittanceTrig(int count, float b0,
                                         MFR_IN_ARRAY(float, moments, kMboitMaxMoments), float z,
                                         float bias, float overestimation) {
  if (b0 <= 0.0f) return 1.0f;
  const int n = count;
  const double scale = 1.0 - double(bias);
  // the normalised, scaled moments b[0..n], b[0] = 1
  dvec2 b[5];
  b[0] = dvec2(1.0, 0.0);
  for (int k = 1; k <= n; ++k)
    b[k] = dvec2(double(moments[2 * k - 2]) / double(b0) * scale,
                 double(moments[2 * k - 1]) / double(b0) * scale);
  // LDL^H of the Toeplitz matrix T[i][j] = b[i - j] (i >= j): L[i][j] for j < i, D[i] real
  dvec2 L[25];
  double D[5];
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j < i; ++j) {
      dvec2 v = b[i - j];
      for (int k = 0; k < j; ++k) v -= D[k] * complexMul(L[i * 5 + k], complexConj(L[j * 5 + k]));
      L[i * 5 + j] = v / D[j];
    }
    MFR_PRECISE double d = 1.0;
    for (int k = 0; k < i; ++k) {
      const dvec2 l = L[i * 5 + k];
      d -= D[k] * (l.x * l.x + l.y * l.y);
    }
    D[i] = d;
  }
  // solve T c = (1, w, .., w^n): L y = e, then D, then L^H c = D^-1 y
  const dvec2 w = mboitCircle(mboitTrigPhase(z));
  dvec2 c[5];
  dvec2 power = dvec2(1.0, 0.0);
  for (int i = 0; i <= n; ++i) {
    dvec2 v = power;
    for (int k = 0; k < i; ++k) v -= complexMul(L[i * 5 + k], c[k]);
    c[i] = v;
    power = complexMul(power, w);
  }
  for (int i = 0; i <= n; ++i) c[i] /= D[i];
  for (int i = n; i >= 0; --i)
    for (int k = i + 1; k <= n; ++k) c[i] -= complexMul(complexConj(L[k * 5 + i]), c[k]);
  // the roots of sum_k conj(c_k) x^k, monic: a_k = conj(c_k) / conj(c_n)
  dvec2 a[5];
  for (int k = 0; k <= n; ++k) a[k] = complexDiv(complexConj(c[k]), complexConj(c[n]));
  dvec2 x[5];
  x[0] = w;
  const dvec2 seed = dvec2(0.375, 0.875);  // exact in float: the same double on both sides
  dvec2 guess = seed;
  for (int r = 1; r <= n; ++r) {
    x[r] = guess;
    guess = complexMul(guess, seed);
  }
  for (int it = 0; it < kMboitRootIterations; ++it) {
    MFR_PRECISE double largest = 0.0;
    for (int r = 1; r <= n; ++r) {
      // p(x_r) / prod_(s != r) (x_r - x_s)
      dvec2 value = a[n];
      for (int k = n - 1; k >= 0; --k) value = complexMul(value, x[r]) + a[k];
      dvec2 den = dvec2(1.0, 0.0);
      for (int s = 1; s <= n; ++s)
        if (s != r) den = complexMul(den, x[r] - x[s]);
      if (den.x == 0.0 && den.y == 0.0) continue;
      const dvec2 step = complexDiv(value, den);
      x[r] -= step;
      largest = max(largest, abs(step.x) + abs(step.y));
    }
    if (largest <= kMboitTiny) break;
  }
  // the weights: overestimation at w, 1 for a root in front of w, plus the wrapping zone's ramp
  double f[5];
  f[0] = double(overestimation);
  const double reference = mboitCircleParameter(w);
  for (int r = 1; r <= n; ++r) {
    const double parameter = mboitCircleParameter(x[r]);
    MFR_PRECISE double ramp =
        parameter * double(kMboitTrigZoneSlope) + double(kMboitTrigZoneOffset);
    f[r] = (parameter < reference ? 1.0 : 0.0) + clamp(ramp, 0.0, 1.0);
  }
  // separate coincident support points
  for (int r = 1; r <= n; ++r)
    for (int s = 0; s < r; ++s) {
      const dvec2 d = x[r] - x[s];
      if (abs(d.x) + abs(d.y) < kMboitTiny) x[r] += dvec2(kMboitTiny, kMboitTiny);
    }
  // Newton's divided differences (complex), then the monomial coefficients of the interpolant
  dvec2 dv[5];
  for (int i = 0; i <= n; ++i) dv[i] = dvec2(f[i], 0.0);
  for (int level = 1; level <= n; ++level)
    for (int i = n; i >= level; --i) dv[i] = complexDiv(dv[i] - dv[i - 1], x[i] - x[i - level]);
  dvec2 poly[5];
  for (int i = 0; i <= n; ++i) poly[i] = dvec2(0.0, 0.0);
  poly[0] = dv[n];
  for (int k = n - 1; k >= 0; --k) {
    // poly = poly (x - x_k) + dv[k], low coefficients first (see mboitTransmittancePower)
    dvec2 carry = dv[k];
    for (int i = 0; i <= n; ++i) {
      const dvec2 old = poly[i];
      poly[i] = carry - complexMul(x[k], old);
      carry = old;
    }
  }
  MFR_PRECISE double absorbance = 0.0;
  for (int k = 0; k <= n; ++k) absorbance += complexMul(b[k], poly[k]).x;
  MFR_PRECISE double t = doubleExp(-double(b0) * absorbance);
  if (!isFiniteDouble(t)) return 1.0f;
  return float(clamp(t, 0.0, 1.0));
}

// ---- adaptive transparency (AOIT) ---------------------------------------------------------------
// Salvi, Montgomery, Lefohn, "Adaptive Transparency", HPG 2011. Per pixel n nodes (depth d_i,
// transmittance T_i), sorted by depth; T_i is the transmittance just behind d_i; unused nodes sit
// at kAoitEmptyDepth and carry the pixel's total transmittance (so node n - 1 always holds it). The
// working arrays have room for n + 1 nodes (kAoitMaxNodes + 1): the insertion may make n + 1, the
// compression brings them back to n.

/// Inserts a fragment (depth z, transmittance t = 1 - alpha) into nodes 0..n-1:
/// its node goes at the first node not strictly in front of it (an equal depth: in front of the
/// nodes already there) with T = T(node before) t, and every node behind it is multiplied by t.
/// When that makes n + 1 used nodes, the node i in 1..n whose removal changes the area under the
/// visibility curve least, (d_i - d_{i-1}) (T_{i-1} - T_i), is removed: node i - 1 takes T_i (the
/// step moves forward to d_{i-1}: visibility is only ever under-, never overestimated, and the
/// total transmittance is kept); the nearest node is never removed; ties go to the smallest i.
MFR_MATH_FN void aoitInsert(int n, MFR_INOUT_ARRAY(float, depth, kAoitMaxNodes + 1),
                            MFR_INOUT_ARRAY(float, trans, kAoitMaxNodes + 1), float z, float t) {
  int index = 0;
  float before = 1.0f;
  for (int i = 0; i < n; ++i) {
    if (z > depth[i]) {
      index = i + 1;
      before = trans[i];
    }
  }
  for (int i = n - 1; i >= index; --i) {
    MFR_PRECISE float behind = trans[i] * t;
    depth[i + 1] = depth[i];
    trans[i + 1] = behind;
  }
  MFR_PRECISE float own = before * t;
  depth[index] = z;
  trans[index] = own;
  if (depth[n] == kAoitEmptyDepth) return;
  int removed = 1;
  MFR_PRECISE float least = (depth[1] - depth[0]) * (trans[0] - trans[1]);
  for (int i = 2; i <= n; ++i) {
    MFR_PRECISE float area = (depth[i] - depth[i - 1]) * (trans[i - 1] - trans[i]);
    if (area < least) {
      least = area;
      removed = i;
    }
  }
  trans[removed - 1] = trans[removed];
  for (int i = removed; i < n; ++i) {
    depth[i] = depth[i + 1];
    trans[i] = trans[i + 1];
  }
}

/// Visibility in front of depth z: T of the farthest node strictly in front of z, 1 if none (a
/// fragment at a node's depth is not attenuated by that node: equal depths do not occlude each
/// other).
MFR_MATH_FN float aoitVisibility(int n, MFR_IN_ARRAY(float, depth, kAoitMaxNodes + 1),
                                 MFR_IN_ARRAY(float, trans, kAoitMaxNodes + 1), float z) {
  float vis = 1.0f;
  for (int i = 0; i < n; ++i) {
    if (z > depth[i]) vis = trans[i];
  }
  return vis;
}

/// Pass 2: the fragment's premultiplied colour weighted by its visibility, (r, g, b) += vis a c.
MFR_MATH_FN void aoitAddColor(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b, vec3 c,
                              float a, float vis) {
  MFR_PRECISE float w = vis * a;
  MFR_PRECISE float nr = r + c.r * w;
  MFR_PRECISE float ng = g + c.g * w;
  MFR_PRECISE float nb = b + c.b * w;
  r = nr;
  g = ng;
  b = nb;
}

/// The composite: the weighted sum plus the total transmittance (the last node's) times the
/// background.
MFR_MATH_FN vec3 aoitComposite(vec3 sum, float total, vec3 background) {
  MFR_PRECISE vec3 result = sum + total * background;
  return result;
}

// ---- deep and fast approximate OIT (DFAOIT) ---------------------------------------------------
// Tsopouridis, Vasilakis, Fudos, "Deep and Fast Approximate Order Independent Transparency", CGF
// 2024 (dfaoit.hpp): one pass of order-independent sums per pixel, the 12 network inputs built
// from them, the composite of the nearest fragment over the predicted colour behind it. The
// network itself (12-32-32-3) is dfaoit.hpp's dfaoitForward and dfaoit_resolve.comp's loop (its
// weights are a buffer on GL).
MFR_MATH_CONST(int, kDfaoitInputs, 12)
MFR_MATH_CONST(int, kDfaoitHidden, 32)
MFR_MATH_CONST(int, kDfaoitOutputs, 3)

/// One fragment (linear colour c, alpha a, window depth z) into the sums: (r, g, b) += a c,
/// alphaSum += a, alphaDepth += a z, (rz, gz, bz) += a c z, T *= 1 - a.
MFR_MATH_FN void dfaoitAccumulate(MFR_INOUT(float) r, MFR_INOUT(float) g, MFR_INOUT(float) b,
                                  MFR_INOUT(float) alphaSum, MFR_INOUT(float) alphaDepth,
                                  MFR_INOUT(float) rz, MFR_INOUT(float) gz, MFR_INOUT(float) bz,
                                  MFR_INOUT(float) T, vec3 c, float a, float z) {
  MFR_PRECISE float pr = a * c.r;
  MFR_PRECISE float pg = a * c.g;
  MFR_PRECISE float pb = a * c.b;
  MFR_PRECISE float nr = r + pr;
  MFR_PRECISE float ng = g + pg;
  MFR_PRECISE float nb = b + pb;
  MFR_PRECISE float na = alphaSum + a;
  MFR_PRECISE float az = a * z;
  MFR_PRECISE float nad = alphaDepth + az;
  MFR_PRECISE float prz = pr * z;
  MFR_PRECISE float pgz = pg * z;
  MFR_PRECISE float pbz = pb * z;
  MFR_PRECISE float nrz = rz + prz;
  MFR_PRECISE float ngz = gz + pgz;
  MFR_PRECISE float nbz = bz + pbz;
  MFR_PRECISE float nT = T * (1.0f - a);
  r = nr;
  g = ng;
  b = nb;
  alphaSum = na;
  alphaDepth = nad;
  rz = nrz;
  gz = ngz;
  bz = nbz;
  T = nT;
}

/// Where a channel's colour sits in depth against the alpha: (sum a c z / sum a c - zbar) / range,
/// clamped to [-1, 1]; 0 without colour or range.
MFR_MATH_FN float dfaoitSkew(float colourDepth, float colour, float zbar, float range) {
  if (!(colour > 0.0f) || !(range > 0.0f)) return 0.0f;
  MFR_PRECISE float zc = exactDivide(colourDepth, colour);
  MFR_PRECISE float skew = zc - zbar;
  return clamp(exactDivide(skew, range), -1.0f, 1.0f);
}

/// The 12 network inputs of a pixel with n >= 1 fragments of positive alpha. They describe the
/// fragments behind the nearest one (the "rest": the sums less the nearest fragment's own terms,
/// a0 c0, a0, a0 z0, a0 c0 z0, computed as dfaoitAccumulate computes them), whose
/// visibility-weighted mean colour the network predicts (dfaoitComposite):
///   x0-2   the rest's alpha-weighted mean colour sum' a c / sum' a   (0 when sum' a <= 0)
///   x3-5   per channel, where the rest's colour sits in depth against its alpha: dfaoitSkew of
///          sum' a c z, sum' a c, zbar' = sum' a z / sum' a, range = z_far - z_near
///   x6     (zbar' - z_near) / range, clamped to [0, 1] (0 without range)
///   x7     the rest's opacity 1 - T / (1 - a0)   (0 when a0 = 1)
///   x8     the rest's mean alpha sum' a / (n - 1)   (0 when n = 1)
///   x9     1 / (n - 1)                              (0 when n = 1)
///   x10    the pixel's opacity 1 - T
///   x11    the nearest fragment's alpha a0
/// Divisions are exactDivide (correctly rounded on both sides).
MFR_MATH_FN void dfaoitFeatures(vec3 sum, float alphaSum, float alphaDepth, vec3 colourDepth,
                                float T, uint n, float nearDepth, vec3 nearColour, float nearAlpha,
                                float farDepth, MFR_INOUT_ARRAY(float, x, kDfaoitInputs)) {
  MFR_PRECISE float pr = nearAlpha * nearColour.r;
  MFR_PRECISE float pg = nearAlpha * nearColour.g;
  MFR_PRECISE float pb = nearAlpha * nearColour.b;
  MFR_PRECISE float restR = sum.r - pr;
  MFR_PRECISE float restG = sum.g - pg;
  MFR_PRECISE float restB = sum.b - pb;
  MFR_PRECISE float restA = alphaSum - nearAlpha;
  MFR_PRECISE float az = nearAlpha * nearDepth;
  MFR_PRECISE float restAz = alphaDepth - az;
  MFR_PRECISE float prz = pr * nearDepth;
  MFR_PRECISE float pgz = pg * nearDepth;
  MFR_PRECISE float pbz = pb * nearDepth;
  MFR_PRECISE float restRz = colourDepth.r - prz;
  MFR_PRECISE float restGz = colourDepth.g - pgz;
  MFR_PRECISE float restBz = colourDepth.b - pbz;
  MFR_PRECISE float range = farDepth - nearDepth;
  for (int i = 0; i < kDfaoitInputs; ++i) x[i] = 0.0f;
  if (n > 1u && restA > 0.0f) {
    x[0] = clamp(exactDivide(restR, restA), 0.0f, 1.0f);
    x[1] = clamp(exactDivide(restG, restA), 0.0f, 1.0f);
    x[2] = clamp(exactDivide(restB, restA), 0.0f, 1.0f);
    MFR_PRECISE float zbar = exactDivide(restAz, restA);
    x[3] = dfaoitSkew(restRz, restR, zbar, range);
    x[4] = dfaoitSkew(restGz, restG, zbar, range);
    x[5] = dfaoitSkew(restBz, restB, zbar, range);
    if (range > 0.0f) {
      MFR_PRECISE float front = zbar - nearDepth;
      x[6] = clamp(exactDivide(front, range), 0.0f, 1.0f);
    }
    MFR_PRECISE float behind = 1.0f - nearAlpha;
    if (behind > 0.0f) x[7] = clamp(1.0f - exactDivide(T, behind), 0.0f, 1.0f);
    MFR_PRECISE float rest = float(n - 1u);
    x[8] = exactDivide(restA, rest);
    x[9] = exactDivide(1.0f, rest);
  }
  x[10] = 1.0f - T;
  x[11] = nearAlpha;
}

/// The composite: the nearest fragment over the rest, whose colour is the predicted
/// visibility-weighted mean y of the fragments behind it times their share of the coverage,
/// (1 - a0) - T, over the background by the exact transmittance:
///   a0 c0 + max(0, (1 - a0) - T) y + T background.
MFR_MATH_FN vec3 dfaoitComposite(vec3 y, float T, vec3 nearColour, float nearAlpha,
                                 vec3 background) {
  MFR_PRECISE float share = max(0.0f, (1.0f - nearAlpha) - T);
  MFR_PRECISE vec3 result = nearAlpha * nearColour + share * y + T * background;
  return result;
}

// ---- moment-based OIT: 16-bit storage ---------------------------------------------------------
// The authors' read-modify-write of the normalised moments (their generatePowerMoments and
// generateTrigonometricMoments without SINGLE_PRECISION, under a rasterizer-ordered view; here
// under the per-pixel lock or in the tile's order): the stored unorm values u_j (q_j / 65535) less
// the offset, times the old b0, plus A times the new fragment's vector in the storage basis,
// divided by the new b0, plus the offset, rounded to the nearest 16-bit step. The resolve inverts
// the basis (the inverse of Q by Gauss-Jordan in double) and hands b0 times the normalised moments
// to the float32 reconstructions above. `count`: the floats of moments (4, 6, 8; trigonometric: 6,
// 8).

/// The 16-bit unorm code of u (clamped to [0, 1], nearest).
MFR_MATH_FN uint unorm16Code(float u) {
  MFR_PRECISE float scaled = clamp(u, 0.0f, 1.0f) * kUnorm16Max + 0.5f;
  return uint(floor(scaled));
}

/// The storage basis' entry (row, col) of the odd (z^1, z^3, ..) or even (z^2, z^4, ..) vector
/// for `count` power moments (halves = count / 2 rows and columns).
MFR_MATH_FN float mboitQuantizeEntry(int count, bool odd, int row, int col) {
  const int halves = count / 2;
  const int at = row * halves + col;
  if (count == 4) return odd ? kMboitQ4Odd[at] : kMboitQ4Even[at];
  if (count == 6) return odd ? kMboitQ6Odd[at] : kMboitQ6Even[at];
  return odd ? kMboitQ8Odd[at] : kMboitQ8Even[at];
}

/// The storage offset of stored moment `index` (0-based in z, z^2, .., z^count order).
MFR_MATH_FN float mboitQuantizeOffset(int count, bool trigonometric, int index) {
  if (trigonometric || index % 2 == 0) return 0.5f;  // the odd moments and b / b0 / 2 + 1/2
  const int row = index / 2;
  if (count == 6) return row == 2 ? kMboitQ6EvenOffset3 : 0.0f;
  if (count == 8) return kMboitQ8EvenOffset[row];
  return 0.0f;
}

/// The bias of a 16-bit moment set.
MFR_MATH_FN float mboitQuantizedBias(int count, bool trigonometric) {
  if (trigonometric) return count == 6 ? kMboitTrig3_16Bias : kMboitTrig4_16Bias;
  return count == 4 ? kMboit16Bias : (count == 6 ? kMboit6_16Bias : kMboit8_16Bias);
}

/// Pass 1 on 16-bit storage: b0 (float32) and the unorm values u (count of them, each on the
/// 1/65535 grid) take the fragment of absorbance A at warped depth z.
MFR_MATH_FN void mboitAddQuantizedMoments(int count, bool trigonometric, MFR_INOUT(float) b0,
                                          MFR_INOUT_ARRAY(float, u, kMboitMaxMoments), float A,
                                          float z) {
  // the fragment's own vector in the storage basis
  float v[kMboitMaxMoments];
  if (trigonometric) {
    const dvec2 w = mboitCircle(mboitTrigPhase(z));
    dvec2 wk = w;
    for (int k = 0; k < count / 2; ++k) {
      v[2 * k] = float(wk.x);
      v[2 * k + 1] = float(wk.y);
      wk = complexMul(wk, w);
    }
  } else {
    float powers[kMboitMaxMoments];
    MFR_PRECISE float zj = 1.0f;
    for (int j = 0; j < count; ++j) {
      MFR_PRECISE float next = zj * z;
      zj = next;
      powers[j] = zj;
    }
    const int halves = count / 2;
    for (int row = 0; row < halves; ++row) {
      MFR_PRECISE float odd = 0.0f;
      MFR_PRECISE float even = 0.0f;
      for (int col = 0; col < halves; ++col) {
        odd += mboitQuantizeEntry(count, true, row, col) * powers[2 * col];
        even += mboitQuantizeEntry(count, false, row, col) * powers[2 * col + 1];
      }
      v[2 * row] = odd;
      v[2 * row + 1] = even;
    }
  }
  const float oldB0 = b0;
  MFR_PRECISE float newB0 = oldB0 + A;
  for (int j = 0; j < count; ++j) {
    const float offset = mboitQuantizeOffset(count, trigonometric, j);
    // trigonometric: b / b0 = 2 (u - 1/2)
    const float scale = trigonometric ? 2.0f : 1.0f;
    MFR_PRECISE float s = (u[j] - offset) * scale * oldB0 + A * v[j];
    MFR_PRECISE float back = s / newB0 / scale + offset;
    u[j] = float(unorm16Code(back)) / kUnorm16Max;
  }
  b0 = newB0;
}

/// The resolve's view of 16-bit storage: b0 times the normalised moments (z, z^2, .. order, or
/// the trigonometric moments' real and imaginary parts), for mboitTransmittancePower / Trig.
MFR_MATH_FN void mboitDequantizeMoments(int count, bool trigonometric, float b0,
                                        MFR_IN_ARRAY(float, u, kMboitMaxMoments),
                                        MFR_INOUT_ARRAY(float, moments, kMboitMaxMoments)) {
  if (trigonometric) {
    for (int j = 0; j < count; ++j) {
      MFR_PRECISE float m = (u[j] - 0.5f) * 2.0f * b0;
      moments[j] = m;
    }
    return;
  }
  const int halves = count / 2;
  for (int parity = 0; parity < 2; ++parity) {
    // Gauss-Jordan on [Q | q]: solves Q v = q for the normalised odd or even vector v
    double a[20];
    for (int row = 0; row < halves; ++row) {
      for (int col = 0; col < halves; ++col)
        a[row * 5 + col] = double(mboitQuantizeEntry(count, parity == 0, row, col));
      const int index = 2 * row + parity;
      a[row * 5 + 4] = double(u[index]) - double(mboitQuantizeOffset(count, false, index));
    }
    for (int col = 0; col < halves; ++col) {
      int pivot = col;
      for (int row = col + 1; row < halves; ++row)
        if (abs(a[row * 5 + col]) > abs(a[pivot * 5 + col])) pivot = row;
      for (int k = 0; k < 5; ++k) {
        const double t = a[col * 5 + k];
        a[col * 5 + k] = a[pivot * 5 + k];
        a[pivot * 5 + k] = t;
      }
      const double diagonal = a[col * 5 + col];
      for (int k = 0; k < 5; ++k) a[col * 5 + k] /= diagonal;
      for (int row = 0; row < halves; ++row) {
        if (row == col) continue;
        const double factor = a[row * 5 + col];
        for (int k = 0; k < 5; ++k) a[row * 5 + k] -= factor * a[col * 5 + k];
      }
    }
    for (int row = 0; row < halves; ++row) {
      MFR_PRECISE float m = float(a[row * 5 + 4]) * b0;
      moments[2 * row + parity] = m;
    }
  }
}

// ---- stochastic transparency and hashed alpha testing -----------------------------------------
// The integer hash both draw their random numbers from (fragment_hash.hpp): PCG's output
// permutation over one LCG step (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 9(3),
// 2020), 32-bit multiplies, shifts and xors only. Stochastic transparency: Enderton, Sintorn,
// Shirley, Luebke, I3D 2010, and Laine & Karras' stratified alpha, EGSR 2011 (stochastic.hpp);
// hashed alpha testing: Wyman & McGuire, I3D 2017, the isotropic threshold of its Listing 3
// (hashed_alpha.hpp).

/// PCG hash of one 32-bit word.
MFR_MATH_FN uint pcgHash(uint v) {
  const uint state = v * 747796405u + 2891336453u;
  const uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

/// Folds `word` into the running hash `h`.
MFR_MATH_FN uint hashCombine(uint h, uint word) {
  return pcgHash(h ^ pcgHash(word));
}

/// A hash as a float in [0, 1): its top 24 bits over 2^24 (exact in float).
MFR_MATH_FN float hashToUnit(uint h) {
  return float(h >> 8u) * (1.0f / 16777216.0f);
}

/// A hash as an integer uniform in [0, n): the top of the 64-bit product h n (Lemire's
/// multiply-shift; the bias is below n / 2^32).
MFR_MATH_FN uint hashBelow(uint h, uint n) {
  return mulHigh32(h, n);
}

/// The depth of a stochastic sample no fragment covered, and of a hashed-alpha pixel no kept
/// fragment reached.
MFR_MATH_CONST(float, kStochasticFarDepth, 3.0e38f)
MFR_MATH_CONST(int, kStochasticMaxSamples, 32)
MFR_MATH_CONST(uint, kStochasticStrataWord, 0x9e3779b9u)  // the stratified count's hash word

/// What identifies a fragment, hashed: its pixel, the depth's bits and the colour word.
MFR_MATH_FN uint stochasticKey(uint pixel, uint depthBits, uint rgba) {
  return hashCombine(hashCombine(pcgHash(pixel), depthBits), rgba);
}

/// The samples (bits 0..S-1) a fragment of alpha `alpha8` (0..255) covers; `key` its
/// stochasticKey. Unstratified: each sample independently with probability alpha8 / 255.
/// Stratified: floor(a S) or floor(a S) + 1 samples (mean a S), a uniformly random subset (the
/// first n of a random permutation, partial Fisher-Yates).
MFR_MATH_FN uint stochasticMask(int samples, bool stratified, uint key, uint alpha8) {
  const uint s = uint(samples);
  uint mask = 0u;
  if (!stratified) {
    for (uint j = 0u; j < s; ++j)
      if (hashBelow(hashCombine(key, j), 255u) < alpha8) mask |= 1u << j;
    return mask;
  }
  // the count: #{m < S : 255 m + v < alpha8 S}, v uniform over [0, 255)
  const uint v = hashBelow(hashCombine(key, kStochasticStrataWord), 255u);
  const uint scaled = alpha8 * s;
  const uint n = scaled > v ? min(s, (scaled - v + 254u) / 255u) : 0u;
  uint order[kStochasticMaxSamples];
  for (uint j = 0u; j < s; ++j) order[j] = j;
  for (uint i = 0u; i < n; ++i) {
    const uint pick = i + hashBelow(hashCombine(key, i + 1u), s - i);
    const uint t = order[i];
    order[i] = order[pick];
    order[pick] = t;
    mask |= 1u << order[i];
  }
  return mask;
}

/// The fraction of the S samples nothing nearer covered (`seen` of them at or behind the depth).
MFR_MATH_FN float stochasticVisibility(int seen, int samples) {
  MFR_PRECISE float v = float(seen) * (1.0f / float(samples));
  return v;
}

/// The alpha-corrected composite: the colours' visibility-weighted mean C / A scaled to the exact
/// total opacity 1 - T, over the background (A = 0: the background).
MFR_MATH_FN vec3 stochasticComposite(vec3 sum, float sumA, float trans, vec3 background) {
  if (sumA <= 0.0f) return background;
  MFR_PRECISE vec3 c = sum / sumA * (1.0f - trans) + trans * background;
  return c;
}

/// Hashed alpha: cells per pixel footprint (the paper's g_HashScale) and the smallest threshold
/// (alpha 0 is never kept).
MFR_MATH_CONST(float, kHashedAlphaScale, 1.0f)
MFR_MATH_CONST(float, kHashedAlphaMinThreshold, 1e-6f)
MFR_MATH_CONST(float, kHashedAlphaMaxCell, 2.0e9f)  // cell coordinates clamped to int32's range
MFR_MATH_CONST(float, kHashedAlphaMaxLevel, 60.0f)  // |log2 cells per unit| bound

/// The cell's integer coordinate of x at `scale` cells per unit (clamped to the int32 range).
MFR_MATH_FN uint hashedAlphaCoordinate(float x, float scale) {
  const float c = floor(x * scale);
  const float bounded = c < -kHashedAlphaMaxCell  ? -kHashedAlphaMaxCell
                        : c > kHashedAlphaMaxCell ? kHashedAlphaMaxCell
                                                  : c;
  return uint(int(bounded));
}

/// The hash in [0, 1) of the cell of `p` at `scale` cells per world unit, for primitive `prim`.
MFR_MATH_FN float hashedAlphaCell(uint prim, vec3 p, float scale) {
  uint h = pcgHash(prim);
  h = hashCombine(h, hashedAlphaCoordinate(p.x, scale));
  h = hashCombine(h, hashedAlphaCoordinate(p.y, scale));
  h = hashCombine(h, hashedAlphaCoordinate(p.z, scale));
  return hashToUnit(h);
}

/// The alpha threshold in [1e-6, 1] of the surface point `p` of primitive `prim` whose pixel
/// covers `footprint` world units: uniform over the points, constant on cells about a pixel wide
/// whose scale follows the footprint continuously (log2, exp2: std:: on the host, GLSL's on the
/// GPU, so a point within rounding of a level or cell boundary may differ between the engines).
MFR_MATH_FN float hashedAlphaThreshold(uint prim, vec3 p, float footprint) {
  float level = -log2(kHashedAlphaScale * footprint);
  level = !(level > -kHashedAlphaMaxLevel) ? -kHashedAlphaMaxLevel
          : level > kHashedAlphaMaxLevel   ? kHashedAlphaMaxLevel
                                           : level;
  const float lower = floor(level);
  MFR_PRECISE float f = level - lower;
  const float x0 = hashedAlphaCell(prim, p, exp2(lower));
  const float x1 = hashedAlphaCell(prim, p, exp2(lower + 1.0f));
  MFR_PRECISE float x = (1.0f - f) * x0 + f * x1;
  const float a = f < 1.0f - f ? f : 1.0f - f;
  float h;
  if (x < a) {
    MFR_PRECISE float q = x * x / (2.0f * a * (1.0f - a));
    h = q;
  } else if (x < 1.0f - a) {
    MFR_PRECISE float q = (x - 0.5f * a) / (1.0f - a);
    h = q;
  } else {
    MFR_PRECISE float q = 1.0f - (1.0f - x) * (1.0f - x) / (2.0f * a * (1.0f - a));
    h = q;
  }
  return h < kHashedAlphaMinThreshold ? kHashedAlphaMinThreshold : h > 1.0f ? 1.0f : h;
}

/// Whether a fragment of alpha `a` (as the capture decodes it, alpha8 * (1 / 255)) at that point
/// is kept.
MFR_MATH_FN bool hashedAlphaKeeps(float a, uint prim, vec3 p, float footprint) {
  return a >= hashedAlphaThreshold(prim, p, footprint);
}

/// The world-space point seen at image position (x, y) (pixels, the centre at the index) at
/// window depth `depth`, and the world width of a pixel there (`footprint`): the view ray (the
/// shading's rays: x rayScaleX + rayBiasX, y rayScaleY + rayBiasY, -1) times the view depth
/// (from the perspective depth with near and far), through the inverse view matrix.
MFR_MATH_FN vec3 surfacePoint(float x, float y, float depth, float zNear, float zFar, vec4 rays,
                              mat4 inverseView, MFR_INOUT(float) footprint) {
  MFR_PRECISE float ndcZ = 2.0f * depth - 1.0f;
  MFR_PRECISE float viewDepth = 2.0f * zNear * zFar / (zFar + zNear - ndcZ * (zFar - zNear));
  MFR_PRECISE float vx = x * rays.x + rays.y;
  MFR_PRECISE float vy = y * rays.z + rays.w;
  MFR_PRECISE vec4 view = vec4(vx * viewDepth, vy * viewDepth, -1.0f * viewDepth, 1.0f);
  MFR_PRECISE vec4 world = inverseView * view;
  footprint = viewDepth * abs(rays.x);
  return vec3(world.x, world.y, world.z);
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
