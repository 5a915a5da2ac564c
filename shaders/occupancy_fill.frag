// Occupancy culling, pass 2: the bit of each fragment's depth bucket in its pixel's
// 32 * uWords-bucket bitmap (atomicOr).
layout(std430, binding = kBindOccupancy) readonly buffer Range {
  uint range[];
};
layout(std430, binding = kBindOccBits) coherent buffer Bits {
  uint bits[];  // uWords per pixel
};
uniform uint uWords;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, true, base)) discard;
  const uint p = uint(f.pixel);
  const uint b = occupancyBucket(fragmentDepth(f), uintBitsToFloat(range[kOccupancyWords * p]),
                                 uintBitsToFloat(range[kOccupancyWords * p + 1u]), 32u * uWords);
  atomicOr(bits[p * uWords + (b >> 5)], 1u << (b & 31u));
}
