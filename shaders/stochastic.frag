// Per-pixel memory (pixel p; bindings in shared_layout.h):
//
//   accum  (kBindAccum, kStochasticWords = 13 words = 52 B)
//     [13p + 0..7]  the stochastic z-buffer: sample j's nearest depth (float bits; starts at
//                   kStochasticFarDepth)
//     [13p + 8]     T = prod (1 - a) (float; starts at 1)
//     [13p + 9..11] sum vis a c (r, g, b)   [13p + 12] sum vis a (floats; start at 0)
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around T and the sums
//
// Bytes per pixel: 52 + 4 (lock); no nodes.
//
// Stochastic transparency (Enderton, Sintorn, Shirley, Luebke, I3D 2010) with S = 8 samples, and
// Laine and Karras' stratified alpha (EGSR 2011) with kStratified (mfr::StochasticPasses): three
// geometry passes of this shader, kPass
//   0 total alpha       T *= 1 - a, under the lock
//   1 stochastic depth  the fragment covers the samples of its mask (method_math.h's
//                       stochasticMask of stochasticKey(pixel, depth bits, colour word)); each
//                       covered sample keeps the nearest depth (atomicMin on the depth bits:
//                       depths are non-negative floats, whose bits order as they do)
//   2 capture           vis = the samples at or behind the depth / S; sums += vis a (c, 1), under
//                       the lock; n(p) counted here
// then stochastic_resolve.comp. The masks are a pure function of the fragment, so passes 1 and 2
// and every run draw the same; T and the sums are float products and sums in arrival order.
layout(std430, binding = kBindAccum) coherent buffer Accum {
  uint accum[];  // kStochasticWords per pixel
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
// Compile-time switches (gl_programs.cpp's stochasticSwitches):
//   MFR_PASS  0 total alpha, 1 stochastic depth, 2 capture
//   MFR_STRATIFIED  1: stochastic-strat
#ifndef MFR_PASS
#define MFR_PASS 0
#endif
#ifndef MFR_STRATIFIED
#define MFR_STRATIFIED 0
#endif
const uint kPass = MFR_PASS;
const uint kStratified = MFR_STRATIFIED;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  if (kPass == 2u) countInCapture(f);
  const float depth = fragmentDepth(f);
  const uint rgba = shade(f, base);
  const uint alpha8 = rgba >> 24;
  const uint i = kStochasticWords * uint(f.pixel);
  if (kPass == 1u) {
    if (alpha8 == 0u) return;
    const uint mask =
        stochasticMask(kStochasticSamples, kStratified != 0u,
                       stochasticKey(uint(f.pixel), floatBitsToUint(depth), rgba), alpha8);
    for (int j = 0; j < kStochasticSamples; ++j)
      if (((mask >> uint(j)) & 1u) != 0u) atomicMin(accum[i + uint(j)], floatBitsToUint(depth));
    return;
  }
  precise float a = float(alpha8) * uInv255;  // unpackFragmentColor's alpha
  float w = 0.0;
  vec3 c = vec3(0.0);
  if (kPass == 2u) {
    if (a <= 0.0) return;
    int seen = 0;
    for (int j = 0; j < kStochasticSamples; ++j)
      seen += uintBitsToFloat(accum[i + uint(j)]) >= depth ? 1 : 0;
    precise float weight = stochasticVisibility(seen, kStochasticSamples) * a;
    w = weight;
    c = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
             srgb8ToLinear((rgba >> 16) & 0xffu));
  }
  const uint t = i + uint(kStochasticSamples);
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      if (kPass == 0u) {
        precise float trans = uintBitsToFloat(accum[t]) * (1.0 - a);
        accum[t] = floatBitsToUint(trans);
      } else {
        precise float r = uintBitsToFloat(accum[t + 1u]) + w * c.r;
        precise float g = uintBitsToFloat(accum[t + 2u]) + w * c.g;
        precise float b = uintBitsToFloat(accum[t + 3u]) + w * c.b;
        precise float sumA = uintBitsToFloat(accum[t + 4u]) + w;
        accum[t + 1u] = floatBitsToUint(r);
        accum[t + 2u] = floatBitsToUint(g);
        accum[t + 3u] = floatBitsToUint(b);
        accum[t + 4u] = floatBitsToUint(sumA);
      }
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
