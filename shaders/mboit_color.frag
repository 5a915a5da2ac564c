// Moment-based OIT, pass 2 (mfr::MboitPixel::addColor / mboitTransmittance,
// mfr::PowerMomentPixel::addColor and mfr::TrigMomentPixel::addColor: method_math.h's
// mboitTransmittance, mboitTransmittancePower, mboitTransmittanceTrig and mboitAddColor): the
// transmittance in front of the fragment reconstructed from the pixel's moments (power: biased
// Hankel system in double, the canonical N/2 + 1 point distribution; trigonometric: the Toeplitz
// system and N/2 roots on the unit circle; kMboitOverestimation), then T a c and T a added to the
// pixel's accumulator under the spin-lock. GLSL has no double exp: the final exp is float
// (method_math.h's doubleExp).
layout(std430, binding = kBindAccum) coherent buffer Accum {
  float accum[];  // kMboitWordsBase + N per pixel (mboit_moments.frag)
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
uniform uint uMomentCount;     // N: 4, 6 or 8
uniform uint uTrigonometric;  // 1: N / 2 trigonometric moments (mboitTransmittanceTrig)

float transmittance(uint i, float z) {
  if (uMomentCount == 4u)
    return mboitTransmittance(accum[i], accum[i + 1u], accum[i + 2u], accum[i + 3u],
                              accum[i + 4u], z, kMboitBias, kMboitOverestimation);
  float m[kMboitMaxMoments];
  for (uint j = 0u; j < uint(kMboitMaxMoments); ++j)
    m[j] = j < uMomentCount ? accum[i + 1u + j] : 0.0;
  if (uTrigonometric != 0u) {
    const int complexCount = int(uMomentCount / 2u);
    return mboitTransmittanceTrig(complexCount, accum[i], m, z, mboitTrigBias(complexCount),
                                  kMboitOverestimation);
  }
  const int count = int(uMomentCount);
  return mboitTransmittancePower(count, accum[i], m, z, mboitPowerBias(count),
                                 kMboitOverestimation);
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
  const uint i = (kMboitWordsBase + uMomentCount) * uint(f.pixel);
  precise float ta = transmittance(i, mboitWarpDepth(depth)) * a;  // the moments are final (pass 1)
  const vec3 c = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                      srgb8ToLinear((rgba >> 16) & 0xffu));
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      const uint o = i + 1u + uMomentCount;  // the colour accumulators after the moments
      float r = accum[o], g = accum[o + 1u], b = accum[o + 2u], sumA = accum[o + 3u];
      mboitAddColor(r, g, b, sumA, c, ta);
      accum[o] = r;
      accum[o + 1u] = g;
      accum[o + 2u] = b;
      accum[o + 3u] = sumA;
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
