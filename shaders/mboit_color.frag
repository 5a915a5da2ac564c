// Moment-based OIT, pass 2 (mfr::MboitPixel::addColor / mboitTransmittance): the transmittance in
// front of the fragment reconstructed from the pixel's moments (biased Hankel system in double,
// the canonical 3-point distribution, overestimation 0.25), then T a c and T a added to the
// pixel's accumulator under the spin-lock. GLSL has no double exp: the final exp is float.
layout(std430, binding = kBindAccum) coherent buffer Accum {
  float accum[];  // kMboitWords per pixel
};
layout(binding = kBindLocks, r32ui) uniform coherent uimageBuffer uLocks;

float transmittance(uint i, float zf) {
  const float b0 = accum[i];
  if (b0 <= 0.0) return 1.0;
  const double beta = double(5e-7);
  const double v[4] = double[4](0.0lf, 0.375lf, 0.0lf, 0.375lf);
  double b[4];
  for (int j = 0; j < 4; ++j)
    b[j] = (1.0lf - beta) * (double(accum[i + 1u + uint(j)]) / double(b0)) + beta * v[j];
  precise double d1 = b[1] - b[0] * b[0];
  precise double l21 = (b[2] - b[0] * b[1]) / d1;
  precise double d2 = b[3] - b[1] * b[1] - l21 * l21 * d1;
  const double z0 = double(zf);
  precise double c1 = z0 - b[0];
  precise double c2 = z0 * z0 - b[1] - l21 * c1;
  c1 /= d1;
  c2 /= d2;
  c1 -= l21 * c2;
  precise double c0 = 1.0lf - b[0] * c1 - b[1] * c2;
  precise double p = c1 / c2;
  precise double q = c0 / c2;
  precise double r = sqrt(max(0.0lf, 0.25lf * p * p - q));
  double z1 = -0.5lf * p - r, z2 = -0.5lf * p + r;
  const double f0 = 0.25lf, f1 = z1 < z0 ? 1.0lf : 0.0lf, f2 = z2 < z0 ? 1.0lf : 0.0lf;
  const double tiny = 1e-12lf;
  if (abs(z1 - z0) < tiny) z1 = z0 - tiny;
  if (abs(z2 - z0) < tiny) z2 = z0 + tiny;
  if (abs(z2 - z1) < tiny) z2 = z1 + tiny;
  precise double f01 = (f1 - f0) / (z1 - z0);
  precise double f12 = (f2 - f1) / (z2 - z1);
  precise double f012 = (f12 - f01) / (z2 - z0);
  precise double p2 = f012;
  precise double p1 = f01 - f012 * (z0 + z1);
  precise double p0 = f0 - f01 * z0 + f012 * z0 * z1;
  precise double absorbance = p0 + p1 * b[0] + p2 * b[1];
  const float t = exp(float(-double(b0) * absorbance));
  if (isinf(t) || isnan(t)) return 1.0;
  return clamp(t, 0.0, 1.0);
}

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const float depth = fragmentDepth(f);
  const uint rgba = shade(f, base);
  precise float a = float(rgba >> 24) * uInv255;
  if (a <= 0.0) return;
  const uint i = kMboitWords * uint(f.pixel);
  precise float z = 2.0 * clamp(depth, 0.0, 1.0) - 1.0;
  precise float ta = transmittance(i, z) * a;  // the moments are final (pass 1)
  const vec3 c = vec3(srgb8ToLinear(rgba & 0xffu), srgb8ToLinear((rgba >> 8) & 0xffu),
                      srgb8ToLinear((rgba >> 16) & 0xffu));
  precise vec3 tc = ta * c;
  bool done = false;
  while (!done) {
    if (imageAtomicExchange(uLocks, f.pixel, kLockHeld) == kLockFree) {
      precise float r = accum[i + 5u] + tc.r;
      precise float g = accum[i + 6u] + tc.g;
      precise float b = accum[i + 7u] + tc.b;
      precise float sumA = accum[i + 8u] + ta;
      accum[i + 5u] = r;
      accum[i + 6u] = g;
      accum[i + 7u] = b;
      accum[i + 8u] = sumA;
      memoryBarrierBuffer();
      imageAtomicExchange(uLocks, f.pixel, kLockFree);
      done = true;
    }
  }
}
