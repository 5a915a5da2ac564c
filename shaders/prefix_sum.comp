// Exclusive prefix sum, one level of a multi-level scan: each work group scans
// kScanGroupSize * kScanItemsPerThread consecutive elements (each thread a run of
// kScanItemsPerThread, then a Hillis-Steele scan of the runs' sums in shared memory) and writes the
// group's total to blockSums. The host scans blockSums the same way and adds them back
// (prefix_sum_add.comp). Exact for totals below 2^32.
layout(local_size_x = kScanGroupSize) in;

layout(std430, binding = kBindScanIn) readonly buffer ScanIn {
  uint inData[];
};
layout(std430, binding = kBindScanOut) writeonly buffer ScanOut {
  uint outData[];
};
layout(std430, binding = kBindScanSums) writeonly buffer ScanSums {
  uint blockSums[];
};
uniform uint uCount;
uniform uint uBlocks;  // work groups of this level (the dispatch may be 2D and larger)

shared uint partial[kScanGroupSize];

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (group >= uBlocks) return;  // uniform in the work group
  const uint t = gl_LocalInvocationID.x;
  const uint first = (group * kScanGroupSize + t) * kScanItemsPerThread;
  uint v[kScanItemsPerThread];
  uint sum = 0u;
  for (uint i = 0u; i < kScanItemsPerThread; ++i) {
    const uint idx = first + i;
    v[i] = idx < uCount ? inData[idx] : 0u;
    sum += v[i];
  }
  partial[t] = sum;
  barrier();
  for (uint offset = 1u; offset < kScanGroupSize; offset <<= 1u) {
    const uint add = t >= offset ? partial[t - offset] : 0u;
    barrier();
    partial[t] += add;
    barrier();
  }
  uint running = partial[t] - sum;
  for (uint i = 0u; i < kScanItemsPerThread; ++i) {
    const uint idx = first + i;
    if (idx < uCount) outData[idx] = running;
    running += v[i];
  }
  if (t == kScanGroupSize - 1u) blockSums[group] = partial[t];
}
