// Colour encoding shared by every stage. Blending happens on linear RGB floats; fragment colours
// travel as RGBA8 with sRGB-encoded RGB (like an SRGB8_ALPHA8 texture) and linear alpha; images are
// written sRGB-encoded.
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

namespace mfr {

/// sRGB transfer functions on [0, 1] (IEC 61966-2-1).
float srgbToLinear(float encoded);
float linearToSrgb(float linear);

/// Table lookups for the hot paths.
struct ColorTables {
  std::array<float, 256> srgb8ToLinear;  // decode of an 8-bit sRGB code
  std::array<uint8_t, 65536> linear16ToSrgb8;  // encode of round(linear * 65535)
  static const ColorTables& get() {
    static const ColorTables tables = build();
    return tables;
  }

 private:
  static ColorTables build();
};

/// Linear [0, 1] (clamped; NaN -> 0) to an 8-bit sRGB code.
inline uint8_t encodeSrgb8(float linear) {
  const float c = linear > 0.0f ? (linear < 1.0f ? linear : 1.0f) : 0.0f;
  return ColorTables::get().linear16ToSrgb8[static_cast<uint32_t>(c * 65535.0f + 0.5f)];
}
inline float decodeSrgb8(uint8_t code) { return ColorTables::get().srgb8ToLinear[code]; }

inline uint8_t unorm8(float v) {
  const float c = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
  return static_cast<uint8_t>(c * 255.0f + 0.5f);
}

/// Packs linear RGB + alpha into the fragment colour word: R in bits 0-7, G 8-15, B 16-23 (sRGB
/// codes), A 24-31 (linear), i.e. the byte order of GL's packUnorm4x8 / RGBA8 in memory.
inline uint32_t packFragmentColor(const glm::vec3& linearRgb, float alpha) {
  return static_cast<uint32_t>(encodeSrgb8(linearRgb.r)) |
         (static_cast<uint32_t>(encodeSrgb8(linearRgb.g)) << 8) |
         (static_cast<uint32_t>(encodeSrgb8(linearRgb.b)) << 16) |
         (static_cast<uint32_t>(unorm8(alpha)) << 24);
}

/// Unpacks a fragment colour word to linear RGB and alpha.
inline glm::vec4 unpackFragmentColor(uint32_t rgba) {
  const ColorTables& t = ColorTables::get();
  return {t.srgb8ToLinear[rgba & 0xffu], t.srgb8ToLinear[(rgba >> 8) & 0xffu],
          t.srgb8ToLinear[(rgba >> 16) & 0xffu], static_cast<float>(rgba >> 24) * (1.0f / 255.0f)};
}

}  // namespace mfr
