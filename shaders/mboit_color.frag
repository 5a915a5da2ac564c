// Moment-based OIT, pass 2 (mfr::MboitPixel::addColor / mboitTransmittance,
// mfr::PowerMomentPixel, mfr::TrigMomentPixel and mfr::QuantizedMomentPixel's addColor:
// method_math.h's mboitTransmittance, mboitTransmittancePower, mboitTransmittanceTrig,
// mboitDequantizeMoments and mboitAddColor): the
// transmittance in front of the fragment reconstructed from the pixel's moments (power: biased
// Hankel system in double, the canonical N/2 + 1 point distribution; trigonometric: the Toeplitz
// system and N/2 roots on the unit circle; kMboitOverestimation), then T a c and T a added to the
// pixel's accumulator under the spin-lock. GLSL has no double exp: the final exp is float
// (method_math.h's doubleExp).
layout(std430, binding = kBindAccum) coherent buffer Accum {
  uint accum[];  // kMboitWordsBase + M per pixel (mboit_moments.frag)
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
// Compile-time switches (gl_programs.cpp's mboitSwitches):
//   MFR_MOMENTS  N: 4, 6 or 8
//   MFR_TRIGONOMETRIC  1: N / 2 trigonometric moments
//   MFR_QUANTIZED  1: 16-bit storage, two codes per word
#ifndef MFR_MOMENTS
#define MFR_MOMENTS 4
#endif
#ifndef MFR_TRIGONOMETRIC
#define MFR_TRIGONOMETRIC 0
#endif
#ifndef MFR_QUANTIZED
#define MFR_QUANTIZED 0
#endif
const uint kMomentCount = MFR_MOMENTS;
const uint kTrigonometric = MFR_TRIGONOMETRIC;
const uint kQuantized = MFR_QUANTIZED;
const uint kMomentWords = kQuantized != 0u ? kMomentCount / 2u : kMomentCount;  // M

float transmittance(uint i, float z) {
  const float b0 = uintBitsToFloat(accum[i]);
  const int count = int(kMomentCount);
  const bool trig = kTrigonometric != 0u;
  float m[kMboitMaxMoments];
  float bias;
  if (kQuantized != 0u) {
    float u[kMboitMaxMoments];
    for (uint j = 0u; j < uint(kMboitMaxMoments); ++j) {
      const uint word = j < kMomentCount ? accum[i + 1u + j / 2u] : 0u;
      u[j] = float((j % 2u == 0u) ? (word & 0xffffu) : (word >> 16)) / kUnorm16Max;
      m[j] = 0.0;
    }
    mboitDequantizeMoments(count, trig, b0, u, m);
    bias = mboitQuantizedBias(count, trig);
  } else {
    if (kMomentCount == 4u && !trig)
      return mboitTransmittance(b0, uintBitsToFloat(accum[i + 1u]), uintBitsToFloat(accum[i + 2u]),
                                uintBitsToFloat(accum[i + 3u]), uintBitsToFloat(accum[i + 4u]), z,
                                kMboitBias, kMboitOverestimation);
    for (uint j = 0u; j < uint(kMboitMaxMoments); ++j)
      m[j] = j < kMomentCount ? uintBitsToFloat(accum[i + 1u + j]) : 0.0;
    bias = trig ? mboitTrigBias(count / 2) : mboitPowerBias(count);
  }
  if (trig) return mboitTransmittanceTrig(count / 2, b0, m, z, bias, kMboitOverestimation);
  return mboitTransmittancePower(count, b0, m, z, bias, kMboitOverestimation);
}

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const float depth = fragmentDepth(f);
  const uint rgba = shade(f, base);
  precise float a = float(rgba >> 24) * uInv255;
  if (a <= 0.0) return;
  const uint i = (kMboitWordsBase + kMomentWords) * uint(f.pixel);
  precise float ta = transmittance(i, mboitWarpDepth(depth)) * a;  // the moments are final (pass 1)
  const vec3 c = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                      srgb8ToLinear((rgba >> 16) & 0xffu));
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      const uint o = i + 1u + kMomentWords;  // the colour accumulators after the moments
      float r = uintBitsToFloat(accum[o]), g = uintBitsToFloat(accum[o + 1u]),
            b = uintBitsToFloat(accum[o + 2u]), sumA = uintBitsToFloat(accum[o + 3u]);
      mboitAddColor(r, g, b, sumA, c, ta);
      accum[o] = floatBitsToUint(r);
      accum[o + 1u] = floatBitsToUint(g);
      accum[o + 2u] = floatBitsToUint(b);
      accum[o + 3u] = floatBitsToUint(sumA);
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
