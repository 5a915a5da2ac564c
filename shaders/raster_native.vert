// Vertex shader of the native geometry passes (--gl-raster native): the CPU engine's transform in
// single precision, y negated so that GL's row 0 (the first in memory) is the top row, as in the
// CPU engine's images. GL clips and rasterizes; raster_native.glsl reads the varyings.
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
layout(location = 3) in vec4 inColor;  // linear RGBA; the constant white without vertex colours

uniform mat4 uViewProj;
uniform mat3 uViewRot;

out vec3 vNormal;  // view space
out vec2 vUv;
out vec4 vColor;
out vec2 vClipZW;  // clip z and w (the multisampled depth, raster_native.glsl)

void main() {
  const vec4 clip = uViewProj * vec4(inPosition, 1.0);
  gl_Position = vec4(clip.x, -clip.y, clip.z, clip.w);
  vNormal = uViewRot * inNormal;
  vUv = inUv;
  vColor = inColor;
  vClipZW = clip.zw;
}
