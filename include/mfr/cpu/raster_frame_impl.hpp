// Inner loops of RasterFrame (templates over the shading mode and the fragment sink, so that each
// capture pass compiles to one tight loop). Included by raster_frame.hpp only.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "mfr/core/color.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

inline TileRect RasterFrame::tileRect(int tile) const {
  const int tx = tile % tilesX_, ty = tile / tilesX_;
  return {tx * tileSize_, ty * tileSize_, std::min(width_, (tx + 1) * tileSize_) - 1,
          std::min(height_, (ty + 1) * tileSize_) - 1};
}

/// While alive, lets oneTBB run `workers` threads even above the hardware's (a no-op below it).
class WorkerLimit {
 public:
  explicit WorkerLimit(int workers) {
    if (workers > resolveThreads(0))
      control_.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(workers));
  }

 private:
  std::optional<tbb::global_control> control_;
};

template <class Fn>
void RasterFrame::forEachTile(Fn&& fn) const {
  const WorkerLimit workers(arenaThreads());
  tbb::task_arena arena(arenaThreads());
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, tileCount(), 1),
                      [&](const tbb::blocked_range<int>& r) {
                        for (int tile = r.begin(); tile != r.end(); ++tile) fn(tile);
                      });
  });
}

namespace detail {
/// The tile passes walk a tile's triangles in binning order, and their set-ups are scattered in
/// memory (a tile's triangles are a sparse subset of the frame's): each pass starts loading the
/// set-up kPrefetchAhead triangles ahead (measured 2026-12-05: the dragon's count pass 6.0 ->
/// 5.1 ms and capture 15.2 -> 12.6 ms at 1024x1024, docs/PERFORMANCE.md).
inline constexpr int kPrefetchAhead = 4;
[[gnu::always_inline]] inline void prefetchSetup(const TriangleSetup& t) {
  const char* p = reinterpret_cast<const char*>(&t);
  for (size_t line = 0; line < sizeof(TriangleSetup); line += 64) __builtin_prefetch(p + line);
  __builtin_prefetch(p + sizeof(TriangleSetup) - 1);
}

// Integer quotients for the row spans. A double division gives the quotient to within one (the
// operands stay below 2^51), an exact integer check fixes it: much cheaper than a 64-bit idiv.
inline int64_t floorDivPositive(int64_t a, int64_t b) {  // a >= 0, b > 0
  int64_t q = static_cast<int64_t>(static_cast<double>(a) / static_cast<double>(b));
  while (q * b > a) --q;
  while ((q + 1) * b <= a) ++q;
  return q;
}
inline int64_t ceilDivPositive(int64_t a, int64_t b) {  // a > 0, b > 0
  int64_t q = static_cast<int64_t>(static_cast<double>(a) / static_cast<double>(b));
  while (q * b < a) ++q;
  while (q > 0 && (q - 1) * b >= a) --q;
  return q;
}

/// The three edge functions of a set-up from the centre of pixel (x0, y0), in 1/256 pixel: edge i
/// runs from vertex (i+1)%3 to (i+2)%3, w_i = B_i (py - ay) + A_i (px - ax), with the top-left
/// rule's -1 for the other edges (bias) folded into row; one pixel right adds stepX, one down
/// stepY. Every rasterizer of the frame (scalar, multisampled, 8-lane) starts from it.
struct EdgeFunctions {
  int64_t A[3], B[3], stepX[3], stepY[3], row[3], bias[3];
};
inline EdgeFunctions edgeFunctions(const TriangleSetup& t, int x0, int y0) {
  EdgeFunctions e;
  const int64_t px0 = static_cast<int64_t>(x0) * 256 + 128;
  const int64_t py0 = static_cast<int64_t>(y0) * 256 + 128;
  for (int i = 0; i < 3; ++i) {
    const int a = (i + 1) % 3, b = (i + 2) % 3;
    e.A[i] = static_cast<int64_t>(t.y[a]) - t.y[b];
    e.B[i] = static_cast<int64_t>(t.x[b]) - t.x[a];
    e.stepX[i] = e.A[i] * 256;
    e.stepY[i] = e.B[i] * 256;
    e.bias[i] = (t.topLeft >> i) & 1 ? 0 : -1;
    e.row[i] = e.B[i] * (py0 - t.y[a]) + e.A[i] * (px0 - t.x[a]) + e.bias[i];
  }
  return e;
}

/// Narrows [xs, xe] to the pixels of a row (x0..x1, edge values row[i] at x0, steps stepX[i])
/// where all three edge functions are >= 0: exact integer bounds; an edge that is non-negative at
/// both ends of the row cannot cut it, by linearity. Leaves xs > xe when none is.
inline void rowSpan(const int64_t row[3], const int64_t stepX[3], int x0, int x1, int& xs,
                    int& xe) {
  for (int i = 0; i < 3 && xs <= xe; ++i) {
    const int64_t r = row[i], st = stepX[i];
    if (r >= 0 && r + st * (x1 - x0) >= 0) continue;
    if (st > 0) {  // r < 0 here: the first x with w >= 0
      xs = static_cast<int>(std::max<int64_t>(xs, x0 + ceilDivPositive(-r, st)));
    } else if (st < 0 && r >= 0) {  // the last x with w >= 0
      xe = static_cast<int>(std::min<int64_t>(xe, x0 + floorDivPositive(r, -st)));
    } else {
      xe = xs - 1;  // st <= 0 and r < 0: nothing on this row
    }
  }
}

static_assert(static_cast<uint32_t>(TextureWrap::Repeat) == method_math::kTextureWrapRepeat &&
              static_cast<uint32_t>(TextureWrap::ClampToEdge) == method_math::kTextureWrapClamp &&
              static_cast<uint32_t>(TextureWrap::MirroredRepeat) ==
                  method_math::kTextureWrapMirror);

/// The integer part of a texel coordinate (floored) before wrapping: exact for |f| < 1e9; beyond,
/// any value past the edge for clamp, else f reduced exactly by fmod over the wrap's period (n, 2n
/// mirrored) so the conversion cannot overflow; 0 for NaN and infinities.
inline int texelIndex(float f, int n, TextureWrap wrap) {
  if (!std::isfinite(f)) return 0;
  if (std::abs(f) < 1e9f) return static_cast<int>(f);
  if (wrap == TextureWrap::ClampToEdge) return f < 0.0f ? -1 : n;
  const int period = wrap == TextureWrap::MirroredRepeat ? 2 * n : n;
  return static_cast<int>(std::fmod(f, static_cast<float>(period)));
}

/// Texel i of an RGBA8 texture (sRGB colour, linear alpha) in linear RGB and alpha: the fragment
/// colour word's decode (the scalar sampler's and the 8-lane sampler's, raster_span_avx2.hpp).
inline glm::vec4 texelColor(const ColorTables& t, const uint8_t* rgba, size_t i) {
  const uint8_t* p = rgba + i * 4;
  return unpackFragmentColor(t, static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
                                    static_cast<uint32_t>(p[2]) << 16 |
                                    static_cast<uint32_t>(p[3]) << 24);
}

/// One sample of `tex` at `uv` by `sampler`: bilinear (texel centres at half-integers, the four
/// neighbours wrapped) or nearest (the texel containing uv), each axis wrapped by
/// method_math::wrapTexel; returns linear RGB and alpha.
inline glm::vec4 sampleTexture(const Texture& tex, const TextureSampler& sampler, glm::vec2 uv) {
  const ColorTables& t = ColorTables::get();
  const auto modeS = static_cast<uint32_t>(sampler.wrapS);
  const auto modeT = static_cast<uint32_t>(sampler.wrapT);
  auto texel = [&](int x, int y) {
    return texelColor(t, tex.rgba.data(), static_cast<size_t>(y) * tex.width + x);
  };
  if (sampler.filter == TextureFilter::Nearest) {
    const float fx = std::floor(uv.x * static_cast<float>(tex.width));
    const float fy = std::floor(uv.y * static_cast<float>(tex.height));
    return texel(
        method_math::wrapTexel(texelIndex(fx, tex.width, sampler.wrapS), tex.width, modeS),
        method_math::wrapTexel(texelIndex(fy, tex.height, sampler.wrapT), tex.height, modeT));
  }
  const float fx = uv.x * static_cast<float>(tex.width) - 0.5f;
  const float fy = uv.y * static_cast<float>(tex.height) - 0.5f;
  const float flx = std::floor(fx), fly = std::floor(fy);
  const float ax = fx - flx, ay = fy - fly;
  const int ix = texelIndex(flx, tex.width, sampler.wrapS);
  const int iy = texelIndex(fly, tex.height, sampler.wrapT);
  const int x0 = method_math::wrapTexel(ix, tex.width, modeS);
  const int x1 = method_math::wrapTexel(ix + 1, tex.width, modeS);
  const int y0 = method_math::wrapTexel(iy, tex.height, modeT);
  const int y1 = method_math::wrapTexel(iy + 1, tex.height, modeT);
  const glm::vec4 top = glm::mix(texel(x0, y0), texel(x1, y0), ax);
  const glm::vec4 bottom = glm::mix(texel(x0, y1), texel(x1, y1), ax);
  return glm::mix(top, bottom, ay);
}
}  // namespace detail

