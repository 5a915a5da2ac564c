// Fixed-k k-buffer capture with the k+ culling test (Vasilakis and Fudos, k+-buffer), max-array or
// max-heap store (uStore): pixel p owns the k nodes nodes[p * k .. p * k + k), initialised to the
// far node (so the store is always full), with the maximum always in slot 0. Max-array: the
// maximum is replaced and the new maximum found by a linear scan (O(k)); max-heap: the root is
// replaced and sifted down (O(log k)), as mfr::maxArrayInsert / maxHeapInsert do once full. A fragment not nearer than that maximum is culled before the critical section
// (its depth word alone is compared there: slot 0's depth word only decreases, so a stale read is
// conservative). Otherwise it takes the pixel's spin-lock (imageAtomicExchange); the loop is around
// the critical section, not a spin inside it, so lanes of one SIMD group cannot deadlock.
layout(std430, binding = kBindNodes) coherent buffer Nodes {
  uvec2 nodes[];
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
uniform uint uK;
uniform uint uStore;  // kStoreMaxArray or kStoreMaxHeap
uniform uint uOccupancyWords;  // 0: no occupancy culling
layout(std430, binding = kBindOccRange) readonly buffer Range {
  uint range[];
};
layout(std430, binding = kBindOccThreshold) readonly buffer Threshold {
  uint threshold[];
};
layout(std430, binding = kBindCaptureStats) buffer CaptureStats {
  uint culledOccupancy;
  uint culledKPlus;
};

void main() {
  FragmentData f;
  if (!exactCoverage(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  const float depth = fragmentDepth(f);
  const uint p = uint(f.pixel);
  if (uOccupancyWords > 0u) {  // occupancy test: behind the pixel's k-th occupied bucket
    const uint t = threshold[p];
    if (t != kOccupancyNoCulling &&
        occupancyBucket(depth, uintBitsToFloat(range[2u * p]), uintBitsToFloat(range[2u * p + 1u]),
                        32u * uOccupancyWords) > t) {
      atomicAdd(culledOccupancy, 1u);
      return;
    }
  }
  const uvec2 node = uvec2(floatBitsToUint(depth), shade(f, base));
  const uint first = p * uK;
  if (node.x > nodes[first].x) {  // k+ test
    atomicAdd(culledKPlus, 1u);
    return;
  }
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      const uvec2 maxNode = nodes[first];
      if (nodeLess(node, maxNode) && uStore == kStoreMaxHeap) {
        // down-heap: move the larger child up into the hole
        uint i = 0u;
        for (;;) {
          const uint left = 2u * i + 1u;
          if (left >= uK) break;
          const uint right = left + 1u;
          const uint child =
              (right < uK && nodeLess(nodes[first + left], nodes[first + right])) ? right : left;
          const uvec2 c = nodes[first + child];
          if (!nodeLess(node, c)) break;
          nodes[first + i] = c;
          i = child;
        }
        nodes[first + i] = node;
      } else if (nodeLess(node, maxNode)) {
        // replace the maximum; the new maximum of the k moves to slot 0
        uint maxIndex = 0u;
        uvec2 m = node;
        for (uint i = 1u; i < uK; ++i) {
          const uvec2 s = nodes[first + i];
          if (nodeLess(m, s)) {
            m = s;
            maxIndex = i;
          }
        }
        if (maxIndex != 0u) nodes[first + maxIndex] = node;
        nodes[first] = m;
      }
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
