// The per-pixel allocation the k-buffer capture, occupancy count and resolve read (texture unit
// kBindAllocation): (first slot = the exclusive prefix sum of k(p), k(p) | kAllocHeapBit) with
// mfr::allocate's store choice (the K+B-SB rule, k+-buffer paper sec. 3.3: the max-heap when the
// pixel overflows and k(p) > 16).
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAllocCounts) readonly buffer Counts {
  uint counts[];
};
layout(std430, binding = kBindAllocK) readonly buffer Capacity {
  uint capacity[];
};
layout(std430, binding = kBindAllocOffsets) readonly buffer Offsets {
  uint offsets[];
};
layout(std430, binding = kBindAllocWords) writeonly buffer Words {
  uvec2 words[];
};
uniform uint uPixels;
uniform uint uStore;  // 0: max-array, 1: max-heap, 2: per pixel (the K+B-SB rule)

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint k = capacity[p];
  const bool heap = uStore == 1u || (uStore == 2u && counts[p] > k && k > 16u);
  words[p] = uvec2(offsets[p], k | (heap ? kAllocHeapBit : 0u));
}
