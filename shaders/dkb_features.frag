// Deep k-buffer feature pass (DHOIT sec. 3.1.1; mfr::FeatureAccumulator::add): per pixel under the
// spin-lock n += 1, the nearest node (depth, colour), the farthest depth and the sum of the
// premultiplied linear colours (in arrival order).
layout(std430, binding = kBindDkbAcc) coherent buffer Acc {
  uint acc[];  // kDkbAccWords per pixel: n, nearest depth bits, nearest colour, farthest depth
               // bits, sum r, g, b (float bits)
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  const float depth = fragmentDepth(f);
  const uvec2 node = uvec2(floatBitsToUint(depth), shade(f, base));
  precise float alpha = float(node.y >> 24) / 255.0;
  precise vec3 pm = vec3(srgb8ToLinear(node.y & 0xffu), srgb8ToLinear((node.y >> 8) & 0xffu),
                         srgb8ToLinear((node.y >> 16) & 0xffu)) *
                    alpha;
  const uint w = kDkbAccWords * uint(f.pixel);
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      acc[w] += 1u;
      if (nodeLess(node, uvec2(acc[w + 1u], acc[w + 2u]))) {
        acc[w + 1u] = node.x;
        acc[w + 2u] = node.y;
      }
      if (depth > uintBitsToFloat(acc[w + 3u])) acc[w + 3u] = node.x;
      precise float r = uintBitsToFloat(acc[w + 4u]) + pm.r;
      precise float g = uintBitsToFloat(acc[w + 5u]) + pm.g;
      precise float b = uintBitsToFloat(acc[w + 6u]) + pm.b;
      acc[w + 4u] = floatBitsToUint(r);
      acc[w + 5u] = floatBitsToUint(g);
      acc[w + 6u] = floatBitsToUint(b);
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
