// Count pass: n(p) += 1 for every fragment the CPU engine's Coverage pass emits (exact coverage and
// alpha test), with imageAtomicAdd; no depth test, no colour output.
layout(binding = kBindCounts, r32ui) uniform coherent uimageBuffer uCounts;

void main() {
  FragmentData f;
  if (!exactCoverage(f)) discard;
  vec4 base;
  if (!surface(f, true, base)) discard;
  imageAtomicAdd(uCounts, f.pixel, 1u);
}
