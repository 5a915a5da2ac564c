// Per-pixel memory (pixel p; bindings in shared_layout.h), both MBOIT passes:
//
//   accum  (kBindAccum, kMboitWords = 9 floats = 36 B)
//     [9p + 0] b0   [9p + 1..4] b1..b4 (this pass)   [9p + 5..7] sum T a c   [9p + 8] sum T a
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the update
//
// Bytes per pixel: 36 (moments and accumulators) + 4 (lock); no nodes.
//
// Moment-based OIT, pass 1 (Muenstermann et al. 2018; mfr::MboitPixel::addMoments, method_math.h's
// mboitAbsorbance, mboitWarpDepth and mboitAddMoments): each fragment adds its absorbance
// A = -ln(1 - min(a, kMboitMaxAlpha)) times 1, z, z^2, z^3, z^4 (z = 2 d - 1) to the pixel's
// moments under the pixel's spin-lock. Sums in arrival order (see wboit.frag).
layout(std430, binding = kBindAccum) coherent buffer Accum {
  float accum[];  // kMboitWords per pixel: b0, b1..b4, sum T a c (r, g, b), sum T a
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  const float depth = fragmentDepth(f);
  const uint rgba = shade(f, base);
  precise float alpha = float(rgba >> 24) / 255.0;
  if (alpha <= 0.0) return;
  const float A = mboitAbsorbance(alpha);
  const float z = mboitWarpDepth(depth);
  const uint i = kMboitWords * uint(f.pixel);
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      float s0 = accum[i], s1 = accum[i + 1u], s2 = accum[i + 2u], s3 = accum[i + 3u],
            s4 = accum[i + 4u];
      mboitAddMoments(s0, s1, s2, s3, s4, A, z);
      accum[i] = s0;
      accum[i + 1u] = s1;
      accum[i + 2u] = s2;
      accum[i + 3u] = s3;
      accum[i + 4u] = s4;
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
