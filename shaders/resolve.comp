// Per-pixel memory read (pixel p; bindings in shared_layout.h):
//
//   counts  (kBindCounts, uint)        n(p) from the count pass (the store holds min(n(p), k(p)))
//   offsets (kBindOffsets, uint)       first slot of p (exact allocations; fixed k: p * k)
//   nodes   (kBindNodes, uvec2)        the captured nodes (written back sorted front to back
//                                      with MFR_WRITE_SORTED)
//   tails   (kBindResolveTails, 20 B)  hybrid: the order-independent tail
//   image   (kBindImage, 3 floats)     the output: linear RGB, rows top to bottom
//
// Resolve: one invocation per pixel sorts the pixel's captured nodes (insertion sort in a local
// array when they fit in kResolveLocalNodes, else heap sort in place in the node buffer, so any
// count works),
// writes them back sorted where the stores are read back, and composites them front to back in linear RGB over the
// background with the CPU engine's kbuffer rule (mfr::compositeKBuffer), operation for operation,
// or its hybrid rule (mfr::compositeHybrid) with the pixel's tail: method_math.h's blendStep,
// hybridBehind and overBackground, the functions the CPU engine calls.
layout(local_size_x = kResolveGroupSize) in;

// Compile-time switches (gl_frame.cpp's resolveSwitches; the engine's in shared_layout.h):
//   MFR_RESOLVE_NODES  kResolveFixedK (uK slots at p * uK), kResolveABuffer (n(p) nodes at
//                      offsets[p]) or kResolvePerPixel (k(p) slots from uAlloc's first slot)
//   MFR_HYBRID         1: mfr::compositeHybrid with the pixel's tail
//   MFR_LOCAL_SORT     1: every pixel's slots fit kResolveLocalNodes (no heap sort compiled in)
//   MFR_WRITE_SORTED   1: the sorted nodes are written back (for a read-back of the stores)
#ifndef MFR_RESOLVE_NODES
#define MFR_RESOLVE_NODES kResolveFixedK
#endif
#ifndef MFR_HYBRID
#define MFR_HYBRID 0
#endif
#ifndef MFR_LOCAL_SORT
#define MFR_LOCAL_SORT 0
#endif
#ifndef MFR_WRITE_SORTED
#define MFR_WRITE_SORTED 1
#endif
const uint kNodes = MFR_RESOLVE_NODES;
const bool kHybrid = MFR_HYBRID != 0;
const bool kLocalSortOnly = MFR_LOCAL_SORT != 0;
const bool kWriteSorted = MFR_WRITE_SORTED != 0;

layout(std430, binding = kBindCounts) readonly buffer Counts {
  uint counts[];
};
layout(std430, binding = kBindOffsets) readonly buffer Offsets {
  uint offsets[];
};
layout(std430, binding = kBindNodes) buffer Nodes {
  uvec2 nodes[];
};
layout(std430, binding = kBindImage) writeonly buffer Image {
  float image[];  // linear RGB, 3 floats per pixel, rows top to bottom
};
layout(std430, binding = kBindColorTables) readonly buffer ColorTables {
  uint colorTables[];
};

layout(std430, binding = kBindResolveTails) readonly buffer Tails {
  uint tails[];  // kTailWords per pixel
};

uniform uint uPixels;
layout(binding = kBindAllocation) uniform usamplerBuffer uAlloc;
uniform uint uK;  // fixed k
uniform vec3 uBackground;
uniform float uInv255;

float srgb8ToLinear(uint code) {
  return uintBitsToFloat(colorTables[kTableLinearBase + code]);
}

