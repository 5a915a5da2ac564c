#include "mfr/core/color.hpp"

#include <cmath>

namespace mfr {

float srgbToLinear(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float linear) {
  return linear <= 0.0031308f ? linear * 12.92f
                              : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

ColorTables ColorTables::build() {
  ColorTables t{};
  for (int i = 0; i < 256; ++i) t.srgb8ToLinear[i] = srgbToLinear(static_cast<float>(i) / 255.0f);
  for (int i = 0; i < 65536; ++i) {
    const float encoded = linearToSrgb(static_cast<float>(i) / 65535.0f);
    t.linear16ToSrgb8[i] = static_cast<uint8_t>(std::lround(encoded * 255.0f));
  }
  return t;
}

}  // namespace mfr
