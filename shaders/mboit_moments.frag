// Per-pixel memory (pixel p; bindings in shared_layout.h), both MBOIT passes:
//
//   accum  (kBindAccum, W = kMboitWordsBase + M words: M = kMomentWords)
//     [Wp + 0] b0 (float)   [Wp + 1..M] the moments (this pass)   [Wp + M+1..M+3] sum T a c
//     [Wp + M+4] sum T a
//     The moments: N = kMomentCount floats (4, 6 or 8: power moments b1..bN, or with
//     kTrigonometric N / 2 complex moments as real and imaginary parts), M = N; with kQuantized
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
  const uint i = (kMboitWordsBase + kMomentWords) * uint(f.pixel);
  const int count = int(kMomentCount);
  const bool trig = kTrigonometric != 0u;
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      float s0 = uintBitsToFloat(accum[i]);
      float m[kMboitMaxMoments];
      if (kQuantized != 0u) {
        for (uint j = 0u; j < uint(kMboitMaxMoments); ++j) {
          const uint word = j < kMomentCount ? accum[i + 1u + j / 2u] : 0u;
          const uint code = (j % 2u == 0u) ? (word & 0xffffu) : (word >> 16);
          m[j] = float(code) / kUnorm16Max;  // with b0 = 0 the old values weigh nothing
        }
        mboitAddQuantizedMoments(count, trig, s0, m, A, z);
        for (uint w = 0u; w < kMomentWords; ++w)
          accum[i + 1u + w] = unorm16Code(m[2u * w]) | (unorm16Code(m[2u * w + 1u]) << 16);
      } else if (kMomentCount == 4u && !trig) {
        float s1 = uintBitsToFloat(accum[i + 1u]), s2 = uintBitsToFloat(accum[i + 2u]),
              s3 = uintBitsToFloat(accum[i + 3u]), s4 = uintBitsToFloat(accum[i + 4u]);
        mboitAddMoments(s0, s1, s2, s3, s4, A, z);
        accum[i + 1u] = floatBitsToUint(s1);
        accum[i + 2u] = floatBitsToUint(s2);
        accum[i + 3u] = floatBitsToUint(s3);
        accum[i + 4u] = floatBitsToUint(s4);
      } else {
        for (uint j = 0u; j < uint(kMboitMaxMoments); ++j)
          m[j] = j < kMomentCount ? uintBitsToFloat(accum[i + 1u + j]) : 0.0;
        if (trig)
          mboitAddTrigMoments(count / 2, s0, m, A, z);
        else
          mboitAddPowerMoments(count, s0, m, A, z);
        for (uint j = 0u; j < kMomentCount; ++j) accum[i + 1u + j] = floatBitsToUint(m[j]);
      }
      accum[i] = floatBitsToUint(s0);
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
