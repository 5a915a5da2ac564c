// Colour encoding shared by every stage. Blending happens on linear RGB floats; fragment colours
// travel as RGBA8 with sRGB-encoded RGB (like an SRGB8_ALPHA8 texture) and linear alpha; images are
// written sRGB-encoded.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/blend_mode.hpp"
#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace mfr {

/// sRGB transfer functions on [0, 1] (IEC 61966-2-1).
float srgbToLinear(float encoded);
float linearToSrgb(float linear);

/// Table lookups for the hot paths.
struct ColorTables {
  std::array<float, 256> srgb8ToLinear;  // decode of an 8-bit sRGB code
  // encode: a coarse guess from round(linear * 4095), corrected by the exact code boundaries
  // (lowerBound[c] = linear value of sRGB (c - 0.5) / 255); 5 KB, so it stays in L1
  std::array<uint8_t, 4096> coarseSrgb8;
  // the 8-lane encode's guess (raster_span_avx2.hpp): the code of the smallest input of each
  // bucket round(linear * 4095), which no bucket exceeds by more than one (at most one code
  // boundary lies in a bucket: the boundaries are at least 1/3295 apart, the buckets 1/4095
  // wide), so one correction upwards, against lowerBound, makes it exact (ColorTables test)
  std::array<uint8_t, 4096> bucketLowSrgb8;
  std::array<float, 257> lowerBound;
  static const ColorTables& get() {
    static const ColorTables tables = build();
    return tables;
  }

 private:
  static ColorTables build();
};

/// Linear [0, 1] (clamped; NaN -> 0) to the correctly rounded 8-bit sRGB code.
/// clamp(v, 0, 1) with NaN -> 0, as two min/max instructions.
inline float saturate(float v) {
#if defined(__SSE2__)
  return _mm_cvtss_f32(_mm_min_ss(_mm_max_ss(_mm_set_ss(v), _mm_setzero_ps()), _mm_set_ss(1.0f)));
#else
  return std::min(std::max(0.0f, v), 1.0f);  // max(0, NaN) is 0
#endif
}

inline uint8_t encodeSrgb8(const ColorTables& t, float linear) {
  const float c = saturate(linear);
  int32_t code = t.coarseSrgb8[static_cast<int32_t>(c * 4095.0f + 0.5f)];
  code += c >= t.lowerBound[code + 1];
  code -= c < t.lowerBound[code];
  return static_cast<uint8_t>(code);
}
inline uint8_t encodeSrgb8(float linear) {
  return encodeSrgb8(ColorTables::get(), linear);
}
inline float decodeSrgb8(uint8_t code) {
  return ColorTables::get().srgb8ToLinear[code];
}

inline uint8_t unorm8(float v) {
  const float c = saturate(v);
  return static_cast<uint8_t>(static_cast<int32_t>(c * 255.0f + 0.5f));
}

/// Packs linear RGB + alpha into the fragment colour word: R in bits 0-7, G 8-15, B 16-23 (sRGB
/// codes), A 24-31 (linear), i.e. the byte order of GL's packUnorm4x8 / RGBA8 in memory.
inline uint32_t packFragmentColor(const ColorTables& t, const glm::vec3& linearRgb, float alpha) {
#if defined(__SSE2__)
  // the clamps, scales and conversions of all four channels at once (maxps maps NaN to 0)
  const __m128 v = _mm_setr_ps(linearRgb.r, linearRgb.g, linearRgb.b, alpha);
  const __m128 c = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps(1.0f));
  const __m128i index = _mm_cvttps_epi32(
      _mm_add_ps(_mm_mul_ps(c, _mm_setr_ps(4095.0f, 4095.0f, 4095.0f, 255.0f)), _mm_set1_ps(0.5f)));
  alignas(16) int32_t i[4];
  alignas(16) float clamped[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(i), index);
  _mm_store_ps(clamped, c);
  uint32_t word = static_cast<uint32_t>(i[3]) << 24;
  for (int ch = 0; ch < 3; ++ch) {
    int32_t code = t.coarseSrgb8[i[ch]];
    code += clamped[ch] >= t.lowerBound[code + 1];
    code -= clamped[ch] < t.lowerBound[code];
    word |= static_cast<uint32_t>(code) << (8 * ch);
  }
  return word;
