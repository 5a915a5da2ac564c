// Count pass: n(p) += 1 for every fragment the CPU engine's Coverage pass emits (exact coverage and
// alpha test), with imageAtomicAdd on uCounts (raster_common.glsl); no depth test, no colour
// output.

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, true, base)) discard;
  imageAtomicAdd(uCounts, f.pixel, 1u);
}
