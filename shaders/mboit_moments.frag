// Per-pixel memory (pixel p; bindings in shared_layout.h), both MBOIT passes:
//
//   accum  (kBindAccum, W = kMboitWordsBase + M words: M = uMomentWords)
//     [Wp + 0] b0 (float)   [Wp + 1..M] the moments (this pass)   [Wp + M+1..M+3] sum T a c
//     [Wp + M+4] sum T a
//     The moments: N = uMomentCount floats (4, 6 or 8: power moments b1..bN, or with
//     uTrigonometric N / 2 complex moments as real and imaginary parts), M = N; with uQuantized
//     N 16-bit unorm codes of method_math.h's storage basis, two per word (low half first),
//     M = N / 2.
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the update
//
// Bytes per pixel: 36, 44 or 52 (float moments and accumulators; 28, 32, 36 with 16-bit
// moments) + 4 (lock); no nodes. The buffer is declared uint: the float fields go through
// floatBitsToUint / uintBitsToFloat, the packed codes are not floats.
//
// Moment-based OIT, pass 1 (Muenstermann et al. 2018; mfr::MboitPixel::addMoments,
// mfr::PowerMomentPixel, mfr::TrigMomentPixel and mfr::QuantizedMomentPixel's addMoments:
// method_math.h's mboitAbsorbance, mboitWarpDepth, mboitAddMoments, mboitAddPowerMoments,
// mboitAddTrigMoments and mboitAddQuantizedMoments): each fragment adds its absorbance
// A = -ln(1 - min(a, kMboitMaxAlpha)) times 1, z, .., z^N (z = 2 d - 1), or times 1 and
// e^(i k phi(z)), to the pixel's moments under the pixel's spin-lock (16-bit storage: the
// authors' read-modify-write of the normalised moments). Sums in arrival order (see wboit.frag).
layout(std430, binding = kBindAccum) coherent buffer Accum {
  uint accum[];  // kMboitWordsBase + M per pixel
};
uniform uint uMomentCount;    // N: 4, 6 or 8
uniform uint uMomentWords;    // M: N, or N / 2 with uQuantized
uniform uint uTrigonometric;  // 1: N / 2 trigonometric moments
uniform uint uQuantized;      // 1: 16-bit storage
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
  const uint i = (kMboitWordsBase + uMomentWords) * uint(f.pixel);
  const int count = int(uMomentCount);
  const bool trig = uTrigonometric != 0u;
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      float s0 = uintBitsToFloat(accum[i]);
      float m[kMboitMaxMoments];
      if (uQuantized != 0u) {
        for (uint j = 0u; j < uint(kMboitMaxMoments); ++j) {
          const uint word = j < uMomentCount ? accum[i + 1u + j / 2u] : 0u;
          const uint code = (j % 2u == 0u) ? (word & 0xffffu) : (word >> 16);
          m[j] = float(code) / kUnorm16Max;  // with b0 = 0 the old values weigh nothing
        }
        mboitAddQuantizedMoments(count, trig, s0, m, A, z);
        for (uint w = 0u; w < uMomentWords; ++w)
          accum[i + 1u + w] = unorm16Code(m[2u * w]) | (unorm16Code(m[2u * w + 1u]) << 16);
      } else if (uMomentCount == 4u && !trig) {
        float s1 = uintBitsToFloat(accum[i + 1u]), s2 = uintBitsToFloat(accum[i + 2u]),
              s3 = uintBitsToFloat(accum[i + 3u]), s4 = uintBitsToFloat(accum[i + 4u]);
        mboitAddMoments(s0, s1, s2, s3, s4, A, z);
        accum[i + 1u] = floatBitsToUint(s1);
        accum[i + 2u] = floatBitsToUint(s2);
        accum[i + 3u] = floatBitsToUint(s3);
        accum[i + 4u] = floatBitsToUint(s4);
      } else {
        for (uint j = 0u; j < uint(kMboitMaxMoments); ++j)
          m[j] = j < uMomentCount ? uintBitsToFloat(accum[i + 1u + j]) : 0.0;
        if (trig)
          mboitAddTrigMoments(count / 2, s0, m, A, z);
        else
          mboitAddPowerMoments(count, s0, m, A, z);
        for (uint j = 0u; j < uMomentCount; ++j) accum[i + 1u + j] = floatBitsToUint(m[j]);
      }
      accum[i] = floatBitsToUint(s0);
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
