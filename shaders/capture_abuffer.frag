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
  if (!exactCoverage(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  const uvec2 node = uvec2(floatBitsToUint(fragmentDepth(f)), shade(f, base));
  const uint slot = atomicAdd(fill[f.pixel], 1u);
  nodes[offsets[f.pixel] + slot] = node;
}
