// Per-pixel memory (pixel p; bindings in shared_layout.h):
//
//   accum  (kBindAccum, kWboitWords = 5 floats = 20 B)
//     [5p + 0..2] sum C w (r, g, b)   [5p + 3] sum a w   [5p + 4] revealage (starts at 1)
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the update
//
// Bytes per pixel: 20 (accumulators) + 4 (lock); no nodes.
//
// Weighted blended OIT (McGuire and Bavoil 2013; mfr::WboitPixel::add): each fragment adds
// C w, a w to the pixel's sums and multiplies its revealage by 1 - a, under the pixel's spin-lock
// (float atomics are not core GL; the CPU engine's fragment-parallel capture locks the same way).
// The sums follow the fragments' arrival order, so their last bits may differ from the CPU
// engine's primitive order.
layout(std430, binding = kBindAccum) coherent buffer Accum {
  float accum[];  // kWboitWords per pixel: sum C w (r, g, b), sum a w, revealage
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;

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
  const vec3 c = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                      srgb8ToLinear((rgba >> 16) & 0xffu));
  const float w = wboitWeight(depth, a);  // method_math.h, as mfr::WboitPixel::add
  const uint i = kWboitWords * uint(f.pixel);
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      float r = accum[i], g = accum[i + 1u], b = accum[i + 2u], sumA = accum[i + 3u],
            revealage = accum[i + 4u];
      wboitAccumulate(r, g, b, sumA, revealage, c, a, w);
      accum[i] = r;
      accum[i + 1u] = g;
      accum[i + 2u] = b;
      accum[i + 3u] = sumA;
      accum[i + 4u] = revealage;
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
