// Per-pixel k(p) of the variable-k allocations, as mfr::allocate:
//   kAllocCapped        k(p) = min(n(p), k): the K+B-SB (k+-buffer paper sec. 3.3) and the dynamic
//                       k-buffer with the global k the host chose (mfr::boundedK);
//   kAllocByImportance  k(p) = floor(I(p) / I_tot * F(M)) (variable k-buffer paper Eq. 1), in
//                       double like the host; materialised min(k(p), n(p)).
// Writes k(p) materialised (the prefix sum's input) and as allocated, and adds both to 64-bit
// totals (lo, hi words with a carry), the few numbers the host checks against the budget.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAllocCounts) readonly buffer Counts {
  uint counts[];
};
layout(std430, binding = kBindAllocSummary) coherent buffer Totals {
  uint totals[];  // kAllocTotalWords: sum of materialised k(p) lo, hi; as allocated lo, hi
};
layout(std430, binding = kBindAllocK) writeonly buffer Capacity {
  uint capacity[];
};
layout(std430, binding = kBindAllocReserved) writeonly buffer Reserved {
  uint reserved[];  // k(p) as allocated, clamped to 2^32 - 1
};
layout(std430, binding = kBindImportance) readonly buffer Importance {
  float importance[];  // kImportanceWords per pixel, I(p) first
};
layout(std430, binding = kBindImportanceTotal) readonly buffer Total {
  double total;
};
uniform uint uPixels;
uniform uint uMode;     // kAllocCapped or kAllocByImportance
uniform uint uK;        // kAllocCapped: the global k
uniform double uSlots;  // kAllocByImportance: F(M) in nodes

// totals[at], totals[at + 1] += hi * 2^32 + lo
void add64(uint at, uint lo, uint hi) {
  const uint old = atomicAdd(totals[at], lo);
  if (old + lo < old) ++hi;  // the low word wrapped
  if (hi != 0u) atomicAdd(totals[at + 1u], hi);
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint n = counts[p];
  uint cap = 0u, kept = 0u, keptHi = 0u;
  if (uMode == kAllocCapped) {
    cap = min(n, uK);
    kept = cap;
  } else {
    precise double k = 0.0lf;
    if (total > 0.0lf) k = floor(double(importance[p * kImportanceWords]) / total * uSlots);
    keptHi = uint(floor(k / 4294967296.0lf));
    kept = uint(k - double(keptHi) * 4294967296.0lf);
    cap = keptHi != 0u ? n : min(kept, n);
  }
  capacity[p] = cap;
  reserved[p] = keptHi != 0u ? 0xffffffffu : kept;
  add64(0u, cap, 0u);
  add64(2u, kept, keptHi);
}
