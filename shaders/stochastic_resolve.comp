// Stochastic transparency's composite (mfr::StochasticPixel::composite, method_math.h's
// stochasticComposite): the colours' visibility-weighted mean scaled to the exact total opacity
// 1 - T, over the background. Reads stochastic.frag's kStochasticWords per pixel.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) readonly buffer Accum {
  uint accum[];  // kStochasticWords per pixel
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
  const uint t = kStochasticWords * p + uint(kStochasticSamples);
  const vec3 sum = vec3(uintBitsToFloat(accum[t + 1u]), uintBitsToFloat(accum[t + 2u]),
                        uintBitsToFloat(accum[t + 3u]));
  const vec3 result = stochasticComposite(sum, uintBitsToFloat(accum[t + 4u]),
                                          uintBitsToFloat(accum[t]), uBackground);
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
