// Multi-layer alpha blending resolve (mfr::compositeMlab: method_math.h's mlabCompositeStep and
// overBackground): the pixel's sorted nodes front to back over the background.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindNodes) readonly buffer MlabNodes {
  float mlab[];  // kMlabWords per node
};
layout(std430, binding = kBindFill) readonly buffer Fill {
  uint fill[];
};
layout(std430, binding = kBindImage2) writeonly buffer Image {
  float image[];  // linear RGB, 3 floats per pixel
};
uniform uint uPixels;
uniform uint uK;
uniform vec3 uBackground;

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  vec3 color = vec3(0.0f);
  float T = 1.0f;
  for (uint i = 0u; i < fill[p]; ++i) {
    const uint w = kMlabWords * (p * uK + i);
    mlabCompositeStep(color, T, vec3(mlab[w + 1u], mlab[w + 2u], mlab[w + 3u]), mlab[w + 4u]);
  }
  const vec3 result = overBackground(color, T, uBackground);
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
