// Second half of a scan level: adds each block's scanned offset to its elements.
layout(local_size_x = kScanGroupSize) in;

layout(std430, binding = kBindScanOut) buffer ScanOut {
  uint data[];
};
layout(std430, binding = kBindScanSums) readonly buffer ScanSums {
  uint blockOffsets[];
};
uniform uint uCount;

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint idx = group * kScanGroupSize + gl_LocalInvocationID.x;
  if (idx >= uCount) return;
  data[idx] += blockOffsets[idx / (kScanGroupSize * kScanItemsPerThread)];
}
