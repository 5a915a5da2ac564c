// Per-pixel memory (pixel p; bindings in shared_layout.h):
//
//   accum  (kBindAccum, kDfaoitWords = 13 words = 52 B; floats as their bits)
//     [13p + 0..2] sum a c (r, g, b)   [+ 3] sum a   [+ 4] sum a z   [+ 5..7] sum a c z (r, g, b)
//     [+ 8] T = prod (1 - a) (starts at 1)   [+ 9] n (uint)   [+ 10] farthest depth
//     [+ 11] nearest depth bits (starts at kFarDepthBits)   [+ 12] nearest RGBA8
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the update
//
// Bytes per pixel: 52 (accumulators) + 4 (lock); no nodes.
//
// Deep and fast approximate OIT (Tsopouridis, Vasilakis, Fudos 2024; mfr::DfaoitPixel::add): each
// fragment of positive alpha adds to the sums (method_math.h's dfaoitAccumulate), counts, and
// keeps the farthest depth and the nearest node, under the pixel's spin-lock. The sums follow the
// fragments' arrival order (their last bits may differ from the CPU engine's primitive order); the
// count, the farthest depth and the nearest node do not depend on it.
layout(std430, binding = kBindAccum) coherent buffer Accum {
  uint acc[];  // kDfaoitWords per pixel
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
  const uvec2 node = uvec2(floatBitsToUint(depth), rgba);
  const uint i = kDfaoitWords * uint(f.pixel);
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      float r = uintBitsToFloat(acc[i]), g = uintBitsToFloat(acc[i + 1u]),
            b = uintBitsToFloat(acc[i + 2u]), alphaSum = uintBitsToFloat(acc[i + 3u]),
            alphaDepth = uintBitsToFloat(acc[i + 4u]), rz = uintBitsToFloat(acc[i + 5u]),
            gz = uintBitsToFloat(acc[i + 6u]), bz = uintBitsToFloat(acc[i + 7u]),
            T = uintBitsToFloat(acc[i + 8u]);
      dfaoitAccumulate(r, g, b, alphaSum, alphaDepth, rz, gz, bz, T, c, a, depth);
      acc[i] = floatBitsToUint(r);
      acc[i + 1u] = floatBitsToUint(g);
      acc[i + 2u] = floatBitsToUint(b);
      acc[i + 3u] = floatBitsToUint(alphaSum);
      acc[i + 4u] = floatBitsToUint(alphaDepth);
      acc[i + 5u] = floatBitsToUint(rz);
      acc[i + 6u] = floatBitsToUint(gz);
      acc[i + 7u] = floatBitsToUint(bz);
      acc[i + 8u] = floatBitsToUint(T);
      acc[i + 9u] += 1u;
      if (depth > uintBitsToFloat(acc[i + 10u])) acc[i + 10u] = node.x;
      if (nodeLess(node, uvec2(acc[i + 11u], acc[i + 12u]))) {
        acc[i + 11u] = node.x;
        acc[i + 12u] = node.y;
      }
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
