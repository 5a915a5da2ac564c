// After the 64-bit atomic k-buffer capture (capture_kbuffer_atomic64.frag): each node's words from
// the uint64 layout (colour, depth) to the engine's uvec2 (depth, colour) (shared_layout.h).
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindNodes) buffer Nodes {
  uvec2 nodes[];
};
uniform uint uCount;

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint i = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (i < uCount) nodes[i] = nodes[i].yx;
}