// max-heap sift-down of nodes[first + root] within nodes[first .. first + n)
void siftDown(uint first, uint root, uint n) {
  const uvec2 v = nodes[first + root];
  uint i = root;
  for (;;) {
    const uint left = 2u * i + 1u;
    if (left >= n) break;
    uint child = left;
    if (left + 1u < n) {
      if (nodeLess(nodes[first + left], nodes[first + left + 1u])) child = left + 1u;
    }
    const uvec2 c = nodes[first + child];
    if (!nodeLess(v, c)) break;
    nodes[first + i] = c;
    i = child;
  }
  nodes[first + i] = v;
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  uint first, slots, n;
  if (kNodes == kResolvePerPixel) {
    const uvec2 a = texelFetch(uAlloc, int(p)).xy;
    first = a.x;
    slots = a.y & ~kAllocHeapBit;  // empty slots hold the far node and sort last
    n = min(counts[p], slots);
  } else if (kNodes == kResolveABuffer) {
    first = offsets[p];
    slots = counts[p];
    n = slots;
  } else {
    first = p * uK;
    slots = uK;  // empty slots hold the far node and sort last
    n = min(counts[p], uK);
  }
  uvec2 local[kResolveLocalNodes];
  const bool inLocal = kLocalSortOnly || slots <= kResolveLocalNodes;
  if (inLocal) {
    for (uint i = 0u; i < slots; ++i) {
      const uvec2 v = nodes[first + i];
      uint j = i;
      while (j > 0u) {  // (no local[j - 1] read at j == 0, not even short-circuited)
        const uvec2 previous = local[j - 1u];
        if (!nodeLess(v, previous)) break;
        local[j] = previous;
        --j;
      }
      local[j] = v;
    }
    if (kWriteSorted)
      for (uint i = 0u; i < slots; ++i) nodes[first + i] = local[i];
  } else {
    // heap sort in place (O(n log n)): build a max-heap, then move its root to the end
    for (uint start = slots / 2u; start > 0u; --start) siftDown(first, start - 1u, slots);
    for (uint end = slots - 1u; end > 0u; --end) {
      const uvec2 top = nodes[first];
      nodes[first] = nodes[first + end];
      nodes[first + end] = top;
      siftDown(first, 0u, end);
    }
  }
  vec3 behind = uBackground;
  if (kHybrid) {
    const uint t = kTailWords * p;
    const vec3 sum = vec3(uintBitsToFloat(tails[t]), uintBitsToFloat(tails[t + 1u]),
                          uintBitsToFloat(tails[t + 2u]));
    // (GLSL pow is exp2(y log2 x), not std::pow: last bits differ from the CPU engine)
    behind = hybridBehind(sum, uintBitsToFloat(tails[t + 3u]), tails[t + 4u], uBackground);
  }
  vec3 result;
  if (kViewMaskSamples > 1) {  // per-pixel multisampled storage: each sample (method_math.h)
    SampleSums sums = emptySampleSums(kViewMaskSamples);
    for (uint i = 0u; i < n; ++i) {
      const uvec2 node = inLocal ? local[i] : nodes[first + i];
      precise float alpha = float(node.y >> 24) * uInv255;
      blendSampleNode(sums, node.x, node.y >> 24, alpha, srgb8ToLinear(node.y & 0xffu),
                      srgb8ToLinear((node.y >> 8) & 0xffu), srgb8ToLinear((node.y >> 16) & 0xffu));
    }
    result = resolveSampleSums(sums, behind);
  } else {  // (the one-sample loop in registers: SampleSums' arrays cost llvmpipe 25% here)
    float r = 0.0f, g = 0.0f, b = 0.0f, tr = 1.0f, tg = 1.0f, tb = 1.0f;
    for (uint i = 0u; i < n; ++i) {
      const uint rgba = (inLocal ? local[i] : nodes[first + i]).y;
      precise float alpha = float(rgba >> 24) * uInv255;
      blendStep(r, g, b, tr, tg, tb, rgba >> 24, alpha, srgb8ToLinear(rgba & 0xffu),
                srgb8ToLinear((rgba >> 8) & 0xffu), srgb8ToLinear((rgba >> 16) & 0xffu));
    }
    result = overBackground(vec3(r, g, b), vec3(tr, tg, tb), behind);
  }
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
