// Deep k-buffer importance (DHOIT sec. 3.1; mfr::pixelFeatures and learn::predict): one invocation
// per pixel builds the 12 features from its accumulators and the image's statistics (uniforms) and
// runs the 12-128-64-1 network (ReLU, ReLU, sigmoid; weights column-major like Eigen's, each layer
// W a then + b). The sums run in index order (not Eigen's), and log2 / exp are float: the
// importance agrees with the CPU engine's within float rounding.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindDkbAcc) readonly buffer Acc {
  uint acc[];  // kDkbAccWords per pixel
};
layout(std430, binding = kBindDkbWeights) readonly buffer Weights {
  float weights[];  // W0 (128 x 12), b0, W1 (64 x 128), b1, W2 (1 x 64), b2
};
layout(std430, binding = kBindDkbImportance) writeonly buffer Importance {
  float importance[];
};
layout(std430, binding = kBindColorTables) readonly buffer ColorTables {
  uint colorTables[];
};
uniform uint uPixels;
uniform double uMeanN;     // sum n / covered pixels
uniform float uNearest;    // D_n
uniform float uFarthest;   // D_f
uniform float uSlotShare;  // min(1, F(M) / sum n)

float srgb8ToLinear(uint code) {
  return uintBitsToFloat(colorTables[kTableLinearBase + code]);
}

float relativeDepth(float z) {
  precise float range = uFarthest - uNearest;
  precise float q = (z - uNearest) / range;
  return range > 0.0 ? clamp(q, 0.0, 1.0) : 0.0;
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint w = kDkbAccWords * p;
  const uint n = acc[w];
  if (n == 0u) {
    importance[p] = 0.0;
    return;
  }
  float x[12];
  const double q = 1.0lf + double(n) / uMeanN;
  x[0] = log2(float(q));
  x[1] = relativeDepth(uintBitsToFloat(acc[w + 1u]));
  x[2] = relativeDepth(uintBitsToFloat(acc[w + 3u]));
  const uint rgba = acc[w + 2u];
  precise float alpha = float(rgba >> 24) / 255.0;
  precise vec3 nearest = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                              srgb8ToLinear((rgba >> 16) & 0xffu)) *
                         alpha;
  precise vec3 mean = vec3(uintBitsToFloat(acc[w + 4u]), uintBitsToFloat(acc[w + 5u]),
                           uintBitsToFloat(acc[w + 6u])) /
                      float(n);
  x[3] = nearest.r;
  x[4] = nearest.g;
  x[5] = nearest.b;
  x[6] = mean.r;
  x[7] = mean.g;
  x[8] = mean.b;
  x[9] = uSlotShare;
  x[10] = uNearest;
  x[11] = uFarthest;
  // layer 1: 12 -> 128, ReLU
  float h1[128];
  const uint b0 = 128u * 12u, w1 = b0 + 128u, b1 = w1 + 64u * 128u, w2 = b1 + 64u,
             b2 = w2 + 64u;
  for (uint r = 0u; r < 128u; ++r) {
    precise float z = 0.0;
    for (uint c = 0u; c < 12u; ++c) z += weights[c * 128u + r] * x[c];
    z += weights[b0 + r];
    h1[r] = max(z, 0.0);
  }
  float h2[64];
  for (uint r = 0u; r < 64u; ++r) {
    precise float z = 0.0;
    for (uint c = 0u; c < 128u; ++c) z += weights[w1 + c * 64u + r] * h1[c];
    z += weights[b1 + r];
    h2[r] = max(z, 0.0);
  }
  precise float z = 0.0;
  for (uint c = 0u; c < 64u; ++c) z += weights[w2 + c] * h2[c];
  z += weights[b2];
  precise float y = 1.0 / (1.0 + exp(-z));
  importance[p] = isnan(y) ? 0.0 : y;
}
