// Per-pixel linked lists (Yang, Hensley, Gruen, Thibieroz, "Real-Time Concurrent Linked List
// Construction on the GPU", EGSR 2010; mfr::LinkedNode, include/mfr/method/linked_list.hpp).
//
// Memory (pixel p; bindings in shared_layout.h):
//
//   heads   (kBindListHeads, uint)         p's newest node, kListEnd when empty
//   pool    (kBindNodes, kListNodeWords)   uPoolSize nodes: depth bits, RGBA8 colour, next index
//   counter (kBindFill, uint)              the pool counter: nodes handed out (and beyond: the
//                                          fragments the full pool turned away)
//   tails   (kBindTails, kTailWords)       hybrid only: the order-independent tail
//
// Bytes (MemoryModel): 4 per pixel (head) + 4 (counter) + 12 per pool node [+ 20 per pixel tail].
//
// Capture: a node from the counter (atomicAdd); the head swapped for it (atomicExchange) and the
// old head linked as the node's next. No lock: a list's order is the arrival order. A fragment
// past the pool's end is lost, or under hybrid compositing added to its pixel's tail with
// lock-free float adds (compare-and-swap on each word; the summation order is the arrival order).
layout(std430, binding = kBindListHeads) coherent buffer Heads {
  uint heads[];
};
layout(std430, binding = kBindNodes) writeonly buffer Pool {
  uint pool[];  // kListNodeWords per node
};
layout(std430, binding = kBindFill) coherent buffer PoolCounter {
  uint poolCounter;
};
layout(std430, binding = kBindTails) coherent buffer Tails {
  uint tails[];  // kTailWords per pixel
};

uniform uint uPoolSize;
// Compile-time switches (gl_programs.cpp's listSwitches):
//   MFR_HYBRID  1: the fragments the pool turns away go to the pixel's tail
#ifndef MFR_HYBRID
#define MFR_HYBRID 0
#endif
const uint kHybrid = MFR_HYBRID;

// tails[i] += v as a float, lock-free
void addToTail(uint i, float v) {
  uint seen = tails[i];
  for (;;) {
    precise float sum = uintBitsToFloat(seen) + v;
    const uint previous = atomicCompSwap(tails[i], seen, floatBitsToUint(sum));
    if (previous == seen) break;
    seen = previous;
  }
}

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const uint depthBits = floatBitsToUint(fragmentDepth(f));
  const uint rgba = shade(f, base);
  const uint node = atomicAdd(poolCounter, 1u);
  if (node < uPoolSize) {
    const uint next = atomicExchange(heads[f.pixel], node);
    pool[kListNodeWords * node] = depthBits;
    pool[kListNodeWords * node + 1u] = rgba;
    pool[kListNodeWords * node + 2u] = next;
  } else if (kHybrid != 0u) {  // mfr::HybridTail::add's terms (method_math.h's hybridTailAdd)
    const uint t = kTailWords * f.pixel;
    // hybridTailAddNode: an additive node (alpha byte 0) adds its emission and no alpha
    // (hybridTailAddCovered: weighted by the share of the pixel's samples the fragment covers)
    const bool additive = (rgba >> 24) == kAdditiveNode;
    const float share = coverageShare(depthBits);
    precise float a8 = float(rgba >> 24) * uInv255;
    precise float a = a8 * share;
    const float w = additive ? share : a;
    precise float ar = w * srgb8ToLinear(rgba & 0xffu);
    precise float ag = w * srgb8ToLinear((rgba >> 8) & 0xffu);
    precise float ab = w * srgb8ToLinear((rgba >> 16) & 0xffu);
    addToTail(t, ar);
    addToTail(t + 1u, ag);
    addToTail(t + 2u, ab);
    addToTail(t + 3u, a);
    atomicAdd(tails[t + 4u], 1u);
  }
}
