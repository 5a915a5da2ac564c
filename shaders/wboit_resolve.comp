// Weighted blended OIT composite (mfr::WboitPixel::composite): the weighted average colour over
// the background by the revealage, the denominator clamped to [1e-4, 5e4].
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
  const float a = accum[i + 3u];
  vec3 result = uBackground;
  if (a > 0.0) {
    const float revealage = accum[i + 4u];
    precise vec3 average = vec3(accum[i], accum[i + 1u], accum[i + 2u]) / clamp(a, 1e-4, 5e4);
    precise vec3 mixed = average * (1.0 - revealage) + revealage * uBackground;
    result = mixed;
  }
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
