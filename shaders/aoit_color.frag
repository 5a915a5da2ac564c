// Adaptive transparency, pass 2 (mfr::AoitPixel::addColor: method_math.h's aoitVisibility and
// aoitAddColor): the visibility in front of the fragment from the pixel's final nodes (the T of the
// farthest node strictly in front of it), then vis a c added to the pixel's colour sum under the
// spin-lock. Layout: aoit_visibility.frag.
layout(std430, binding = kBindAccum) coherent buffer Accum {
  float accum[];  // kAoitNodeWords N + kAoitColorWords per pixel
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
// Compile-time switches (gl_programs.cpp's aoitSwitches):
//   MFR_AOIT_NODES  N: 4, 8 or 16 nodes
#ifndef MFR_AOIT_NODES
#define MFR_AOIT_NODES 4
#endif
const uint kNodeCount = MFR_AOIT_NODES;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const float depth = fragmentDepth(f);
  const uint rgba = shade(f, base);
  precise float alpha = float(rgba >> 24) * uInv255;
  // AoitPixel::addColor: an additive node adds its emission times vis(z); the word 0 adds nothing
  const float a = (rgba >> 24) == kAdditiveNode ? 1.0 : alpha;
  if (a <= 0.0 || rgba == 0u) return;
  const uint i = (kAoitNodeWords * kNodeCount + kAoitColorWords) * uint(f.pixel);
  const int n = int(kNodeCount);
  float d[kAoitMaxNodes + 1];
  float tr[kAoitMaxNodes + 1];
  for (int j = 0; j <= kAoitMaxNodes; ++j) {  // the nodes are final (pass 1)
    d[j] = j < n ? accum[i + kAoitNodeWords * uint(j)] : kAoitEmptyDepth;
    tr[j] = j < n ? accum[i + kAoitNodeWords * uint(j) + 1u] : 1.0;
  }
  const float vis = aoitVisibility(n, d, tr, depth);
  const vec3 c = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                      srgb8ToLinear((rgba >> 16) & 0xffu));
  const uint o = i + kAoitNodeWords * kNodeCount;  // the colour sum after the nodes
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      float r = accum[o], g = accum[o + 1u], b = accum[o + 2u];
      aoitAddColor(r, g, b, c, a, vis);
      accum[o] = r;
      accum[o + 1u] = g;
      accum[o + 2u] = b;
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