template <ShadeMode Mode>
[[gnu::always_inline]] inline bool RasterFrame::surface(const TriangleSetup& t,
                                                        const ShadeMaterial& m, float l0, float l1,
                                                        float l2, glm::vec4& base) const {
  const bool needsAlphaTest = m.mode == AlphaMode::Mask;
  if constexpr (Mode == ShadeMode::Coverage) {
    if (!needsAlphaTest) return true;
  }
  base = glm::vec4(m.color, m.alpha);
  if (m.texture != nullptr || t.hasColor) {
    const float invQ = 1.0f / (t.invW[0] * l0 + t.invW[1] * l1 + t.invW[2] * l2);
    if (m.texture != nullptr) {
      const glm::vec2 uv = (t.uvW[0] * l0 + t.uvW[1] * l1 + t.uvW[2] * l2) * invQ;
      base *= detail::sampleTexture(*m.texture, m.sampler, uv);
    }
    if (t.hasColor) {  // the perspective-correct vertex colour, after the texture
      const glm::vec4* c = colors_[static_cast<size_t>(&t - setups_.data())].colorW;
      base *= (c[0] * l0 + c[1] * l1 + c[2] * l2) * invQ;
    }
  }
  if (needsAlphaTest) {
    if (base.a < m.cutoff) return false;
    base.a = 1.0f;
  } else if (m.mode == AlphaMode::Opaque) {
    base.a = 1.0f;
  }
  if (m.alphaOverridden) base.a = m.overrideAlpha;
  return true;
}

