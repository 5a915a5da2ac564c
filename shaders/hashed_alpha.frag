// Per-pixel memory (pixel p; bindings in shared_layout.h):
//
//   accum  (kBindAccum, kHashedAlphaWords = 2 words = 8 B)
//     [2p + 0] the nearest kept fragment's depth (float bits; kStochasticFarDepth: none)
//     [2p + 1] its colour word (packFragmentColor)
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the pair
//
// Bytes per pixel: 8 + 4 (lock); no nodes.
//
// Hashed alpha testing (Wyman and McGuire, I3D 2017; mfr::HashedAlphaMethod): one geometry pass
// into a z-buffer. A fragment is kept, as an opaque surface, when its alpha reaches a hash of its
// surface point (method_math.h's hashedAlphaKeeps: the isotropic threshold of the paper's Listing
// 3, cells about a pixel wide, the primitive hashed with the cell); the point is the world-space
// position seen at the fragment's image position and depth (surfacePoint, with the camera's inverse
// view, near and far). The nearest kept one wins, at equal depths the smaller colour word (the
// arrival order does not matter). n(p): every fragment tested.
layout(std430, binding = kBindAccum) coherent buffer Accum {
  uint accum[];  // kHashedAlphaWords per pixel
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
uniform mat4 uInverseView;  // world from view (the camera with its fitted clip planes)
uniform vec2 uNearFar;      // its zNear, zFar

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const float depth = fragmentDepth(f);
  const uint rgba = shade(f, base);
  float footprint;
  const vec3 point =
      surfacePoint(f.pos.x, f.pos.y, depth, uNearFar.x, uNearFar.y, uRay, uInverseView, footprint);
  precise float a = float(rgba >> 24) * uInv255;  // unpackFragmentColor's alpha
  if (!hashedAlphaKeeps(a, fragmentPrimitive(), point, footprint)) return;
  const uint i = kHashedAlphaWords * uint(f.pixel);
  const uint z = floatBitsToUint(depth);
  if (z > accum[i]) return;  // behind the kept one (its depth only decreases: a stale read is safe)
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      const uint kept = accum[i];
      if (z < kept || (z == kept && rgba < accum[i + 1u])) {
        accum[i] = z;
        accum[i + 1u] = rgba;
      }
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
