// Importance map of the variable k-buffer (/work/shared/papers/variable-k-buffer-importance-maps.md
// sec. 3.2, Eqs. 3-6), per pixel as mfr::computeImportance:
//   I_d = alpha + (1 - alpha) min(1, n / N_limit), I_per = 1 - (2 |p - o| / (1.1 sqrt(w^2 + h^2)))^d,
//   I_f = 1 - (1 - |n.v|)^5 / 2, I = max(0, I_per I_d I_f + lambda (xi - 0.5)); 0 where n(p) = 0.
// Bit for bit the host's float arithmetic: every operation `precise` (no fused multiply-add);
// division and square root in double rounded to float (the correctly rounded float result, as
// the host's); an integer power as a product in double rounded to float (the host's powf, which
// glibc rounds correctly in all but rare cases); xi the same SplitMix64 hash in 32-bit words. A
// non-integer d uses GLSL's float pow (a few ulp from powf).
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

float divide(float a, float b) {
  return float(double(a) / double(b));
}

float powInt(float x, int e) {
  precise double r = 1.0lf;
  for (int i = 0; i < e; ++i) r *= double(x);
  return float(r);
}

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
  z = mul64(z ^ shr64(z, 30u), uvec2(0x1CE4E5B9u, 0xBF58476Du));
  z = mul64(z ^ shr64(z, 27u), uvec2(0x133111EBu, 0x94D049BBu));
  z ^= shr64(z, 31u);
  return float(z.y >> 8u) * (1.0 / 16777216.0);
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
  precise float id = 1.0;
  if ((uUse & 1u) != 0u) id = uAlpha + uOneMinusAlpha * min(1.0, divide(float(n), uNLimit));
  precise float iper = 1.0;
  if ((uUse & 2u) != 0u) {
    const uint x = p % uWidth, y = p / uWidth;
    precise float dx = (float(x) + 0.5) - uFovea.x;
    precise float dy = (float(y) + 0.5) - uFovea.y;
    precise float length2 = dx * dx + dy * dy;
    const float len = float(sqrt(double(length2)));
    precise float base = divide(2.0 * len, uDiagonal);
    iper = 1.0 - (uExponentInt >= 0 ? powInt(base, uExponentInt) : pow(base, uExponent));
  }
  float c = 1.0;
  if (uCosine == kCosineNearest)
    c = divide(float(cosine[p * kNearestWords + 2u]), 255.0);
  else if (uCosine == kCosineFloats)
    c = uintBitsToFloat(cosine[p]);
  c = min(max(c, 0.0), 1.0);
  precise float ifr = 1.0;
  if ((uUse & 4u) != 0u) ifr = 1.0 - powInt(1.0 - c, 5) * 0.5;
  precise float noise = 0.0;
  if ((uUse & 8u) != 0u) noise = uNoise * (noiseXi(p) - 0.5);
  precise float v = iper * id * ifr + noise;
  importance[w] = v > 0.0 ? v : 0.0;  // std::max(0, v): NaN -> 0
  importance[w + 1u] = id;
  importance[w + 2u] = iper;
  importance[w + 3u] = ifr;
  importance[w + 4u] = noise;
}