[[gnu::always_inline]] inline void RasterFrame::shade(const TriangleSetup& t, float l0, float l1,
                                                      float l2, float px, float py,
                                                      const glm::vec4& base, Fragment& f) const {
  // headlight: the light sits at the eye, so diffuse = |n.v| (scalar code: glm's vec3 is not
  // vectorised and this is the hottest loop of every capture pass)
  const float nx = t.normalW[0].x * l0 + t.normalW[1].x * l1 + t.normalW[2].x * l2;
  const float ny = t.normalW[0].y * l0 + t.normalW[1].y * l1 + t.normalW[2].y * l2;
  const float nz = t.normalW[0].z * l0 + t.normalW[1].z * l1 + t.normalW[2].z * l2;
  const float dx = px * rayScaleX_ + rayBiasX_;
  const float dy = py * rayScaleY_ + rayBiasY_;
  const float nn = (nx * nx + ny * ny + nz * nz) * (dx * dx + dy * dy + 1.0f);
  const float ndotv =
      nn > 0.0f ? std::clamp((nz - nx * dx - ny * dy) / std::sqrt(nn), -1.0f, 1.0f) : 1.0f;
  const float light = kAmbient + (1.0f - kAmbient) * std::fabs(ndotv);
  f.rgba = packBlendedColor(*colorTables_, materials_[t.material].blend, glm::vec3(base) * light,
                            base.a);
  f.ndotv = ndotv;
}

