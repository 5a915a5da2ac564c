// Per-pixel memory (pixel p; bindings in shared_layout.h):
//
//   offsets (kBindOffsets, uint)    first slot of p: the exclusive prefix sum of n(p)
//   fill    (kBindFill, uint)       slots of p filled so far (atomicAdd; n(p) when done)
//   nodes   (kBindNodes, uvec2)     [offsets[p], offsets[p] + n(p)): x = depth bits, y = RGBA8
//                                   colour, in arrival order (the resolve sorts them)
//
// Bytes per pixel: 8 n(p) + 4 (offset) + 4 (counter); no lock (the append is atomic).
//
// A-buffer capture: every fragment into its pixel's slots offsets[p] + fill[p]++ (atomic).
layout(std430, binding = kBindOffsets) readonly buffer Offsets {
  uint offsets[];
};
layout(std430, binding = kBindNodes) writeonly buffer Nodes {
  uvec2 nodes[];
};
layout(std430, binding = kBindFill) buffer Fill {
  uint fill[];
};

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  const uvec2 node = uvec2(floatBitsToUint(fragmentDepth(f)), shade(f, base));
  const uint slot = atomicAdd(fill[f.pixel], 1u);
  nodes[offsets[f.pixel] + slot] = node;
}
