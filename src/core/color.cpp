#include "mfr/core/color.hpp"

#include <cmath>

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
  return t;
}

}  // namespace mfr
