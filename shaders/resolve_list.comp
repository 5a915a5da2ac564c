// Resolve of the per-pixel linked lists (capture_list.frag; mfr::LinkedNode). Memory read
// (pixel p; bindings in shared_layout.h):
//
//   heads   (kBindListHeads, uint)          p's newest node, kListEnd when empty
//   pool    (kBindNodes, kListNodeWords)    the nodes; each list is sorted in place (contents
//                                           swapped between its nodes, the links unchanged)
//   lengths (kBindListLengths, uint)        written: the nodes p's list holds (k(p))
//   tails   (kBindResolveTails, 20 B)       hybrid: the order-independent tail
//   image   (kBindImage, 3 floats)          the output: linear RGB, rows top to bottom
//
// One invocation per pixel walks its list with a selection sort (the nearest remaining node's
// contents swapped into the current node: nearest first by the FragmentNode key (depth bits,
// colour word), no local array, so any length works) and composites each node as it is placed,
// front to back, with the CPU engine's kbuffer or hybrid rule: method_math.h's blendStep,
// hybridBehind and overBackground, as resolve.comp.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindListHeads) readonly buffer Heads {
  uint heads[];
};
layout(std430, binding = kBindListLengths) writeonly buffer Lengths {
  uint lengths[];
};
layout(std430, binding = kBindNodes) buffer Pool {
  uint pool[];  // kListNodeWords per node
};
layout(std430, binding = kBindImage) writeonly buffer Image {
  float image[];
};
layout(std430, binding = kBindColorTables) readonly buffer ColorTables {
  uint colorTables[];
};
layout(std430, binding = kBindResolveTails) readonly buffer Tails {
  uint tails[];  // kTailWords per pixel
};

// Compile-time switches (gl_programs.cpp's listSwitches):
//   MFR_HYBRID  1: mfr::compositeHybrid with the pixel's tail
#ifndef MFR_HYBRID
#define MFR_HYBRID 0
#endif
const uint kHybrid = MFR_HYBRID;
uniform uint uPixels;
uniform vec3 uBackground;
uniform float uInv255;

float srgb8ToLinear(uint code) {
  return uintBitsToFloat(colorTables[kTableLinearBase + code]);
}

uvec2 keyOf(uint node) {
  return uvec2(pool[kListNodeWords * node], pool[kListNodeWords * node + 1u]);
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  // one sum in registers while sorting; per-pixel multisampled storage composites each sample
  // after the sort (method_math.h's SampleSums, whose arrays in this loop cost llvmpipe 13% at one
  // sample)
  const bool masked = kViewMaskSamples > 1;
  float r = 0.0f, g = 0.0f, b = 0.0f, tr = 1.0f, tg = 1.0f, tb = 1.0f;
  uint n = 0u;
  for (uint a = heads[p]; a != kListEnd; a = pool[kListNodeWords * a + 2u]) {
    uint best = a;
    uvec2 bestKey = keyOf(a);
    for (uint c = pool[kListNodeWords * a + 2u]; c != kListEnd; c = pool[kListNodeWords * c + 2u]) {
      const uvec2 key = keyOf(c);
      if (nodeLess(key, bestKey)) {
        best = c;
        bestKey = key;
      }
    }
    if (best != a) {
      const uvec2 current = keyOf(a);
      pool[kListNodeWords * best] = current.x;
      pool[kListNodeWords * best + 1u] = current.y;
      pool[kListNodeWords * a] = bestKey.x;
      pool[kListNodeWords * a + 1u] = bestKey.y;
    }
    const uint rgba = bestKey.y;
    precise float alpha = float(rgba >> 24) * uInv255;
    const float cr = srgb8ToLinear(rgba & 0xffu), cg = srgb8ToLinear((rgba >> 8) & 0xffu),
                cb = srgb8ToLinear((rgba >> 16) & 0xffu);
    if (!masked) blendStep(r, g, b, tr, tg, tb, rgba >> 24, alpha, cr, cg, cb);
    ++n;
  }
  lengths[p] = n;
  vec3 behind = uBackground;
  if (kHybrid != 0u) {
    const uint t = kTailWords * p;
    const vec3 sum = vec3(uintBitsToFloat(tails[t]), uintBitsToFloat(tails[t + 1u]),
                          uintBitsToFloat(tails[t + 2u]));
    behind = hybridBehind(sum, uintBitsToFloat(tails[t + 3u]), tails[t + 4u], uBackground);
  }
  vec3 result;
  if (masked) {  // the list is sorted now: each sample from the nodes whose mask holds it
    SampleSums sums = emptySampleSums(kViewMaskSamples);
    for (uint a = heads[p]; a != kListEnd; a = pool[kListNodeWords * a + 2u]) {
      const uvec2 key = keyOf(a);
      precise float alpha = float(key.y >> 24) * uInv255;
      blendSampleNode(sums, key.x, key.y >> 24, alpha, srgb8ToLinear(key.y & 0xffu),
                      srgb8ToLinear((key.y >> 8) & 0xffu), srgb8ToLinear((key.y >> 16) & 0xffu));
    }
    result = resolveSampleSums(sums, behind);
  } else {
    result = overBackground(vec3(r, g, b), vec3(tr, tg, tb), behind);
  }
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
