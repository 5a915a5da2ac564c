// Occupancy culling, pass 1: each pixel's nearest and farthest fragment depth (as uint bits:
// depths are non-negative, so their unsigned order is their order).
layout(std430, binding = kBindOccupancy) coherent buffer Range {
  uint range[];  // kOccupancyWords per pixel: zn, zf, j_k
};

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, true, base)) discard;
  const uint z = floatBitsToUint(fragmentDepth(f));
  atomicMin(range[kOccupancyWords * uint(f.pixel)], z);
  atomicMax(range[kOccupancyWords * uint(f.pixel) + 1u], z);
}
