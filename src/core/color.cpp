#include "mfr/core/color.hpp"

#include <cmath>
#include <cstring>

namespace mfr {

float srgbToLinear(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float linear) {
  return linear <= 0.0031308f ? linear * 12.92f : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

ColorTables ColorTables::build() {
  ColorTables t{};
  for (int i = 0; i < 256; ++i) t.srgb8ToLinear[i] = srgbToLinear(static_cast<float>(i) / 255.0f);
  for (int i = 0; i < 4096; ++i) {
    const double encoded = linearToSrgb(static_cast<float>(i / 4095.0));
    t.coarseSrgb8[i] = static_cast<uint8_t>(std::lround(encoded * 255.0));
  }
  t.lowerBound[0] = 0.0f;
  for (int c = 1; c < 256; ++c) {
    const double e = (c - 0.5) / 255.0;
    const double boundary = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
    // the smallest float at or above the exact boundary, so `v >= lowerBound[c]` is exact
    float f = static_cast<float>(boundary);
    if (static_cast<double>(f) < boundary) f = std::nextafter(f, 2.0f);
    t.lowerBound[c] = f;
  }
  t.lowerBound[256] = 2.0f;  // above any clamped input
  // per bucket, the smallest input in [0, 1] whose bucket (the encode's float operations) is it,
  // by bisection over the float bits (the bucket grows with the input), and its exact code
  const auto bucketOf = [](float c) { return static_cast<int32_t>(c * 4095.0f + 0.5f); };
  for (int b = 0; b < 4096; ++b) {
    uint32_t lo = 0, hi = 0x3f800000u;  // the bits of 0 and 1
    while (lo < hi) {
      const uint32_t mid = lo + (hi - lo) / 2;
      float c;
      std::memcpy(&c, &mid, sizeof c);
      if (bucketOf(c) >= b) {
        hi = mid;
      } else {
        lo = mid + 1;
      }
    }
    float c;
    std::memcpy(&c, &lo, sizeof c);
    t.bucketLowSrgb8[b] = encodeSrgb8(t, c);
  }
  return t;
}

}  // namespace mfr