template <ShadeMode Mode, class Sink>
inline void RasterFrame::rasterizeRect(const TriangleSetup& t, int x0, int y0, int x1, int y1,
                                       Sink& sink) const {
  x0 = std::max(x0, t.minX);
  y0 = std::max(y0, t.minY);
  x1 = std::min(x1, t.maxX);
  y1 = std::min(y1, t.maxY);
  if (x0 > x1 || y0 > y1) return;
  detail::EdgeFunctions edges = detail::edgeFunctions(t, x0, y0);
  int64_t(&row)[3] = edges.row;
  const int64_t(&stepX)[3] = edges.stepX;
  const int64_t(&stepY)[3] = edges.stepY;
  const int64_t(&bias)[3] = edges.bias;
  const float dz1 = t.z[1] - t.z[0], dz2 = t.z[2] - t.z[0];
  const ShadeMaterial& material = materials_[t.material];
  Fragment f;
  f.prim = t.prim;
  f.rgba = 0;
  f.ndotv = 0.0f;
  for (int y = y0; y <= y1; ++y) {
    // the span of this row where all three edge functions are >= 0 (exact integer bounds; an
    // edge that is non-negative at both ends of the row cannot cut it, by linearity), so thin
    // triangles cost their pixels, not their bounding boxes
    int xs = x0, xe = x1;
    detail::rowSpan(row, stepX, x0, x1, xs, xe);
    const int64_t skip = xs - x0;
    int64_t w1 = row[1] + skip * stepX[1], w2 = row[2] + skip * stepX[2];
    const uint32_t rowPixel = static_cast<uint32_t>(y) * static_cast<uint32_t>(width_);
    for (int x = xs; x <= xe; ++x, w1 += stepX[1], w2 += stepX[2]) {
      const float l1 = static_cast<float>(w1 - bias[1]) * t.invArea;
      const float l2 = static_cast<float>(w2 - bias[2]) * t.invArea;
      const float l0 = 1.0f - l1 - l2;
      glm::vec4 base;
      if (!surface<Mode>(t, material, l0, l1, l2, base)) continue;  // alpha test
      const float z = t.z[0] + l1 * dz1 + l2 * dz2;
      f.depth = z > 0.0f ? (z < 1.0f ? z : 1.0f) : 0.0f;
      f.pixel = rowPixel + static_cast<uint32_t>(x);
      if (!sink.accept(f.pixel, f.depth)) continue;  // early test before shading
      if constexpr (Mode == ShadeMode::Full)
        shade(t, l0, l1, l2, static_cast<float>(x), static_cast<float>(y), base, f);
      sink.emit(f);
    }
    row[0] += stepY[0];
    row[1] += stepY[1];
    row[2] += stepY[2];
  }
}

