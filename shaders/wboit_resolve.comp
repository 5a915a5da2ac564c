// Weighted blended OIT composite (mfr::WboitPixel::composite, method_math.h's wboitComposite): the
// weighted average colour over the background by the revealage, the denominator clamped.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) readonly buffer Accum {
  float accum[];  // kWboitWords per pixel
};
layout(std430, binding = kBindImage) writeonly buffer Image {
  float image[];  // linear RGB, 3 floats per pixel
};
uniform uint uPixels;
uniform vec3 uBackground;

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint i = kWboitWords * p;
  const vec3 result = wboitComposite(vec3(accum[i], accum[i + 1u], accum[i + 2u]), accum[i + 3u],
                                     accum[i + 4u], uBackground);
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
