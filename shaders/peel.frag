// Per-pixel memory (pixel p; bindings in shared_layout.h):
//
//   state  (kBindAccum, uint words)   depth peeling: kPeelWords = 9 (36 B) per pixel
//       [0, 1] bound (hi, lo)  [2, 3] candidate key (hi, lo; all ones: none)  [4] multiplicity
//       [5..7] front r, g, b  [8] front T (float bits)
//     dual depth peeling: kDualPeelWords = 18 (72 B) per pixel
//       [0, 1] lo  [2, 3] hi  [4, 5] nearest key  [6, 7] farthest key  [8] nearest multiplicity
//       [9] farthest multiplicity  [10..13] front r, g, b, T  [14..17] back r, g, b, T
//   stats  (kBindCaptureStats)        [0] fragments still to peel in this pass (frame-wide)
//   tails  (kBindTails, kTailWords)   the hybrid tail (--composite hybrid after --max-peels)
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the update
//
// Bytes per pixel: 36 (peel) or 72 (dual-peel) + 4 (lock) [+ 20 tail]; no nodes.
//
// Depth peeling (Everitt 2001) and dual depth peeling (Bavoil & Myers 2008), mfr::PeelPixel::add
// and mfr::DualPeelPixel::add (include/mfr/method/peel.hpp): one geometry pass keeps, per pixel,
// the smallest key (depth bits, colour word) >= bound and how many fragments have it (dual: also
// the largest key < hi and its count), under the pixel's lock; the key order is total, so the
// result does not depend on the arrival order. peel_step.comp blends the layer and advances the
// bounds between passes. The tail pass (kTail) adds the fragments still in range to the tail.
layout(std430, binding = kBindAccum) coherent buffer PeelState {
  uint state[];
};
layout(std430, binding = kBindCaptureStats) coherent buffer PeelStats {
  uint inRange;  // fragments still to peel, this pass
  uint peeled;   // (peel_step.comp's)
};
layout(std430, binding = kBindTails) coherent buffer Tails {
  uint tails[];  // kTailWords per pixel
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
// Compile-time switches (gl_programs.cpp's peelSwitches):
//   MFR_DUAL  1: dual depth peeling
//   MFR_TAIL  1: the tail pass (hybrid): the fragments in range into the tail
#ifndef MFR_DUAL
#define MFR_DUAL 0
#endif
#ifndef MFR_TAIL
#define MFR_TAIL 0
#endif
const uint kDual = MFR_DUAL;
const uint kTail = MFR_TAIL;

uvec2 keyAt(uint i) {
  return uvec2(state[i], state[i + 1u]);
}
void setKey(uint i, uvec2 k) {
  state[i] = k.x;
  state[i + 1u] = k.y;
}
bool keyEqual(uvec2 a, uvec2 b) {
  return a.x == b.x && a.y == b.y;
}

// whether `key` is still to peel (peel: >= bound; dual: >= lo and < hi)
bool remains(uint w, uvec2 key) {
  if (nodeLess(key, keyAt(w))) return false;
  return kDual == 0u || nodeLess(key, keyAt(w + 2u));
}

// the pass's update of pixel p's candidates (mfr::PeelPixel::add, mfr::DualPeelPixel::add)
void peelAdd(uint w, uvec2 key) {
  const uint nearW = kDual != 0u ? w + 4u : w + 2u;
  const uint nearM = kDual != 0u ? w + 8u : w + 4u;
  const uvec2 nearest = keyAt(nearW);
  const bool none = nearest.x == 0xffffffffu && nearest.y == 0xffffffffu;
  if (nodeLess(key, nearest)) {
    setKey(nearW, key);
    state[nearM] = 1u;
  } else if (keyEqual(key, nearest)) {
    state[nearM] = state[nearM] + 1u;
  }
  if (kDual != 0u) {
    const uvec2 farthest = keyAt(w + 6u);
    if (none || nodeLess(farthest, key)) {
      setKey(w + 6u, key);
      state[w + 9u] = 1u;
    } else if (keyEqual(key, farthest)) {
      state[w + 9u] = state[w + 9u] + 1u;
    }
  }
}

// mfr::HybridTail::add (method_math.h's hybridTailAdd)
void tailAdd(uint p, uint rgba) {
  const uint t = kTailWords * p;
  float r = uintBitsToFloat(tails[t]), g = uintBitsToFloat(tails[t + 1u]),
        b = uintBitsToFloat(tails[t + 2u]), sumA = uintBitsToFloat(tails[t + 3u]);
  uint count = tails[t + 4u];
  precise float a = float(rgba >> 24) * uInv255;
  hybridTailAddNode(r, g, b, sumA, count, rgba >> 24, a, srgb8ToLinear(rgba & 0xffu),
                srgb8ToLinear((rgba >> 8) & 0xffu), srgb8ToLinear((rgba >> 16) & 0xffu));
  tails[t] = floatBitsToUint(r);
  tails[t + 1u] = floatBitsToUint(g);
  tails[t + 2u] = floatBitsToUint(b);
  tails[t + 3u] = floatBitsToUint(sumA);
  tails[t + 4u] = count;
}

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const uint depthBits = floatBitsToUint(fragmentDepth(f));
  const uint p = uint(f.pixel);
  const uint w = (kDual != 0u ? kDualPeelWords : kPeelWords) * p;
  // (the bounds change only between passes): a depth outside them needs no shading
  if (depthBits < state[w] || (kDual != 0u && depthBits > state[w + 2u])) return;
  const uvec2 key = uvec2(depthBits, shade(f, base));
  if (!remains(w, key)) return;
  if (kTail == 0u) atomicAdd(inRange, 1u);
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      if (kTail != 0u)
        tailAdd(p, key.y);
      else
        peelAdd(w, key);
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
