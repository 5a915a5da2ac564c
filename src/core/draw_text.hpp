// Bitmap drawing shared by the raster figures (colour-map legends, line plots): single pixels and
// stb_easy_font text scaled by an integer factor, into an sRGB8 Image8. Internal to the library.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/image.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

namespace mfr::detail {

/// Sets one pixel to an sRGB colour in [0, 1] (alpha 255); outside the image does nothing.
inline void putPixel(Image8& img, int x, int y, glm::vec3 srgb) {
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  uint8_t* p = &img.rgba[(static_cast<size_t>(y) * img.width + x) * 4];
  p[0] = static_cast<uint8_t>(srgb.r * 255.0f + 0.5f);
  p[1] = static_cast<uint8_t>(srgb.g * 255.0f + 0.5f);
  p[2] = static_cast<uint8_t>(srgb.b * 255.0f + 0.5f);
  p[3] = 255;
}

/// Vertex bytes of stb_easy_font's largest glyph ('X': 11 quads); ~270 is only the average.
inline constexpr size_t kTextBytesPerChar = 11 * 64;

/// Draws text with its top-left corner at (x, y) with stb_easy_font's quads, scaled by an integer
/// factor. The vertex buffer holds the largest glyph for every character, so no stroke is dropped.
inline void drawText(Image8& img, int x, int y, const std::string& text, int scale,
                     glm::vec3 color) {
  std::vector<char> buffer(text.size() * kTextBytesPerChar + 64);
  std::string copy = text;
  const int quads = stb_easy_font_print(0.0f, 0.0f, copy.data(), nullptr, buffer.data(),
                                        static_cast<int>(buffer.size()));
  struct Vertex {
    float x, y, z;
    unsigned char c[4];
  };
  const Vertex* v = reinterpret_cast<const Vertex*>(buffer.data());
  for (int q = 0; q < quads; ++q) {
    const int x0 = static_cast<int>(v[q * 4].x) * scale, y0 = static_cast<int>(v[q * 4].y) * scale;
    const int x1 = static_cast<int>(v[q * 4 + 2].x) * scale;
    const int y1 = static_cast<int>(v[q * 4 + 2].y) * scale;
    for (int yy = y0; yy < y1; ++yy)
      for (int xx = x0; xx < x1; ++xx) putPixel(img, x + xx, y + yy, color);
  }
}

/// Width in pixels of text drawn by drawText at the given scale.
inline int textWidth(const std::string& text, int scale) {
  std::string copy = text;
  return stb_easy_font_width(copy.data()) * scale;
}

}  // namespace mfr::detail
