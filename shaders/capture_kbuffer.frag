// Per-pixel memory (pixel p = y * width + x; bindings in shared_layout.h):
//
//   nodes   (kBindNodes, uvec2 = 8 B each)   fixed k: slots [p * k, p * k + k)
//                                            variable k: [first, first + k(p)) from uAlloc
//     slot:  x = floatBitsToUint(depth) | y = RGBA8 colour (packFragmentColor)
//     empty: x = y = kFarDepthBits (x = +inf), so a store is always "full" and slot 0 holds its
//            maximum
//     max-array: slot 0 the maximum, the rest unordered; max-heap: a binary max-heap (root slot 0)
//   uAlloc  (kBindAllocation, rg32ui texel)  variable k only: (first slot, k(p) | kAllocHeapBit)
//   uLocks  (kBindLocks, r32ui, 4 B)         kLockFree / kLockHeld (unused with MFR_INTERLOCK)
//   tails   (kBindTails, kTailWords = 20 B)  hybrid only: sum a r, sum a g, sum a b, sum a (float
//                                            bits), t (uint)
//   occupancy (kBindOccupancy, 12 B)         +occupancy only: zn, zf (depth bits), j_k; the
//                                            bitmaps (4 d B) stay with the occupancy passes
//
// Bytes per pixel (MemoryModel): 8 k + 4 (lock) [+ 4 offset for variable k] [+ 20 tail]
// [+ 12 + 4 d occupancy], plus the count pass's 4-byte counter.
//
// Fixed-k k-buffer capture with the k+ culling test (Vasilakis and Fudos, k+-buffer), max-array or
// max-heap store (MFR_STORE): pixel p owns the k nodes nodes[p * k .. p * k + k), initialised to the
// far node (so the store is always full), with the maximum always in slot 0. Max-array: the
// maximum is replaced and the new maximum found by a linear scan (O(k)); max-heap: the root is
// replaced and sifted down (O(log k)), as mfr::maxArrayInsert / maxHeapInsert do once full.
// Hybrid compositing (MFR_HYBRID): fragments culled by the occupancy or k+ test, rejected by the
// store or evicted from it are added to the pixel's tail under the lock (mfr::HybridTail, in
// arrival order). A fragment not nearer than that maximum is culled before the critical section
// (its depth word alone is compared there: slot 0's depth word only decreases, so a stale read is
// conservative). Otherwise it takes the pixel's spin-lock (imageAtomicExchange); the loop is around
// the critical section, not a spin inside it, so lanes of one SIMD group cannot deadlock. With
// MFR_INTERLOCK (--gl-sync interlock, the engine's prelude defines it with the extension's
// begin/end), the fragment shader interlock orders the critical section instead of the lock.
// Compile-time switches (gl_frame.cpp's kbufferSwitches; the engine's in shared_layout.h):
//   MFR_PER_PIXEL  1: variable k, pixel p owns k(p) nodes from its own first slot, its store
//                  per pixel (uAlloc); 0: fixed k (uK), one store for all (MFR_STORE)
//   MFR_STORE      kStoreMaxArray or kStoreMaxHeap (fixed k)
//   MFR_OCCUPANCY  1: occupancy culling (uOccupancyWords words of bitmap per pixel)
//   MFR_HYBRID     1: rejected, culled and evicted fragments go to the pixel's tail
#ifndef MFR_PER_PIXEL
#define MFR_PER_PIXEL 0
#endif
#ifndef MFR_STORE
#define MFR_STORE kStoreMaxArray
#endif
#ifndef MFR_OCCUPANCY
#define MFR_OCCUPANCY 0
#endif
#ifndef MFR_HYBRID
#define MFR_HYBRID 0
#endif
const bool kPerPixel = MFR_PER_PIXEL != 0;
const uint kFixedStore = MFR_STORE;
const bool kOccupancy = MFR_OCCUPANCY != 0;
const bool kHybrid = MFR_HYBRID != 0;

