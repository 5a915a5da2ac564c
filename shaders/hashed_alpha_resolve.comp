// Hashed alpha's composite (mfr::HashedAlphaPixel::composite): the nearest kept fragment's colour
// (linear, opaque), or the background where none was kept. Reads hashed_alpha.frag's
// kHashedAlphaWords per pixel.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) readonly buffer Accum {
  uint accum[];  // kHashedAlphaWords per pixel
};
layout(std430, binding = kBindImage) writeonly buffer Image {
  float image[];  // linear RGB, 3 floats per pixel
};
layout(std430, binding = kBindColorTables) readonly buffer ColorTables {
  uint colorTables[];
};
uniform uint uPixels;
uniform vec3 uBackground;

float srgb8ToLinear(uint code) {
  return uintBitsToFloat(colorTables[kTableLinearBase + code]);
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint i = kHashedAlphaWords * p;
  const uint rgba = accum[i + 1u];
  const vec3 result = accum[i] == floatBitsToUint(kStochasticFarDepth)
                          ? uBackground
                          : vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                                 srgb8ToLinear((rgba >> 16) & 0xffu));
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
