// Importance map of the variable k-buffer (/work/shared/papers/variable-k-buffer-importance-maps.md
// sec. 3.2, Eqs. 3-6), per pixel as mfr::computeImportance:
//   I_d = alpha + (1 - alpha) min(1, n / N_limit), I_per = 1 - (2 |p - o| / (1.1 sqrt(w^2 + h^2)))^d,
//   I_f = 1 - (1 - |n.v|)^5 / 2, I = max(0, I_per I_d I_f + lambda (xi - 0.5)); 0 where n(p) = 0.
// The terms are method_math.h's importanceDepth, importancePeriphery, importanceFresnel,
// importanceNoiseTerm and importanceCombine, which mfr::computeImportance calls too. Bit for bit
// the host's float arithmetic: every operation `precise` (no fused multiply-add); division and
// square root in double rounded to float (the correctly rounded float result, as the host's:
// method_math.h's exactDivide, exactSqrt); an integer power as a product in double rounded to
// float (the host's powf, which glibc rounds correctly in all but rare cases: hostPow); xi the
// same SplitMix64 hash (method_math.h's constants) in 32-bit words. A non-integer d uses GLSL's
// float pow (a few ulp from powf).
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAllocCounts) readonly buffer Counts {
  uint counts[];
};
layout(std430, binding = kBindImportance) writeonly buffer Importance {
  float importance[];  // kImportanceWords per pixel: I, I_d, I_per, I_f, noise
};
layout(std430, binding = kBindCosine) readonly buffer Cosine {
  uint cosine[];  // kCosineNearest: kNearestWords per pixel; kCosineFloats: float bits
};
uniform uint uPixels;
uniform uint uWidth;
uniform float uAlpha;
uniform float uOneMinusAlpha;  // 1 - alpha, rounded on the host as mfr::computeImportance
uniform float uNLimit;
uniform vec2 uFovea;
uniform float uDiagonal;  // 1.1 sqrt(w^2 + h^2), rounded on the host
uniform float uExponent;  // d
uniform int uExponentInt;  // d when an integer in [0, 64], else -1
uniform float uNoise;      // lambda
uniform uvec2 uSeedMix;    // seed * 0x9E3779B97F4A7C15 + 0x632BE59BD9B4E019 (lo, hi words)
uniform uint uUse;         // bits: 1 depth, 2 periphery, 4 Fresnel, 8 noise
uniform uint uCosine;      // kCosineNone, kCosineNearest or kCosineFloats

// 64-bit words as uvec2(lo, hi)
uvec2 add64(uvec2 a, uvec2 b) {
  uint carry;
  const uint lo = uaddCarry(a.x, b.x, carry);
  return uvec2(lo, a.y + b.y + carry);
}
uvec2 mul64(uvec2 a, uvec2 b) {
  uint hi, lo;
  umulExtended(a.x, b.x, hi, lo);
  return uvec2(lo, hi + a.x * b.y + a.y * b.x);
}
uvec2 shr64(uvec2 a, uint s) {  // 0 < s < 32
  return uvec2((a.x >> s) | (a.y << (32u - s)), a.y >> s);
}

// mfr::importanceNoise: SplitMix64's finaliser of (seed, pixel), 24 bits to [0, 1)
float noiseXi(uint pixel) {
  uvec2 z = add64(uSeedMix, uvec2(pixel, 0u));
  z = mul64(z ^ shr64(z, kSplitMixShift1), uvec2(kSplitMixMul1Lo, kSplitMixMul1Hi));
  z = mul64(z ^ shr64(z, kSplitMixShift2), uvec2(kSplitMixMul2Lo, kSplitMixMul2Hi));
  z ^= shr64(z, kSplitMixShift3);
  return float(z.y >> (kSplitMixKeepShift - 32u)) * kImportanceNoiseUnit;
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  const uint n = counts[p];
  const uint w = p * kImportanceWords;
  if (n == 0u) {
    for (uint i = 0u; i < kImportanceWords; ++i) importance[w + i] = 0.0;
    return;
  }
  float id = 1.0f;
  if ((uUse & 1u) != 0u) id = importanceDepth(uAlpha, uOneMinusAlpha, n, uNLimit);
  float iper = 1.0f;
  if ((uUse & 2u) != 0u)
    iper = importancePeriphery(p % uWidth, p / uWidth, uFovea, uDiagonal, uExponent, uExponentInt);
  float c = 1.0f;
  if (uCosine == kCosineNearest)
    c = exactDivide(float(cosine[p * kNearestWords + 2u]), 255.0f);  // the unorm8 code
  else if (uCosine == kCosineFloats)
    c = uintBitsToFloat(cosine[p]);
  c = min(max(c, 0.0f), 1.0f);
  float ifr = 1.0f;
  if ((uUse & 4u) != 0u) ifr = importanceFresnel(c);
  float noise = 0.0f;
  if ((uUse & 8u) != 0u) noise = importanceNoiseTerm(uNoise, noiseXi(p));
  importance[w] = importanceCombine(iper, id, ifr, noise);  // std::max(0, v): NaN -> 0
  importance[w + 1u] = id;
  importance[w + 2u] = iper;
  importance[w + 3u] = ifr;
  importance[w + 4u] = noise;
}
