// Nearest |n.v| (mfr::nearestCosine, the variable k-buffer's previous-frame buffer): under the
// pixel's spin-lock, a fragment whose node (depth, colour) is below the pixel's nearest so far
// replaces it and writes unorm8(|n.v|) (mfr::unorm8: saturate, * 255 + 0.5, truncate). Equal
// nodes keep the first to arrive (the CPU engine: the first in raster order).
layout(std430, binding = kBindNearest) coherent buffer Nearest {
  uint nearest[];  // kNearestWords per pixel: depth bits, colour, unorm8(|n.v|)
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  float cosine;
  const uvec2 node = uvec2(floatBitsToUint(fragmentDepth(f)), shadeWithCosine(f, base, cosine));
  const uint w = kNearestWords * uint(f.pixel);
  if (node.x > nearest[w]) return;  // the stored depth word only decreases
  precise float scaled = clampUnit(abs(cosine)) * 255.0 + 0.5;
  const uint code = uint(int(scaled));
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      if (nodeLess(node, uvec2(nearest[w], nearest[w + 1u]))) {
        nearest[w] = node.x;
        nearest[w + 1u] = node.y;
        nearest[w + 2u] = code;
      }
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
