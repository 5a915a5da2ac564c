// Deep and fast approximate OIT resolve (mfr::dfaoitResolve): one invocation per pixel builds the
// 12 inputs from its sums (method_math.h's dfaoitFeatures), runs the 12-32-32-3 network (ReLU,
// ReLU, sigmoid; weights as mfr::dfaoitWeights lays them out: per layer the matrix column-major,
// then the bias; the sums in index order, as mfr::dfaoitForward) and composites the nearest
// fragment over the predicted colour behind it (dfaoitComposite). An empty pixel is the
// background; a pixel of one or two fragments needs no network (as on the CPU). The
// sigmoid's exp is GLSL's float exp (the host's std::exp): the colours agree within float
// rounding. Layout: dfaoit.frag.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) readonly buffer Accum {
  uint acc[];  // kDfaoitWords per pixel
};
layout(std430, binding = kBindDfaoitWeights) readonly buffer Weights {
  float weights[];  // W0 (32 x 12), b0, W1 (32 x 32), b1, W2 (3 x 32), b2
};
layout(std430, binding = kBindImage) writeonly buffer Image {
  float image[];  // linear RGB, 3 floats per pixel
};
layout(std430, binding = kBindColorTables) readonly buffer ColorTables {
  uint colorTables[];
};
uniform uint uPixels;
uniform vec3 uBackground;
uniform float uInv255;  // 1.0f / 255.0f

float srgb8ToLinear(uint code) {
  return uintBitsToFloat(colorTables[kTableLinearBase + code]);
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint i = kDfaoitWords * p;
  const uint n = acc[i + 9u];
  vec3 result = uBackground;
  if (n > 0u) {
    const uint rgba = acc[i + 12u];
    precise float nearAlpha = float(rgba >> 24) * uInv255;
    const vec3 nearColour = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                                 srgb8ToLinear((rgba >> 16) & 0xffu));
    const float T = uintBitsToFloat(acc[i + 8u]);
    float x[kDfaoitInputs];
    dfaoitFeatures(vec3(uintBitsToFloat(acc[i]), uintBitsToFloat(acc[i + 1u]),
                        uintBitsToFloat(acc[i + 2u])),
                   uintBitsToFloat(acc[i + 3u]), uintBitsToFloat(acc[i + 4u]),
                   vec3(uintBitsToFloat(acc[i + 5u]), uintBitsToFloat(acc[i + 6u]),
                        uintBitsToFloat(acc[i + 7u])),
                   T, n, uintBitsToFloat(acc[i + 11u]), nearColour, nearAlpha,
                   uintBitsToFloat(acc[i + 10u]), x);
    const uint I = uint(kDfaoitInputs), H = uint(kDfaoitHidden), O = uint(kDfaoitOutputs);
    const uint b0 = H * I, w1 = b0 + H, b1 = w1 + H * H, w2 = b1 + H, b2 = w2 + O * H;
    float h1[kDfaoitHidden];
    for (uint r = 0u; r < H; ++r) {
      precise float z = 0.0;
      for (uint c = 0u; c < I; ++c) z += weights[c * H + r] * x[c];
      z += weights[b0 + r];
      h1[r] = max(z, 0.0);
    }
    float h2[kDfaoitHidden];
    for (uint r = 0u; r < H; ++r) {
      precise float z = 0.0;
      for (uint c = 0u; c < H; ++c) z += weights[w1 + c * H + r] * h1[c];
      z += weights[b1 + r];
      h2[r] = max(z, 0.0);
    }
    // at most two fragments: y' is the rest's mean colour x0-2 exactly (no network)
    vec3 y = vec3(x[0], x[1], x[2]);
    for (uint r = 0u; r < O && n > 2u; ++r) {
      precise float z = 0.0;
      for (uint c = 0u; c < H; ++c) z += weights[w2 + c * O + r] * h2[c];
      z += weights[b2 + r];
      precise float s = 1.0 / (1.0 + exp(-z));
      y[r] = s;
    }
    result = dfaoitComposite(y, T, nearColour, nearAlpha, uBackground);
  }
  image[3u * p + 0u] = result.r;
  image[3u * p + 1u] = result.g;
  image[3u * p + 2u] = result.b;
}
