// Shared vertex shader of the geometry passes: the CPU engine's vertex transform, operation for
// operation (glm's mat4 * vec4 = (m0 x + m1 y) + (m2 z + m3 w); mat3 * vec3 left to right), with
// `precise` so that no multiply-add is fused.
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
layout(location = 3) in vec4 inColor;  // linear RGBA; the constant white without vertex colours

uniform mat4 uViewProj;
uniform mat3 uViewRot;

out VertexData {
  vec4 clip;
  vec3 normal;  // view space
  vec2 uv;
  vec4 color;
} vOut;

void main() {
  precise vec4 mul0 = uViewProj[0] * inPosition.x;
  precise vec4 mul1 = uViewProj[1] * inPosition.y;
  precise vec4 add0 = mul0 + mul1;
  precise vec4 mul2 = uViewProj[2] * inPosition.z;
  precise vec4 mul3 = uViewProj[3] * 1.0;
  precise vec4 add1 = mul2 + mul3;
  precise vec4 clip = add0 + add1;
  precise vec3 n0 = uViewRot[0] * inNormal.x;
  precise vec3 n1 = uViewRot[1] * inNormal.y;
  precise vec3 n2 = uViewRot[2] * inNormal.z;
  precise vec3 n01 = n0 + n1;
  precise vec3 n = n01 + n2;
  vOut.clip = clip;
  vOut.normal = n;
  vOut.uv = inUv;
  vOut.color = inColor;
  gl_Position = clip;
}
