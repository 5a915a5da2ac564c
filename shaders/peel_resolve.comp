// Depth peeling's composite (mfr::PeelPixel::composite, mfr::DualPeelPixel::composite): the front
// layers over [the hybrid tail over] (dual: the back layers over) the background, with
// method_math.h's overBackground and hybridBehind.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) readonly buffer PeelState {
  uint state[];  // kPeelWords or kDualPeelWords per pixel (peel.frag)
};
layout(std430, binding = kBindResolveTails) readonly buffer Tails {
  uint tails[];  // kTailWords per pixel
};
layout(std430, binding = kBindImage) writeonly buffer Image {
  float image[];  // linear RGB, 3 floats per pixel
};
uniform uint uPixels;
// Compile-time switches (gl_programs.cpp's peelSwitches):
//   MFR_DUAL  1: dual depth peeling
//   MFR_HYBRID  1: the pixel's tail lies behind the front layers
#ifndef MFR_DUAL
#define MFR_DUAL 0
#endif
#ifndef MFR_HYBRID
#define MFR_HYBRID 0
#endif
const uint kDual = MFR_DUAL;
const uint kHybrid = MFR_HYBRID;
uniform vec3 uBackground;

vec3 colorAt(uint i) {
  return vec3(uintBitsToFloat(state[i]), uintBitsToFloat(state[i + 1u]),
              uintBitsToFloat(state[i + 2u]));
}

vec3 tailBehind(uint p, vec3 behind) {
  if (kHybrid == 0u) return behind;
  const uint t = kTailWords * p;
  return hybridBehind(vec3(uintBitsToFloat(tails[t]), uintBitsToFloat(tails[t + 1u]),
                           uintBitsToFloat(tails[t + 2u])),
                      uintBitsToFloat(tails[t + 3u]), tails[t + 4u], behind);
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  vec3 result;
  if (kDual == 0u) {
    const uint w = kPeelWords * p;
    result = overBackground(colorAt(w + 5u), uintBitsToFloat(state[w + 8u]),
                            tailBehind(p, uBackground));
  } else {
    const uint w = kDualPeelWords * p;
    const vec3 back = overBackground(colorAt(w + 14u), uintBitsToFloat(state[w + 17u]), uBackground);
    result = overBackground(colorAt(w + 10u), uintBitsToFloat(state[w + 13u]), tailBehind(p, back));
  }
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
