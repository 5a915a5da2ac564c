// Adaptive transparency composite (mfr::AoitPixel::composite, method_math.h's aoitComposite):
// sum vis a c + T_total * background, T_total the last node's transmittance. Layout:
// aoit_visibility.frag.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) readonly buffer Accum {
  float accum[];  // kAoitNodeWords N + kAoitColorWords per pixel
};
// Compile-time switches (gl_programs.cpp's aoitSwitches):
//   MFR_AOIT_NODES  N: 4, 8 or 16 nodes
#ifndef MFR_AOIT_NODES
#define MFR_AOIT_NODES 4
#endif
const uint kNodeCount = MFR_AOIT_NODES;
layout(std430, binding = kBindImage) writeonly buffer Image {
  float image[];  // linear RGB, 3 floats per pixel
};
uniform uint uPixels;
uniform vec3 uBackground;

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint i = (kAoitNodeWords * kNodeCount + kAoitColorWords) * p;
  const uint o = i + kAoitNodeWords * kNodeCount;
  const float total = accum[o - 1u];  // node N - 1's transmittance
  const vec3 result =
      aoitComposite(vec3(accum[o], accum[o + 1u], accum[o + 2u]), total, uBackground);
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
