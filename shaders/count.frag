// Count pass: n(p) += 1 for every fragment the CPU engine's Coverage pass emits (exact coverage and
// alpha test), with imageAtomicAdd on uCounts (raster_common.glsl); no depth test, no colour
// output. With uEdges (multisampled, per-pixel storage): 1 for every fragment that covers only
// part of its pixel's samples instead, so that a pixel an edge crosses counts above 0.
uniform uint uEdges;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, true, base)) discard;
  // (the edge pass: only the fragments that cover part of their pixel; the depth word carries the
  // mask, so the other count passes skip reading it)
  if (uEdges != 0u && coverageShare(floatBitsToUint(fragmentDepth(f))) >= 1.0) return;
  imageAtomicAdd(uCounts, f.pixel, 1u);
}
