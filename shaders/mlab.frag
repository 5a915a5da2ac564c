// Per-pixel memory (pixel p; bindings in shared_layout.h):
//
//   mlab   (kBindNodes, kMlabWords = 5 floats = 20 B per node)   nodes [p * k, p * k + k)
//     node: depth, premultiplied r, g, b, transmittance; sorted front to back; slots at and
//     above fill[p] are unused (never read)
//   fill   (kBindFill, uint)          nodes in use (at most k)
//   uLocks (kBindLocks, r32ui, 4 B)   the per-pixel spin-lock around the insertion
//
// Bytes per pixel: 20 k + 4 (counter) + 4 (lock).
//
// Multi-layer alpha blending (Salvi and Vaidyanathan 2014; mfr::mlabInsert): pixel p owns k nodes
// (depth, premultiplied r, g, b, transmittance) at p * k, kept sorted front to back, and a count.
// Under the pixel's spin-lock a fragment is inserted in depth order (after equal depths); when
// that makes k + 1 nodes the two farthest merge by "over". The merges follow the fragments'
// arrival order (the CPU engine: primitive order in tile-owned capture).
layout(std430, binding = kBindNodes) coherent buffer MlabNodes {
  float mlab[];  // kMlabWords per node
};
layout(std430, binding = kBindFill) coherent buffer Fill {
  uint fill[];  // nodes in use per pixel
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;
uniform uint uK;

void copyNode(uint to, uint from) {
  for (uint w = 0u; w < kMlabWords; ++w) mlab[kMlabWords * to + w] = mlab[kMlabWords * from + w];
}

void writeNode(uint at, float z, vec3 rgb, float t) {
  mlab[kMlabWords * at] = z;
  mlab[kMlabWords * at + 1u] = rgb.r;
  mlab[kMlabWords * at + 2u] = rgb.g;
  mlab[kMlabWords * at + 3u] = rgb.b;
  mlab[kMlabWords * at + 4u] = t;
}

// MlabNode::mergeBehind (method_math.h's mlabMergeBehind): the node at `at` gets (rgb, t)
// composited behind it
void mergeBehind(uint at, vec3 rgb, float t) {
  const uint w = kMlabWords * at;
  float r = mlab[w + 1u], g = mlab[w + 2u], b = mlab[w + 3u], nextT = mlab[w + 4u];
  mlabMergeBehind(r, g, b, nextT, rgb, t);
  mlab[w + 1u] = r;
  mlab[w + 2u] = g;
  mlab[w + 3u] = b;
  mlab[w + 4u] = nextT;
}

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const float depth = fragmentDepth(f);
  const uint rgba = shade(f, base);
  precise float a = float(rgba >> 24) * uInv255;
  const vec3 c = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                      srgb8ToLinear((rgba >> 16) & 0xffu));
  const vec3 premultiplied = mlabPremultiplied(c, a);  // MlabNode::fromFragment
  const float transmittance = mlabTransmittance(a);
  const uint p = uint(f.pixel);
  const uint first = p * uK;
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      const uint count = fill[p];
      uint pos = count;
      while (pos > 0u && mlab[kMlabWords * (first + pos - 1u)] > depth) --pos;
      if (count < uK) {
        for (uint i = count; i > pos; --i) copyNode(first + i, first + i - 1u);
        writeNode(first + pos, depth, premultiplied, transmittance);
        fill[p] = count + 1u;
      } else if (pos == uK) {  // behind every node: merged into the last one
        mergeBehind(first + uK - 1u, premultiplied, transmittance);
      } else {
        const uint last = kMlabWords * (first + uK - 1u);
        const vec3 lastRgb = vec3(mlab[last + 1u], mlab[last + 2u], mlab[last + 3u]);
        const float lastT = mlab[last + 4u];
        for (uint i = uK - 1u; i > pos; --i) copyNode(first + i, first + i - 1u);
        writeNode(first + pos, depth, premultiplied, transmittance);
        mergeBehind(first + uK - 1u, lastRgb, lastT);
      }
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
