// Moment-based OIT composite (mfr::MboitPixel::composite): T_total = exp(-b0),
// (1 - T_total) * sum(T a c) / sum(T a) + T_total * background.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) readonly buffer Accum {
  float accum[];  // kMboitWords per pixel
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
  const uint i = kMboitWords * p;
  const float b0 = accum[i], a = accum[i + 8u];
  vec3 result = uBackground;
  if (b0 > 0.0 && a > 0.0) {
    const float total = exp(-b0);
    precise vec3 mixed = (1.0 - total) * vec3(accum[i + 5u], accum[i + 6u], accum[i + 7u]) / a +
                         total * uBackground;
    result = mixed;
  }
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