#else
  return static_cast<uint32_t>(encodeSrgb8(t, linearRgb.r)) |
         (static_cast<uint32_t>(encodeSrgb8(t, linearRgb.g)) << 8) |
         (static_cast<uint32_t>(encodeSrgb8(t, linearRgb.b)) << 16) |
         (static_cast<uint32_t>(unorm8(alpha)) << 24);
#endif
}
inline uint32_t packFragmentColor(const glm::vec3& linearRgb, float alpha) {
  return packFragmentColor(ColorTables::get(), linearRgb, alpha);
}

/// The node word of each blend mode (core/blend_mode.hpp). Its alpha byte says what it is:
///   2..255  over: sRGB colour, linear alpha
///   0       additive: the sRGB-encoded emission e = a c, added times the transmittance in front
///   1       multiply: the sRGB-encoded factor t = 1 - a + a c, per channel, on all behind it
/// An over fragment whose alpha byte would be 0 (it adds nothing and hides nothing) becomes the
/// additive word 0, which adds nothing: every rule composites it as before. One whose alpha byte
/// would be 1 keeps 2 (alpha 2/255 instead of 1/255). The stores, the sort and the node's order
/// do not change: the kind rides in the byte every rule already reads (method_math.h blendStep).
inline constexpr uint32_t kAdditiveAlphaByte = 0u;
inline constexpr uint32_t kMultiplyAlphaByte = 1u;
inline constexpr uint32_t kMinOverAlphaByte = 2u;

/// An over word as a node word: alpha byte 0 -> the word 0, alpha byte 1 -> 2.
inline uint32_t overNodeWord(uint32_t word) {
  const uint32_t a8 = word >> 24;
  if (a8 == kAdditiveAlphaByte) return 0u;
  if (a8 == kMultiplyAlphaByte) return (word & 0x00ffffffu) | (kMinOverAlphaByte << 24);
  return word;
}

/// The node word of a fragment of shaded linear colour `rgb` and alpha `alpha` in blend mode
/// `mode`. Premultiplied: `rgb` is the premultiplied colour; with an alpha byte of 0 it is the
/// additive word of emission rgb, else the over word of straight colour rgb / alpha (clamped to
/// 1: a premultiplied colour above its alpha loses the excess).
inline uint32_t packBlendedColor(const ColorTables& t, BlendMode mode, const glm::vec3& rgb,
                                 float alpha) {
  switch (mode) {
    case BlendMode::Over:
      break;
    case BlendMode::Premultiplied: {
      const float a = saturate(alpha);
      if (static_cast<int32_t>(a * 255.0f + 0.5f) == 0)
        return packFragmentColor(t, rgb, 0.0f) & 0x00ffffffu;
      return overNodeWord(packFragmentColor(t, rgb / a, a));
    }
    case BlendMode::Additive:
      return packFragmentColor(t, rgb * saturate(alpha), 0.0f) & 0x00ffffffu;
    case BlendMode::Multiply: {
      const float a = saturate(alpha);
      const glm::vec3 factor = (1.0f - a) + a * rgb;
      return (packFragmentColor(t, factor, 0.0f) & 0x00ffffffu) | (kMultiplyAlphaByte << 24);
    }
  }
  return overNodeWord(packFragmentColor(t, rgb, alpha));
}

/// Unpacks a fragment colour word (or an RGBA8 texel read as a word) to linear RGB and alpha.
inline glm::vec4 unpackFragmentColor(const ColorTables& t, uint32_t rgba) {
  return {t.srgb8ToLinear[rgba & 0xffu], t.srgb8ToLinear[(rgba >> 8) & 0xffu],
          t.srgb8ToLinear[(rgba >> 16) & 0xffu], static_cast<float>(rgba >> 24) * (1.0f / 255.0f)};
}
inline glm::vec4 unpackFragmentColor(uint32_t rgba) {
  return unpackFragmentColor(ColorTables::get(), rgba);
}

}  // namespace mfr
