// Dynamic k-buffer (variable k-buffer paper, /work/shared/papers/variable-k-buffer-importance-maps.md
// sec. 2: the k+-buffer's "depth complexity histogram analysis"): the histogram of n(p) in
// kAllocHistogramBins bins (the last: n >= bins - 1) and the largest n(p), as mfr::summarizeCounts.
// Each work group counts into shared memory, then adds its non-empty bins to the global histogram.
// The host reads the bins (a few kilobytes) and picks k with mfr::boundedK.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAllocCounts) readonly buffer Counts {
  uint counts[];
};
layout(std430, binding = kBindAllocSummary) buffer Summary {
  uint summary[];  // kAllocHistogramBins bins, then max n(p)
};
uniform uint uPixels;

shared uint bins[kAllocHistogramBins];
shared uint groupMax;

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint t = gl_LocalInvocationID.x;
  for (uint b = t; b < kAllocHistogramBins; b += kResolveGroupSize) bins[b] = 0u;
  if (t == 0u) groupMax = 0u;
  barrier();
  const uint p = group * kResolveGroupSize + t;
  if (p < uPixels) {
    const uint n = counts[p];
    atomicAdd(bins[min(n, kAllocHistogramBins - 1u)], 1u);
    atomicMax(groupMax, n);
  }
  barrier();
  for (uint b = t; b < kAllocHistogramBins; b += kResolveGroupSize)
    if (bins[b] != 0u) atomicAdd(summary[b], bins[b]);
  if (t == 0u) atomicMax(summary[kAllocHistogramBins], groupMax);
}
