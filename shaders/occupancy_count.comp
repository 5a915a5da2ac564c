// Occupancy culling, pass 3: each pixel's k-th occupied bucket j_k by Kernighan's bit counting
// (mfr::OccupancyMap::resolveThreshold); kOccupancyNoCulling when fewer than k are occupied.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindOccBits) readonly buffer Bits {
  uint bits[];
};
layout(std430, binding = kBindOccupancy) buffer Occupancy {
  uint occupancy[];  // kOccupancyWords per pixel: zn, zf, j_k
};
uniform uint uPixels;
uniform uint uWords;
uniform uint uK;
uniform uint uPerPixel;  // 1: k(p) from the allocation (uAlloc)
layout(binding = kBindAllocation) uniform usamplerBuffer uAlloc;

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint k = uPerPixel != 0u ? texelFetch(uAlloc, int(p)).y & ~kAllocHeapBit : uK;
  uint seen = 0u;
  uint result = kOccupancyNoCulling;
  for (uint w = 0u; w < uWords && result == kOccupancyNoCulling; ++w) {
    uint b = bits[p * uWords + w];
    while (b != 0u) {
      if (++seen == k) {
        result = w * 32u + uint(findLSB(b));
        break;
      }
      b &= b - 1u;
    }
  }
  occupancy[kOccupancyWords * p + 2u] = result;
}
