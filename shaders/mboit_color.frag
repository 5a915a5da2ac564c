// Moment-based OIT, pass 2 (mfr::MboitPixel::addColor / mboitTransmittance: method_math.h's
// mboitTransmittance and mboitAddColor): the transmittance in front of the fragment reconstructed
// from the pixel's moments (biased Hankel system in double, the canonical 3-point distribution,
// kMboitOverestimation), then T a c and T a added to the pixel's accumulator under the spin-lock.
// GLSL has no double exp: the final exp is float (method_math.h's doubleExp).
layout(std430, binding = kBindAccum) coherent buffer Accum {
  float accum[];  // kMboitWords per pixel
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;

float transmittance(uint i, float z) {
  return mboitTransmittance(accum[i], accum[i + 1u], accum[i + 2u], accum[i + 3u], accum[i + 4u],
                            z, kMboitBias, kMboitOverestimation);
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
  const uint i = kMboitWords * uint(f.pixel);
  precise float ta = transmittance(i, mboitWarpDepth(depth)) * a;  // the moments are final (pass 1)
  const vec3 c = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                      srgb8ToLinear((rgba >> 16) & 0xffu));
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      float r = accum[i + 5u], g = accum[i + 6u], b = accum[i + 7u], sumA = accum[i + 8u];
      mboitAddColor(r, g, b, sumA, c, ta);
      accum[i + 5u] = r;
      accum[i + 6u] = g;
      accum[i + 7u] = b;
      accum[i + 8u] = sumA;
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