layout(std430, binding = kBindNodes) coherent buffer Nodes {
  uvec2 nodes[];
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
uniform uint uK;  // fixed k
layout(binding = kBindAllocation) uniform usamplerBuffer uAlloc;
uniform uint uOccupancyWords;  // occupancy: bitmap words per pixel
layout(std430, binding = kBindOccupancy) readonly buffer Occupancy {
  uint occupancy[];  // kOccupancyWords per pixel: zn, zf, j_k
};
layout(std430, binding = kBindTails) coherent buffer Tails {
  uint tails[];  // kTailWords per pixel
};
layout(std430, binding = kBindCaptureStats) buffer CaptureStats {
  uint culled[];  // kCaptureStatSlots x kCaptureStatStride: occupancy, k+ (shared_layout.h)
};

// The critical section: the store update and the tail, for one pixel's fragments one at a time.
void insertNode(const uint p, const uint first, const uint k, const uint storeKind, const bool store,
                const uvec2 node) {
  uvec2 tailNode = node;
  bool toTail = !store;
  const uvec2 maxNode = k > 0u ? nodes[first] : uvec2(kFarDepthBits, 0u);
  if (!store) {
    // culled: to the tail
  } else if (!nodeLess(node, maxNode)) {
    toTail = true;  // rejected in the store
  } else if (storeKind == kStoreMaxHeap) {
    // down-heap: move the larger child up into the hole
    uint i = 0u;
    for (;;) {
      const uint left = 2u * i + 1u;
      if (left >= k) break;
      uint child = left;
      if (left + 1u < k) {
        if (nodeLess(nodes[first + left], nodes[first + left + 1u])) child = left + 1u;
      }
      const uvec2 c = nodes[first + child];
      if (!nodeLess(node, c)) break;
      nodes[first + i] = c;
      i = child;
    }
    nodes[first + i] = node;
  } else {
    // replace the maximum; the new maximum of the k moves to slot 0
    uint maxIndex = 0u;
    uvec2 m = node;
    for (uint i = 1u; i < k; ++i) {
      const uvec2 s = nodes[first + i];
      if (nodeLess(m, s)) {
        m = s;
        maxIndex = i;
      }
    }
    if (maxIndex != 0u) nodes[first + maxIndex] = node;
    nodes[first] = m;
  }
  if (store && nodeLess(node, maxNode) && maxNode.x != kFarDepthBits) {
    toTail = true;  // evicted (an empty slot's far node is not a fragment)
    tailNode = maxNode;
  }
  if (kHybrid && toTail) {  // mfr::HybridTail::add (method_math.h's hybridTailAddCovered)
    const uint t = kTailWords * p;
    float r = uintBitsToFloat(tails[t]), g = uintBitsToFloat(tails[t + 1u]),
          b = uintBitsToFloat(tails[t + 2u]), sumA = uintBitsToFloat(tails[t + 3u]);
    uint count = tails[t + 4u];
    const uint tailColor = tailNode.y;
    precise float a = float(tailColor >> 24) * uInv255;
    hybridTailAddCovered(r, g, b, sumA, count, tailColor >> 24, a,
                         srgb8ToLinear(tailColor & 0xffu), srgb8ToLinear((tailColor >> 8) & 0xffu),
                         srgb8ToLinear((tailColor >> 16) & 0xffu), coverageShare(tailNode.x));
    tails[t] = floatBitsToUint(r);
    tails[t + 1u] = floatBitsToUint(g);
    tails[t + 2u] = floatBitsToUint(b);
    tails[t + 3u] = floatBitsToUint(sumA);
    tails[t + 4u] = count;
  }
}

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const float depth = fragmentDepth(f);
  const uint p = uint(f.pixel);
  bool store = true;  // false: culled, to the tail (hybrid) or dropped
  bool drop = false;  // true: nothing to write (no early return: the interlock forbids it)
  if (kOccupancy) {  // occupancy test: behind the pixel's k-th occupied bucket
    const uint t = occupancy[kOccupancyWords * p + 2u];
    if (t != kOccupancyNoCulling &&
        occupancyBucket(depth, uintBitsToFloat(occupancy[kOccupancyWords * p]),
                        uintBitsToFloat(occupancy[kOccupancyWords * p + 1u]),
                        32u * uOccupancyWords) > t) {
      atomicAdd(culled[captureStatSlot(f.px)], 1u);
      if (!kHybrid) drop = true;
      store = false;
    }
  }
  const uint depthBits = floatBitsToUint(depth);
  uint first = p * uK, k = uK, storeKind = kFixedStore;
  if (kPerPixel) {
    const uvec2 a = texelFetch(uAlloc, f.pixel).xy;
    first = a.x;
    k = a.y & ~kAllocHeapBit;
    storeKind = (a.y & kAllocHeapBit) != 0u ? kStoreMaxHeap : kStoreMaxArray;
  }
  if (store && k == 0u) {  // no slot: rejected
    if (!kHybrid) drop = true;
    store = false;
  } else if (store && depthBits > nodes[first].x) {  // k+ test
    atomicAdd(culled[captureStatSlot(f.px) + 1u], 1u);
    if (!kHybrid) drop = true;
    store = false;
  }
  // shaded only when something keeps its colour (the store or the tail): a culled fragment
  // under kbuffer compositing costs no shading
  const uvec2 node = uvec2(depthBits, drop ? 0u : shade(f, base));
#ifdef MFR_INTERLOCK
  // the driver orders the pixel's fragments (outside any control flow, no return before it)
  MFR_INTERLOCK_BEGIN();
  if (!drop) insertNode(p, first, k, storeKind, store, node);
  MFR_INTERLOCK_END();
#else
  if (drop) return;
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      insertNode(p, first, k, storeKind, store, node);
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
#endif
}
