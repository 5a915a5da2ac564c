// Moment-based OIT composite (mfr::MboitPixel::composite, method_math.h's mboitComposite):
// T_total = exp(-b0), (1 - T_total) * sum(T a c) / sum(T a) + T_total * background.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) readonly buffer Accum {
  float accum[];  // kMboitWordsBase + M per pixel (mboit_moments.frag): b0, moments, sums
};
uniform uint uMomentWords;  // M: the words of moments (mboit_moments.frag)
layout(std430, binding = kBindImage) writeonly buffer Image {
  float image[];  // linear RGB, 3 floats per pixel
};
uniform uint uPixels;
uniform vec3 uBackground;

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint i = (kMboitWordsBase + uMomentWords) * p;
  const uint o = i + 1u + uMomentWords;
  const vec3 result = mboitComposite(accum[i], vec3(accum[o], accum[o + 1u], accum[o + 2u]),
                                     accum[o + 3u], uBackground);
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
