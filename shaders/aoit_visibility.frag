// Per-pixel memory (pixel p; bindings in shared_layout.h), both AOIT passes:
//
//   accum  (kBindAccum, W = kAoitNodeWords N + kAoitColorWords floats: N = kNodeCount = 4, 8, 16)
//     [Wp + 2i] depth of node i   [Wp + 2i + 1] its transmittance (i = 0..N-1, this pass;
//     unused nodes: kAoitEmptyDepth and the total transmittance)   [Wp + 2N..2N+2] sum vis a c
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the update
//
// Bytes per pixel: 44, 76 or 140 (nodes and colour sum) + 4 (lock).
//
// Adaptive transparency, pass 1 (Salvi, Montgomery, Lefohn 2011; mfr::AoitPixel::insert,
// method_math.h's aoitInsert): under the pixel's spin-lock the fragment's node (depth,
// 1 - alpha) is inserted into the pixel's N nodes; with N + 1 the node whose removal changes the
// area under the visibility curve least is removed. The removals follow the fragments' arrival
// order (the CPU engine: primitive order in tile-owned capture).
layout(std430, binding = kBindAccum) coherent buffer Accum {
  float accum[];  // kAoitNodeWords N + kAoitColorWords per pixel
};
// Compile-time switches (gl_programs.cpp's aoitSwitches):
//   MFR_AOIT_NODES  N: 4, 8 or 16 nodes
#ifndef MFR_AOIT_NODES
#define MFR_AOIT_NODES 4
#endif
const uint kNodeCount = MFR_AOIT_NODES;
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  const float depth = fragmentDepth(f);
  const uint rgba = shade(f, base);
  precise float alpha = float(rgba >> 24) * uInv255;
  if (alpha <= 0.0) return;
  precise float t = 1.0 - alpha;
  const uint i = (kAoitNodeWords * kNodeCount + kAoitColorWords) * uint(f.pixel);
  const int n = int(kNodeCount);
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      float d[kAoitMaxNodes + 1];
      float tr[kAoitMaxNodes + 1];
      for (int j = 0; j <= kAoitMaxNodes; ++j) {
        d[j] = j < n ? accum[i + kAoitNodeWords * uint(j)] : kAoitEmptyDepth;
        tr[j] = j < n ? accum[i + kAoitNodeWords * uint(j) + 1u] : 1.0;
      }
      aoitInsert(n, d, tr, depth, t);
      for (int j = 0; j < n; ++j) {
        accum[i + kAoitNodeWords * uint(j)] = d[j];
        accum[i + kAoitNodeWords * uint(j) + 1u] = tr[j];
      }
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