template <ShadeMode Mode, class Sink>
inline void RasterFrame::rasterizeRectSamples(const TriangleSetup& t, int x0, int y0, int x1,
                                              int y1, Sink& sink) const {
  x0 = std::max(x0, t.minX);
  y0 = std::max(y0, t.minY);
  x1 = std::min(x1, t.maxX);
  y1 = std::min(y1, t.maxY);
  if (x0 > x1 || y0 > y1) return;
  const int samples = samples_;
  // the centre's edge values as rasterizeRect has them, and each sample's offset from them
  detail::EdgeFunctions edges = detail::edgeFunctions(t, x0, y0);
  int64_t(&row)[3] = edges.row;
  const int64_t(&stepX)[3] = edges.stepX;
  const int64_t(&stepY)[3] = edges.stepY;
  const int64_t(&bias)[3] = edges.bias;
  int64_t offset[kMaxSamples][3];
  int64_t widest[3];  // per edge, the largest sample offset: a row's pixels lie in its span
  for (int i = 0; i < 3; ++i) {
    widest[i] = INT64_MIN;
    for (int s = 0; s < samples; ++s) {
      offset[s][i] = edges.A[i] * sampleX_[s] + edges.B[i] * sampleY_[s];
      widest[i] = std::max(widest[i], offset[s][i]);
    }
  }
  const float dz1 = t.z[1] - t.z[0], dz2 = t.z[2] - t.z[0];
  const ShadeMaterial& material = materials_[t.material];
  const bool perPixel = storage_ == SampleStorage::Pixel;
  Fragment f;
  f.prim = t.prim;
  f.rgba = 0;
  f.ndotv = 0.0f;
  for (int y = y0; y <= y1; ++y) {
    // the row's pixels: a span holding every sample's (each edge at its largest sample offset,
    // which no sample's edge value exceeds); the samples are tested per pixel below
    const int64_t widestRow[3] = {row[0] + widest[0], row[1] + widest[1], row[2] + widest[2]};
    int xs = x0, xe = x1;
    detail::rowSpan(widestRow, stepX, x0, x1, xs, xe);
    for (int x = xs; x <= xe; ++x) {
      const int64_t dx = x - x0;
      const int64_t w0 = row[0] + dx * stepX[0], w1 = row[1] + dx * stepX[1],
                    w2 = row[2] + dx * stepX[2];
      uint32_t mask = 0;
      for (int s = 0; s < samples; ++s)
        if (w0 + offset[s][0] >= 0 && w1 + offset[s][1] >= 0 && w2 + offset[s][2] >= 0)
          mask |= 1u << s;
      // one fragment per covered sample (per-sample storage), or one for the pixel at its first
      // covered sample, carrying the mask (per-pixel storage)
      for (uint32_t left = perPixel && mask ? 1u << std::countr_zero(mask) : mask; left != 0;
           left &= left - 1) {
        const int s = std::countr_zero(left);
        const float l1 = static_cast<float>(w1 + offset[s][1] - bias[1]) * t.invArea;
        const float l2 = static_cast<float>(w2 + offset[s][2] - bias[2]) * t.invArea;
        const float l0 = 1.0f - l1 - l2;
        glm::vec4 base;
        if (!surface<Mode>(t, material, l0, l1, l2, base)) continue;  // alpha test
        const float z = t.z[0] + l1 * dz1 + l2 * dz2;
        const float depth = z > 0.0f ? (z < 1.0f ? z : 1.0f) : 0.0f;
        f.depth = perPixel ? withCoverage(depth, mask, samples) : depth;
        f.pixel = static_cast<uint32_t>(y) * static_cast<uint32_t>(width_) +
                  (perPixel ? static_cast<uint32_t>(x) : static_cast<uint32_t>(x * samples + s));
        if (!sink.accept(f.pixel, f.depth)) continue;  // early test before shading
        if constexpr (Mode == ShadeMode::Full)
          shade(t, l0, l1, l2, static_cast<float>(x) + static_cast<float>(sampleX_[s]) / 256.0f,
                static_cast<float>(y) + static_cast<float>(sampleY_[s]) / 256.0f, base, f);
        sink.emit(f);
      }
    }
    row[0] += stepY[0];
    row[1] += stepY[1];
    row[2] += stepY[2];
  }
}

template <ShadeMode Mode, class Sink>
void RasterFrame::rasterizeTile(int tile, Sink&& sink) const {
  const TileRect r = tileRect(tile);
  const uint32_t* end = tileEnd(tile);
  if (samples_ > 1) {  // the image pixels of the tile (a tile holds whole pixels)
    const int per = storagePerPixel();
    for (const uint32_t* it = tileBegin(tile); it != end; ++it)
      rasterizeRectSamples<Mode>(setups_[*it], r.x0 / per, r.y0, r.x1 / per, r.y1, sink);
    return;
  }
  for (const uint32_t* it = tileBegin(tile); it != end; ++it) {
    if (end - it > detail::kPrefetchAhead)
      detail::prefetchSetup(setups_[it[detail::kPrefetchAhead]]);
    rasterizeRect<Mode>(setups_[*it], r.x0, r.y0, r.x1, r.y1, sink);
  }
}

template <ShadeMode Mode, class Sink>
void RasterFrame::rasterizeTriangle(size_t setupIndex, Sink&& sink) const {
  if (samples_ > 1)
    rasterizeRectSamples<Mode>(setups_[setupIndex], 0, 0, imageWidth_ - 1, height_ - 1, sink);
  else
    rasterizeRect<Mode>(setups_[setupIndex], 0, 0, width_ - 1, height_ - 1, sink);
}

}  // namespace mfr
