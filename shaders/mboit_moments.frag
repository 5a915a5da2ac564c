// Per-pixel memory (pixel p; bindings in shared_layout.h), both MBOIT passes:
//
//   accum  (kBindAccum, W = kMboitWordsBase + N floats: N = uMomentCount = 4, 6 or 8 moments;
//           with uTrigonometric, N / 2 = 3 or 4 complex moments as real and imaginary parts)
//     [Wp + 0] b0   [Wp + 1..N] b1..bN (this pass)   [Wp + N+1..N+3] sum T a c   [Wp + N+4] sum T a
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the update
//
// Bytes per pixel: 36, 44 or 52 (moments and accumulators) + 4 (lock); no nodes.
//
// Moment-based OIT, pass 1 (Muenstermann et al. 2018; mfr::MboitPixel::addMoments and
// mfr::PowerMomentPixel::addMoments, mfr::TrigMomentPixel::addMoments, method_math.h's
// mboitAbsorbance, mboitWarpDepth, mboitAddMoments, mboitAddPowerMoments and
// mboitAddTrigMoments): each fragment adds its absorbance A = -ln(1 - min(a, kMboitMaxAlpha))
// times 1, z, .., z^N (z = 2 d - 1), or times 1 and e^(i k phi(z)), to the pixel's moments under
// the pixel's spin-lock. Sums in arrival order (see wboit.frag).
layout(std430, binding = kBindAccum) coherent buffer Accum {
  float accum[];  // kMboitWordsBase + N per pixel: b0, b1..bN, sum T a c (r, g, b), sum T a
};
uniform uint uMomentCount;     // N: 4, 6 or 8
uniform uint uTrigonometric;  // 1: N / 2 trigonometric moments (mboitAddTrigMoments)
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
  const uint i = (kMboitWordsBase + uMomentCount) * uint(f.pixel);
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      if (uMomentCount == 4u) {
        float s0 = accum[i], s1 = accum[i + 1u], s2 = accum[i + 2u], s3 = accum[i + 3u],
              s4 = accum[i + 4u];
        mboitAddMoments(s0, s1, s2, s3, s4, A, z);
        accum[i] = s0;
        accum[i + 1u] = s1;
        accum[i + 2u] = s2;
        accum[i + 3u] = s3;
        accum[i + 4u] = s4;
      } else {
        float s0 = accum[i];
        float m[kMboitMaxMoments];
        for (uint j = 0u; j < uint(kMboitMaxMoments); ++j)
          m[j] = j < uMomentCount ? accum[i + 1u + j] : 0.0;
        if (uTrigonometric != 0u)
          mboitAddTrigMoments(int(uMomentCount / 2u), s0, m, A, z);
        else
          mboitAddPowerMoments(int(uMomentCount), s0, m, A, z);
        accum[i] = s0;
        for (uint j = 0u; j < uMomentCount; ++j) accum[i + 1u + j] = m[j];
      }
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
