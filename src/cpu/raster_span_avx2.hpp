// The capture pass's tile rasterizer on 8 lanes (AVX2), chosen at run time from activeIsa()
// (k+-buffer paper, Vasilakis & Fudos 2014, sec. 3.2 and Algorithm 3: the k+ test runs before
// the fragment is shaded, against the pixel's current maximum).
//
// Per row of a triangle, 8 pixels at a time:
//   1. the covered pixels: a triangle at most 8 pixels wide in the tile tests the three exact edge
//      values of the row's 8 lanes (one compare each, no span set-up), a wider one finds the row
//      span (coveredSpan, the scalar rasterizeRect's bounds);
//   2. barycentrics and depth of the 8 pixel centres: the edge values are exact integers, carried
//      in doubles (exact below 2^53) and rounded once to float, like the scalar int64 -> float;
//   3. the k+ test on all 8 (kbuffer compositing; a hybrid sink's cull depths are all INT32_MAX,
//      since it shades every fragment): each pixel of the tile has a 32-bit "cull depth" (below),
//      compared with the 8 depths' bits at once;
//   4. a step with at least kDirectLanes passing lanes is shaded as it is; fewer (a small or thin
//      triangle has one to three pixels per row) are packed with the next rows' (PendingLanes)
//      and shaded 8 at a time, the rest at the triangle's end: a triangle reaches a pixel at most
//      once, so no early test of another of its pixels depends on the deferred insertions;
//   5. shading (n.v, headlight, sRGB encode with the colour tables as gathers) on the 8 lanes,
//      each lane with its own pixel (x, y); the surviving lanes, in order, go to the sink's scalar
//      insertion (inlined: a call into baseline SSE code with the upper halves dirty is slow).
// Every float operation is the scalar path's, in the same order, without FMA contraction (the
// function is compiled for "avx2" only, so there is no fused multiply-add to contract into):
// the captured fragments, counters and images are bit-identical to the scalar path's.
//
// Cull depth of a tile pixel (tile-local, row stride = tile size, int32):
//   store not full:       INT32_MAX   (every depth passes: depth bits are <= 0x3f800000)
//   store full (k > 0):   hi(max) + (lo(max) != 0), the smallest depth bits not nearer than
//                         the maximum node (the colour 0 tie-break, as the scalar early test)
//   no slots (k == 0):    0           (nothing passes)
// so "passes the early k+ test" is (depth bits < cull depth), one signed compare.
//
// A tile whose triangles all have non-masked materials blending "over" takes the wide path
// (their alpha test cannot reject, so testing before the surface is the scalar order; the base
// colour is the material's, times the texture sampled on the lanes (LaneTexture: bilinear or
// nearest, every wrap mode, the texels of the lanes in use read one by one) and the
// perspective-correct vertex colour, per lane in the scalar operation order); any other tile
// runs the scalar rasterizeTile on the same sink.
#pragma once

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MFR_HAS_AVX2_KERNELS 1
#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "mfr/cpu/raster_frame.hpp"

namespace mfr {
namespace detail {

#define MFR_TARGET_AVX2 __attribute__((target("avx2")))

/// The cull depth of one store (see the file comment).
inline int32_t cullDepthOf(const FragmentNode* slots, uint32_t count, uint32_t capacity) {
  if (count < capacity) return INT32_MAX;
  if (count == 0) return 0;
  const FragmentNode max = slots[0];
  return static_cast<int32_t>((max >> 32) + ((max & 0xffffffffu) != 0 ? 1 : 0));
}

/// The sRGB codes of 8 linear values, the codes packFragmentColor computes: clamp (NaN -> 0),
/// the code of the smallest input of the value's bucket round(c * 4095) (bucketLowSrgb8), one
/// more when c reaches the next code's exact lower bound. Two gathers (the scalar encode's guess
/// may be one too high or too low and needs three).
[[gnu::always_inline]] inline MFR_TARGET_AVX2 __m256i encodeSrgb8x8(const ColorTables& tables,
                                                                    __m256 v) {
  const int* low = reinterpret_cast<const int*>(tables.bucketLowSrgb8.data());
  const float* lowerBound = tables.lowerBound.data();
  const __m256 c = _mm256_min_ps(_mm256_max_ps(v, _mm256_setzero_ps()), _mm256_set1_ps(1.0f));
  const __m256i index = _mm256_cvttps_epi32(
      _mm256_add_ps(_mm256_mul_ps(c, _mm256_set1_ps(4095.0f)), _mm256_set1_ps(0.5f)));
  // 4-byte gathers of the byte table (the last index reads into lowerBound, in the same struct)
  const __m256i code =
      _mm256_and_si256(_mm256_i32gather_epi32(low, index, 1), _mm256_set1_epi32(0xff));
  const __m256 above =
      _mm256_i32gather_ps(lowerBound, _mm256_add_epi32(code, _mm256_set1_epi32(1)), 4);
  return _mm256_sub_epi32(code, _mm256_castps_si256(_mm256_cmp_ps(c, above, _CMP_GE_OQ)));
}

/// The pixels [xs, xe] of a row whose three edge values (row[i] at x0, stepping stepX[i]) are
/// all >= 0, exactly as rasterizeRect finds them (xe < xs: none).
[[gnu::always_inline]] inline void coveredSpan(const int64_t row[3], const int64_t stepX[3], int x0,
                                               int x1, int& xs, int& xe) {
  for (int i = 0; i < 3 && xs <= xe; ++i) {
    const int64_t rr = row[i], st = stepX[i];
    if (rr >= 0 && rr + st * (x1 - x0) >= 0) continue;
    if (st > 0) {
      xs = static_cast<int>(std::max<int64_t>(xs, x0 + detail::ceilDivPositive(-rr, st)));
    } else if (st < 0 && rr >= 0) {
      xe = static_cast<int>(std::min<int64_t>(xe, x0 + detail::floorDivPositive(rr, -st)));
    } else {
      xe = xs - 1;
    }
  }
}

/// One triangle's shading on 8 lanes: the interpolated normal against the view ray (the
/// headlight of RasterFrame::surface, |n.v| with the scalar path's clamp and its 1 for a zero
/// normal), the lit base colour sRGB-encoded with the frame's tables, the alpha byte.
struct LaneShading {
  __m256 n0x, n1x, n2x, n0y, n1y, n2y, n0z, n1z, n2z;
  __m256 rayScaleX, rayBiasX, baseR, baseG, baseB;
  __m256i alpha;

  [[gnu::always_inline]] MFR_TARGET_AVX2 LaneShading(const ShadingInputs& in,
                                                     const TriangleSetup& t, glm::vec4 base,
                                                     uint32_t alphaByte)
      : n0x(_mm256_set1_ps(t.normalW[0].x)),
        n1x(_mm256_set1_ps(t.normalW[1].x)),
        n2x(_mm256_set1_ps(t.normalW[2].x)),
        n0y(_mm256_set1_ps(t.normalW[0].y)),
        n1y(_mm256_set1_ps(t.normalW[1].y)),
        n2y(_mm256_set1_ps(t.normalW[2].y)),
        n0z(_mm256_set1_ps(t.normalW[0].z)),
        n1z(_mm256_set1_ps(t.normalW[1].z)),
        n2z(_mm256_set1_ps(t.normalW[2].z)),
        rayScaleX(_mm256_set1_ps(in.rayScaleX)),
        rayBiasX(_mm256_set1_ps(in.rayBiasX)),
        baseR(_mm256_set1_ps(base.r)),
        baseG(_mm256_set1_ps(base.g)),
        baseB(_mm256_set1_ps(base.b)),
        alpha(_mm256_set1_epi32(static_cast<int>(alphaByte))) {}

  /// The packed colour words of pixels x .. x + 7 at barycentrics (l1, l2); their n.v in `ndotv`.
  [[gnu::always_inline]] MFR_TARGET_AVX2 __m256i shade(const ColorTables& tables, __m256 l1,
                                                       __m256 l2, __m256 px, __m256 dy,
                                                       __m256 dySquared, __m256& ndotv) const {
    return shadeBase(tables, l1, l2, px, dy, dySquared, ndotv, baseR, baseG, baseB, alpha);
  }

  /// shade() with a base colour and alpha word per lane (vertex colours).
  [[gnu::always_inline]] MFR_TARGET_AVX2 __m256i shadeBase(const ColorTables& tables, __m256 l1,
                                                           __m256 l2, __m256 px, __m256 dy,
                                                           __m256 dySquared, __m256& ndotv,
                                                           __m256 r, __m256 g, __m256 b,
                                                           __m256i alphaWord) const {
    const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
    const __m256 minusOne = _mm256_set1_ps(-1.0f);
    const __m256 absMask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
    const __m256 ambient = _mm256_set1_ps(kAmbient), diffuse = _mm256_set1_ps(1.0f - kAmbient);
    const __m256 l0 = _mm256_sub_ps(_mm256_sub_ps(one, l1), l2);
    const __m256 nx = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0x, l0), _mm256_mul_ps(n1x, l1)),
                                    _mm256_mul_ps(n2x, l2));
    const __m256 ny = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0y, l0), _mm256_mul_ps(n1y, l1)),
                                    _mm256_mul_ps(n2y, l2));
    const __m256 nz = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0z, l0), _mm256_mul_ps(n1z, l1)),
                                    _mm256_mul_ps(n2z, l2));
    const __m256 dx = _mm256_add_ps(_mm256_mul_ps(px, rayScaleX), rayBiasX);
    const __m256 nn =
        _mm256_mul_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(nx, nx), _mm256_mul_ps(ny, ny)),
                                    _mm256_mul_ps(nz, nz)),
                      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), dySquared), one));
    const __m256 ratio = _mm256_div_ps(
        _mm256_sub_ps(_mm256_sub_ps(nz, _mm256_mul_ps(nx, dx)), _mm256_mul_ps(ny, dy)),
        _mm256_sqrt_ps(nn));
    // std::clamp(v, -1, 1): v < -1 ? -1 : (1 < v ? 1 : v), NaN stays
    __m256 clamped = _mm256_blendv_ps(ratio, minusOne, _mm256_cmp_ps(ratio, minusOne, _CMP_LT_OQ));
    clamped = _mm256_blendv_ps(clamped, one, _mm256_cmp_ps(one, clamped, _CMP_LT_OQ));
    ndotv = _mm256_blendv_ps(one, clamped, _mm256_cmp_ps(nn, zero, _CMP_GT_OQ));
    const __m256 light =
        _mm256_add_ps(ambient, _mm256_mul_ps(diffuse, _mm256_and_ps(ndotv, absMask)));
    const __m256i word = _mm256_or_si256(
        _mm256_or_si256(
            detail::encodeSrgb8x8(tables, _mm256_mul_ps(r, light)),
            _mm256_slli_epi32(detail::encodeSrgb8x8(tables, _mm256_mul_ps(g, light)), 8)),
        _mm256_or_si256(
            _mm256_slli_epi32(detail::encodeSrgb8x8(tables, _mm256_mul_ps(b, light)), 16),
            alphaWord));
    // overNodeWord (the lanes take over materials only): alpha byte 0 -> the word 0, 1 -> 2
    const __m256i alphaByte = _mm256_srli_epi32(alphaWord, 24);
    const __m256i kept =
        _mm256_andnot_si256(_mm256_cmpeq_epi32(alphaByte, _mm256_setzero_si256()), word);
    return _mm256_add_epi32(kept,
                            _mm256_and_si256(_mm256_cmpeq_epi32(alphaByte, _mm256_set1_epi32(1)),
                                             _mm256_set1_epi32(1 << 24)));
  }
};

/// The integer texel coordinates (texelIndex, each axis then wrapTexel) of 8 lanes: lanes whose
/// floored coordinate is finite, below 1e9 in magnitude and inside [0, n - 1] (with i1, the
/// bilinear pair's second texel, [0, n - 2]) need no wrapping (the common case, all on lanes);
/// otherwise every lane goes through the scalar functions.
[[gnu::always_inline]] inline MFR_TARGET_AVX2 void wrapTexelLanes(__m256 floored, int n,
                                                                  TextureWrap wrap, __m256i& i0,
                                                                  __m256i* i1) {
  const __m256 absMask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256 inRange =
      _mm256_cmp_ps(_mm256_and_ps(floored, absMask), _mm256_set1_ps(1e9f), _CMP_LT_OQ);
  const __m256i index = _mm256_cvttps_epi32(floored);  // exact: floored, |f| < 1e9
  const int last = n - 1 - (i1 != nullptr ? 1 : 0);
  const __m256i inside =
      _mm256_andnot_si256(_mm256_or_si256(_mm256_cmpgt_epi32(_mm256_setzero_si256(), index),
                                          _mm256_cmpgt_epi32(index, _mm256_set1_epi32(last))),
                          _mm256_castps_si256(inRange));
  if (_mm256_movemask_ps(_mm256_castsi256_ps(inside)) == 0xff) {
    i0 = index;
    if (i1 != nullptr) i1[0] = _mm256_add_epi32(index, _mm256_set1_epi32(1));
    return;
  }
  alignas(32) float f[8];
  alignas(32) int32_t a[8], b[8];
  _mm256_store_ps(f, floored);
  const auto mode = static_cast<uint32_t>(wrap);
  for (int lane = 0; lane < 8; ++lane) {
    const int i = texelIndex(f[lane], n, wrap);
    a[lane] = method_math::wrapTexel(i, n, mode);
    b[lane] = method_math::wrapTexel(i + 1, n, mode);
  }
  i0 = _mm256_load_si256(reinterpret_cast<const __m256i*>(a));
  if (i1 != nullptr) i1[0] = _mm256_load_si256(reinterpret_cast<const __m256i*>(b));
}

/// A texture sampled on 8 lanes, as detail::sampleTexture samples it (the same float operations
/// in the same order: bilinear with texel centres at half-integers and glm::mix's x (1 - a) + y a,
/// or nearest; texels decoded by the sRGB table, alpha times 1/255). The texels of the lanes in
/// use are read one by one (a step shades one to eight lanes, and on Zen 3 a gather of 8 costs
/// more than 8 loads), the filtering runs on the lanes.
struct LaneTexture {
  const uint8_t* rgba = nullptr;
  const ColorTables* tables = nullptr;
  int width = 0, height = 0;
  TextureSampler sampler;

  /// Texel (x[lane], y[lane]) of each lane set in `bits` into out[channel][lane].
  [[gnu::always_inline]] void texels(const int32_t* x, const int32_t* y, uint32_t bits,
                                     float (*out)[8]) const {
    for (; bits != 0; bits &= bits - 1) {
      const int lane = std::countr_zero(bits);
      const glm::vec4 c = texelColor(*tables, rgba, static_cast<size_t>(y[lane]) * width + x[lane]);
      for (int ch = 0; ch < 4; ++ch) out[ch][lane] = c[ch];
    }
  }

  /// The linear RGBA of the lanes set in `bits` at texture coordinates (u, v) (the other lanes:
  /// unspecified).
  [[gnu::always_inline]] MFR_TARGET_AVX2 void sample(__m256 u, __m256 v, uint32_t bits,
                                                     __m256* out) const {
    const __m256 w = _mm256_set1_ps(static_cast<float>(width));
    const __m256 h = _mm256_set1_ps(static_cast<float>(height));
    alignas(32) int32_t x0[8], x1[8], y0[8], y1[8];
    alignas(32) float t[4][4][8];  // corner (x0y0, x1y0, x0y1, x1y1), channel, lane (unused: unset)
    __m256i a, b;
    if (sampler.filter == TextureFilter::Nearest) {
      wrapTexelLanes(_mm256_floor_ps(_mm256_mul_ps(u, w)), width, sampler.wrapS, a, nullptr);
      _mm256_store_si256(reinterpret_cast<__m256i*>(x0), a);
      wrapTexelLanes(_mm256_floor_ps(_mm256_mul_ps(v, h)), height, sampler.wrapT, a, nullptr);
      _mm256_store_si256(reinterpret_cast<__m256i*>(y0), a);
      texels(x0, y0, bits, t[0]);
      for (int ch = 0; ch < 4; ++ch) out[ch] = _mm256_load_ps(t[0][ch]);
      return;
    }
    const __m256 half = _mm256_set1_ps(0.5f), one = _mm256_set1_ps(1.0f);
    const __m256 fx = _mm256_sub_ps(_mm256_mul_ps(u, w), half);
    const __m256 fy = _mm256_sub_ps(_mm256_mul_ps(v, h), half);
    const __m256 flx = _mm256_floor_ps(fx), fly = _mm256_floor_ps(fy);
    const __m256 ax = _mm256_sub_ps(fx, flx), ay = _mm256_sub_ps(fy, fly);
    wrapTexelLanes(flx, width, sampler.wrapS, a, &b);
    _mm256_store_si256(reinterpret_cast<__m256i*>(x0), a);
    _mm256_store_si256(reinterpret_cast<__m256i*>(x1), b);
    wrapTexelLanes(fly, height, sampler.wrapT, a, &b);
    _mm256_store_si256(reinterpret_cast<__m256i*>(y0), a);
    _mm256_store_si256(reinterpret_cast<__m256i*>(y1), b);
    texels(x0, y0, bits, t[0]);
    texels(x1, y0, bits, t[1]);
    texels(x0, y1, bits, t[2]);
    texels(x1, y1, bits, t[3]);
    const __m256 bx = _mm256_sub_ps(one, ax), by = _mm256_sub_ps(one, ay);
    for (int ch = 0; ch < 4; ++ch) {
      const __m256 top = _mm256_add_ps(_mm256_mul_ps(_mm256_load_ps(t[0][ch]), bx),
                                       _mm256_mul_ps(_mm256_load_ps(t[1][ch]), ax));
      const __m256 bottom = _mm256_add_ps(_mm256_mul_ps(_mm256_load_ps(t[2][ch]), bx),
                                          _mm256_mul_ps(_mm256_load_ps(t[3][ch]), ax));
      out[ch] = _mm256_add_ps(_mm256_mul_ps(top, by), _mm256_mul_ps(bottom, ay));
    }
  }
};

/// A textured, vertex-coloured or alpha-masked triangle's base colour on 8 lanes, as
/// RasterFrame::surface computes it: the material's colour and alpha, times the texture sampled
/// at the perspective-correct uv (uvW interpolated, times 1 / ((1/w0 l0 + 1/w1 l1) + 1/w2 l2)),
/// times the perspective-correct vertex colour ((c0 l0 + c1 l1) + c2 l2) / q. A masked material's
/// lanes pass the alpha test when that alpha is not below the cutoff (NaN passes, as in the scalar
/// test); their alpha is then 1, and the override when set. The alpha as packFragmentColor's byte.
struct LaneColors {
  __m256 invW0, invW1, invW2;
  __m256 c[3][4];   // vertex i's colour / w, channel (hasColor)
  __m256 uv[3][2];  // vertex i's uv / w (texture)
  __m256 materialR, materialG, materialB, materialA, cutoff;
  const LaneTexture* texture;
  bool hasColor;
  bool masked;       // AlphaMode::Mask: alphaTest() before the early tests
  bool alphaVaries;  // blended and not overridden: the alpha byte per lane
  __m256i constantAlpha;

  [[gnu::always_inline]] MFR_TARGET_AVX2 LaneColors(const TriangleSetup& t,
                                                    const TriangleColors* colors,
                                                    const LaneTexture* tex, const ShadeMaterial& m,
                                                    uint32_t alphaByte)
      : invW0(_mm256_set1_ps(t.invW[0])),
        invW1(_mm256_set1_ps(t.invW[1])),
        invW2(_mm256_set1_ps(t.invW[2])),
        materialR(_mm256_set1_ps(m.color.r)),
        materialG(_mm256_set1_ps(m.color.g)),
        materialB(_mm256_set1_ps(m.color.b)),
        materialA(_mm256_set1_ps(m.alpha)),
        cutoff(_mm256_set1_ps(m.cutoff)),
        texture(tex),
        hasColor(colors != nullptr),
        masked(m.mode == AlphaMode::Mask),
        alphaVaries(m.mode == AlphaMode::Blend && !m.alphaOverridden),
        constantAlpha(_mm256_set1_epi32(static_cast<int>(alphaByte))) {
    for (int i = 0; i < 3; ++i) {
      for (int ch = 0; ch < 4; ++ch)
        c[i][ch] = _mm256_set1_ps(colors != nullptr ? colors->colorW[i][ch] : 0.0f);
      uv[i][0] = _mm256_set1_ps(t.uvW[i].x);
      uv[i][1] = _mm256_set1_ps(t.uvW[i].y);
    }
  }

  /// (v0 l0 + v1 l1) + v2 l2 of per-vertex lanes v.
  [[gnu::always_inline]] static MFR_TARGET_AVX2 __m256 interpolate(__m256 v0, __m256 v1, __m256 v2,
                                                                   __m256 l0, __m256 l1,
                                                                   __m256 l2) {
    return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(v0, l0), _mm256_mul_ps(v1, l1)),
                         _mm256_mul_ps(v2, l2));
  }

  /// RasterFrame::surface's base colour and alpha (before the mask's and the override's alpha)
  /// of the lanes at barycentrics (l1, l2); texture samples are read for the lanes in `bits` only.
  [[gnu::always_inline]] MFR_TARGET_AVX2 void surface(__m256 l1, __m256 l2, uint32_t bits,
                                                      __m256* rgba) const {
    const __m256 one = _mm256_set1_ps(1.0f);
    const __m256 l0 = _mm256_sub_ps(_mm256_sub_ps(one, l1), l2);
    const __m256 invQ = _mm256_div_ps(one, interpolate(invW0, invW1, invW2, l0, l1, l2));
    rgba[0] = materialR;
    rgba[1] = materialG;
    rgba[2] = materialB;
    rgba[3] = materialA;
    if (texture != nullptr) {
      __m256 s[4];
      texture->sample(_mm256_mul_ps(interpolate(uv[0][0], uv[1][0], uv[2][0], l0, l1, l2), invQ),
                      _mm256_mul_ps(interpolate(uv[0][1], uv[1][1], uv[2][1], l0, l1, l2), invQ),
                      bits, s);
      for (int ch = 0; ch < 4; ++ch) rgba[ch] = _mm256_mul_ps(rgba[ch], s[ch]);
    }
    if (hasColor)
      for (int ch = 0; ch < 4; ++ch)
        rgba[ch] = _mm256_mul_ps(
            rgba[ch], _mm256_mul_ps(interpolate(c[0][ch], c[1][ch], c[2][ch], l0, l1, l2), invQ));
  }

  /// The lanes of `bits` that pass a masked material's alpha test (alpha not below the cutoff).
  [[gnu::always_inline]] MFR_TARGET_AVX2 uint32_t alphaTest(__m256 l1, __m256 l2,
                                                            uint32_t bits) const {
    __m256 rgba[4];
    surface(l1, l2, bits, rgba);
    return bits &
           ~static_cast<uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(rgba[3], cutoff, _CMP_LT_OQ)));
  }

  /// The base colour (r, g, b) and alpha word of the lanes at barycentrics (l1, l2) (texture
  /// samples are read for the lanes set in `bits` only).
  [[gnu::always_inline]] MFR_TARGET_AVX2 void base(__m256 l1, __m256 l2, uint32_t bits, __m256& r,
                                                   __m256& g, __m256& b, __m256i& alphaWord) const {
    __m256 rgba[4];
    surface(l1, l2, bits, rgba);
    r = rgba[0];
    g = rgba[1];
    b = rgba[2];
    if (!alphaVaries) {
      alphaWord = constantAlpha;
      return;
    }
    // packFragmentColor's alpha: min(max(a, 0), 1) (NaN -> 0), * 255 + 0.5, truncated, << 24
    const __m256 clamped =
        _mm256_min_ps(_mm256_max_ps(rgba[3], _mm256_setzero_ps()), _mm256_set1_ps(1.0f));
    alphaWord = _mm256_slli_epi32(
        _mm256_cvttps_epi32(
            _mm256_add_ps(_mm256_mul_ps(clamped, _mm256_set1_ps(255.0f)), _mm256_set1_ps(0.5f))),
        24);
  }
};

/// packFragmentColor's alpha byte (in place, << 24) of `a`: min(max(a, 0), 1) with NaN -> 0, then
/// * 255 + 0.5 truncated, the same float operations without the colour encode.
inline uint32_t alphaWordOf(float a) {
  float c = a > 0.0f ? a : 0.0f;  // maxps(a, 0): NaN and -0 give +0
  c = c < 1.0f ? c : 1.0f;        // minps(c, 1)
  return static_cast<uint32_t>(static_cast<int32_t>(c * 255.0f + 0.5f)) << 24;
}

/// Lane index tables for the left-packing of passing lanes: entry m holds, 3 bits per slot, the
/// lanes set in m in increasing order.
struct LeftPackTable {
  uint32_t v[256];
  constexpr LeftPackTable() : v{} {
    for (int m = 0; m < 256; ++m) {
      uint32_t packed = 0;
      int n = 0;
      for (int lane = 0; lane < 8; ++lane)
        if ((m >> lane) & 1) packed |= static_cast<uint32_t>(lane) << (3 * n++);
      v[m] = packed;
    }
  }
};
inline constexpr LeftPackTable kLeftPack{};

/// The fragments of one triangle that passed the early tests and wait for shading, packed so that
/// the 8 shading lanes serve fragments of several rows (a small triangle has one or two pixels per
/// row). A pixel is reached at most once per triangle, so deferring its shading and insertion to
/// the end of the triangle changes no test of another of its pixels.
struct PendingLanes {
  alignas(32) float l1[16] = {}, l2[16] = {}, depth[16] = {};
  alignas(32) int32_t x[16] = {}, y[16] = {};
  int n = 0;

  [[gnu::always_inline]] MFR_TARGET_AVX2 void append(__m256 l1v, __m256 l2v, __m256 depthv, int x0,
                                                     int y0, uint32_t bits) {
    const __m256i index =
        _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(static_cast<int>(kLeftPack.v[bits])),
                                           _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21)),
                         _mm256_set1_epi32(7));
    const __m256i xv = _mm256_add_epi32(_mm256_set1_epi32(x0), index);
    _mm256_storeu_ps(l1 + n, _mm256_permutevar8x32_ps(l1v, index));
    _mm256_storeu_ps(l2 + n, _mm256_permutevar8x32_ps(l2v, index));
    _mm256_storeu_ps(depth + n, _mm256_permutevar8x32_ps(depthv, index));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(x + n), xv);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(y + n), _mm256_set1_epi32(y0));
    n += std::popcount(bits);
  }

  /// Moves lanes 8 .. n - 1 to 0 .. n - 9 (after the first 8 were shaded).
  [[gnu::always_inline]] MFR_TARGET_AVX2 void dropFirst8() {
    _mm256_store_ps(l1, _mm256_load_ps(l1 + 8));
    _mm256_store_ps(l2, _mm256_load_ps(l2 + 8));
    _mm256_store_ps(depth, _mm256_load_ps(depth + 8));
    _mm256_store_si256(reinterpret_cast<__m256i*>(x),
                       _mm256_load_si256(reinterpret_cast<const __m256i*>(x + 8)));
    _mm256_store_si256(reinterpret_cast<__m256i*>(y),
                       _mm256_load_si256(reinterpret_cast<const __m256i*>(y + 8)));
    n -= 8;
  }
};

/// Shades 8 lanes (barycentrics l1, l2 at pixels (x, y)) and hands the lanes set in `bits` to the
/// sink, in lane order.
template <bool Colored, bool OneRow, class Sink>
[[gnu::always_inline]] inline MFR_TARGET_AVX2 void shadeEmit(
    const RasterFrame& frame, const ShadingInputs& in, const LaneShading& shading,
    const LaneColors* colors, __m256 l1, __m256 l2, __m256 depth, __m256i xv, __m256i yv,
    uint32_t bits, uint32_t prim, const TileRect& tile, Sink& sink) {
  const __m256 px = _mm256_cvtepi32_ps(xv);
  const __m256 py = _mm256_cvtepi32_ps(yv);
  // the scalar path's y * rayScaleY + rayBiasY and its square, per lane
  const __m256 dy =
      _mm256_add_ps(_mm256_mul_ps(py, _mm256_set1_ps(in.rayScaleY)), _mm256_set1_ps(in.rayBiasY));
  const __m256 dySquared = _mm256_mul_ps(dy, dy);
  __m256 ndotv;
  __m256i rgba;
  if constexpr (Colored) {
    __m256 r, g, b;
    __m256i alphaWord;
    colors->base(l1, l2, bits, r, g, b, alphaWord);
    rgba = shading.shadeBase(*in.tables, l1, l2, px, dy, dySquared, ndotv, r, g, b, alphaWord);
  } else {
    (void)colors;
    rgba = shading.shade(*in.tables, l1, l2, px, dy, dySquared, ndotv);
  }
  alignas(32) float depths[8], cosines[8];
  alignas(32) uint32_t words[8];
  alignas(32) int32_t xs[8], ys[8];
  _mm256_store_ps(depths, depth);
  _mm256_store_ps(cosines, ndotv);
  _mm256_store_si256(reinterpret_cast<__m256i*>(words), rgba);
  _mm256_store_si256(reinterpret_cast<__m256i*>(xs), xv);
  _mm256_store_si256(reinterpret_cast<__m256i*>(ys), yv);
  const uint32_t width = static_cast<uint32_t>(frame.width());
  Fragment f;
  f.prim = prim;
  if constexpr (OneRow) {  // lane i is pixel (xs[0] + i, ys[0])
    const uint32_t first = static_cast<uint32_t>(ys[0]) * width + static_cast<uint32_t>(xs[0]);
    int32_t* cull = sink.cullDepthRow(ys[0] - tile.y0) + (xs[0] - tile.x0);
    for (; bits != 0; bits &= bits - 1) {
      const int lane = std::countr_zero(bits);
      f.pixel = first + static_cast<uint32_t>(lane);
      f.depth = depths[lane];
      f.rgba = words[lane];
      f.ndotv = cosines[lane];
      sink.emitLane(f, cull + lane);
    }
  } else {
    for (; bits != 0; bits &= bits - 1) {
      const int lane = std::countr_zero(bits);
      f.pixel = static_cast<uint32_t>(ys[lane]) * width + static_cast<uint32_t>(xs[lane]);
      f.depth = depths[lane];
      f.rgba = words[lane];
      f.ndotv = cosines[lane];
      sink.emitLane(f, sink.cullDepthRow(ys[lane] - tile.y0) + (xs[lane] - tile.x0));
    }
  }
}

/// shadeEmit() of the first `count` pending lanes.
template <bool Colored, class Sink>
[[gnu::always_inline]] inline MFR_TARGET_AVX2 void emitPending(
    const RasterFrame& frame, const ShadingInputs& in, const LaneShading& shading,
    const LaneColors* colors, const PendingLanes& p, int count, uint32_t prim, const TileRect& tile,
    Sink& sink) {
  shadeEmit<Colored, false>(frame, in, shading, colors, _mm256_load_ps(p.l1), _mm256_load_ps(p.l2),
                            _mm256_load_ps(p.depth),
                            _mm256_load_si256(reinterpret_cast<const __m256i*>(p.x)),
                            _mm256_load_si256(reinterpret_cast<const __m256i*>(p.y)),
                            (1u << count) - 1u, prim, tile, sink);
}

/// A step with at least this many passing lanes is shaded as it is, fewer wait in PendingLanes.
inline constexpr int kDirectLanes = 4;  // 2 and 3 measured slower on the dragon

/// One triangle over one tile (see the file comment): per row the covered lanes, their depths and
/// early tests on 8 lanes; the passing ones are packed across rows and shaded 8 at a time. A
/// triangle at most 8 pixels wide in the tile finds its covered lanes from the three edge values
/// of the row's 8 lanes (exact integers in doubles, the same set as rasterizeRect's span), a wider
/// one from the row span (coveredSpan).
template <bool Colored, class Sink>
MFR_TARGET_AVX2 void rasterizeRectAvx2(const RasterFrame& frame, const ShadingInputs& in,
                                       const TriangleSetup& t, const TileRect& tile,
                                       const LaneShading& shading, const LaneColors* colors,
                                       PendingLanes& pending, Sink& sink) {
  const int x0 = std::max(tile.x0, t.minX), y0 = std::max(tile.y0, t.minY);
  const int x1 = std::min(tile.x1, t.maxX), y1 = std::min(tile.y1, t.maxY);
  if (x0 > x1 || y0 > y1) return;
  detail::EdgeFunctions edges = detail::edgeFunctions(t, x0, y0);
  int64_t(&row)[3] = edges.row;
  const int64_t(&stepX)[3] = edges.stepX;
  const int64_t(&stepY)[3] = edges.stepY;
  const int64_t(&bias)[3] = edges.bias;
  const float dz1 = t.z[1] - t.z[0], dz2 = t.z[2] - t.z[0];

  const __m256 invArea = _mm256_set1_ps(t.invArea);
  const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
  const __m256 z0v = _mm256_set1_ps(t.z[0]), dz1v = _mm256_set1_ps(dz1), dz2v = _mm256_set1_ps(dz2);
  const __m256d laneLo = _mm256_setr_pd(0, 1, 2, 3), laneHi = _mm256_setr_pd(4, 5, 6, 7);
  const __m256i laneIndex = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i laneBit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  // lane * step of each edge, exact
  const __m256d st0 = _mm256_set1_pd(static_cast<double>(stepX[0]));
  const __m256d st1 = _mm256_set1_pd(static_cast<double>(stepX[1]));
  const __m256d st2 = _mm256_set1_pd(static_cast<double>(stepX[2]));
  const bool narrow = x1 - x0 < 8;

  // The early tests of the lanes `covered` (bit i: pixel x + i) at edge values less their bias
  // (w1lo .. w2hi); the passing lanes go to `pending`, 8 of them at a time to shading.
  auto lanes = [&](int x, int y, uint32_t covered, __m256d w1lo, __m256d w1hi, __m256d w2lo,
                   __m256d w2hi, int32_t* cull) __attribute__((target("avx2"), always_inline)) {
    const __m256 w1 = _mm256_set_m128(_mm256_cvtpd_ps(w1hi), _mm256_cvtpd_ps(w1lo));
    const __m256 w2 = _mm256_set_m128(_mm256_cvtpd_ps(w2hi), _mm256_cvtpd_ps(w2lo));
    const __m256 l1 = _mm256_mul_ps(w1, invArea);
    const __m256 l2 = _mm256_mul_ps(w2, invArea);
    if constexpr (Colored) {
      // a masked material's alpha test comes first, as in the scalar loop: a lane it rejects is
      // no fragment (not generated, never tested)
      if (colors->masked) {
        covered = colors->alphaTest(l1, l2, covered);
        if (covered == 0) return;
      }
    }
    const __m256i valid = _mm256_cmpeq_epi32(
        _mm256_and_si256(_mm256_set1_epi32(static_cast<int>(covered)), laneBit), laneBit);
    const __m256 z =
        _mm256_add_ps(_mm256_add_ps(z0v, _mm256_mul_ps(l1, dz1v)), _mm256_mul_ps(l2, dz2v));
    // z > 0 ? min(z, 1) : 0 (NaN -> 0): max returns its second operand on NaN and on +-0
    const __m256 depth = _mm256_min_ps(_mm256_max_ps(z, zero), one);
    const __m256i depthBits = _mm256_castps_si256(depth);
    const int32_t* cullAt = cull + (x - tile.x0);
    const __m256i cullDepth = _mm256_maskload_epi32(reinterpret_cast<const int*>(cullAt), valid);
    const __m256i pass = _mm256_and_si256(valid, _mm256_cmpgt_epi32(cullDepth, depthBits));
    uint32_t passBits =
        static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(pass))) & covered;
    if constexpr (Sink::kCullsInLanes) {
      // per-lane tests in the scalar order (occupancy before k+), for the counters
      alignas(32) float depths[8];
      _mm256_store_ps(depths, depth);
      const uint32_t rowPixel = static_cast<uint32_t>(y) * static_cast<uint32_t>(frame.width());
      uint32_t accepted = 0;
      for (uint32_t bits = covered; bits != 0; bits &= bits - 1) {
        const int lane = std::countr_zero(bits);
        if (sink.acceptLane(rowPixel + static_cast<uint32_t>(x + lane), depths[lane],
                            (passBits >> lane) & 1u))
          accepted |= 1u << lane;
      }
      passBits = accepted;
    } else {
      const uint32_t generated = static_cast<uint32_t>(std::popcount(covered));
      sink.countEarly(generated, generated - static_cast<uint32_t>(std::popcount(passBits)));
    }
    if (passBits == 0) return;
    if (std::popcount(passBits) >= kDirectLanes) {  // enough lanes to shade the step as it is
      shadeEmit<Colored, true>(frame, in, shading, colors, l1, l2, depth,
                               _mm256_add_epi32(_mm256_set1_epi32(x), laneIndex),
                               _mm256_set1_epi32(y), passBits, t.prim, tile, sink);
      return;
    }
    pending.append(l1, l2, depth, x, y, passBits);
    if (pending.n >= 8) {
      emitPending<Colored>(frame, in, shading, colors, pending, 8, t.prim, tile, sink);
      pending.dropFirst8();
    }
  };

  if (narrow) {
    // the row's lanes x0 .. x1 at once: edge values row[i] + lane * stepX[i] (bias included)
    const uint32_t inRect = (1u << (x1 - x0 + 1)) - 1u;
    const __m256d s0lo = _mm256_mul_pd(laneLo, st0), s0hi = _mm256_mul_pd(laneHi, st0);
    const __m256d s1lo = _mm256_mul_pd(laneLo, st1), s1hi = _mm256_mul_pd(laneHi, st1);
    const __m256d s2lo = _mm256_mul_pd(laneLo, st2), s2hi = _mm256_mul_pd(laneHi, st2);
    const __m256d zeroD = _mm256_setzero_pd();
    for (int y = y0; y <= y1; ++y) {
      const __m256d r0 = _mm256_set1_pd(static_cast<double>(row[0]));
      const __m256d r1 = _mm256_set1_pd(static_cast<double>(row[1]));
      const __m256d r2 = _mm256_set1_pd(static_cast<double>(row[2]));
      const __m256d e0lo = _mm256_add_pd(r0, s0lo), e0hi = _mm256_add_pd(r0, s0hi);
      const __m256d e1lo = _mm256_add_pd(r1, s1lo), e1hi = _mm256_add_pd(r1, s1hi);
      const __m256d e2lo = _mm256_add_pd(r2, s2lo), e2hi = _mm256_add_pd(r2, s2hi);
      const __m256d inLo = _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(e0lo, zeroD, _CMP_GE_OQ),
                                                       _mm256_cmp_pd(e1lo, zeroD, _CMP_GE_OQ)),
                                         _mm256_cmp_pd(e2lo, zeroD, _CMP_GE_OQ));
      const __m256d inHi = _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(e0hi, zeroD, _CMP_GE_OQ),
                                                       _mm256_cmp_pd(e1hi, zeroD, _CMP_GE_OQ)),
                                         _mm256_cmp_pd(e2hi, zeroD, _CMP_GE_OQ));
      const uint32_t covered = (static_cast<uint32_t>(_mm256_movemask_pd(inLo)) |
                                (static_cast<uint32_t>(_mm256_movemask_pd(inHi)) << 4)) &
                               inRect;
      if (covered != 0) {
        // less the bias (exact: integers below 2^53)
        const __m256d b1 = _mm256_set1_pd(static_cast<double>(bias[1]));
        const __m256d b2 = _mm256_set1_pd(static_cast<double>(bias[2]));
        lanes(x0, y, covered, _mm256_sub_pd(e1lo, b1), _mm256_sub_pd(e1hi, b1),
              _mm256_sub_pd(e2lo, b2), _mm256_sub_pd(e2hi, b2), sink.cullDepthRow(y - tile.y0));
      }
      row[0] += stepY[0];
      row[1] += stepY[1];
      row[2] += stepY[2];
    }
  } else {
    for (int y = y0; y <= y1; ++y) {
      int xs = x0, xe = x1;  // the covered span, exactly as rasterizeRect
      coveredSpan(row, stepX, x0, x1, xs, xe);
      if (xs <= xe) {
        const int64_t skip = xs - x0;
        // edge values less their bias, exact integers in doubles
        const double w1s = static_cast<double>(row[1] + skip * stepX[1] - bias[1]);
        const double w2s = static_cast<double>(row[2] + skip * stepX[2] - bias[2]);
        int32_t* cull = sink.cullDepthRow(y - tile.y0);
        for (int x = xs; x <= xe; x += 8) {
          const int n = std::min(8, xe - x + 1);
          const double k = static_cast<double>(x - xs);
          // w = w_start + (k + lane) * step, exact (|w| < 2^51)
          const __m256d k1 = _mm256_set1_pd(w1s), k2 = _mm256_set1_pd(w2s);
          const __m256d kk = _mm256_set1_pd(k);
          lanes(x, y, (1u << n) - 1u,
                _mm256_add_pd(k1, _mm256_mul_pd(_mm256_add_pd(kk, laneLo), st1)),
                _mm256_add_pd(k1, _mm256_mul_pd(_mm256_add_pd(kk, laneHi), st1)),
                _mm256_add_pd(k2, _mm256_mul_pd(_mm256_add_pd(kk, laneLo), st2)),
                _mm256_add_pd(k2, _mm256_mul_pd(_mm256_add_pd(kk, laneHi), st2)), cull);
        }
      }
      row[0] += stepY[0];
      row[1] += stepY[1];
      row[2] += stepY[2];
    }
  }
  if (pending.n > 0) {
    emitPending<Colored>(frame, in, shading, colors, pending, pending.n, t.prim, tile, sink);
    pending.n = 0;
  }
}

/// The capture pass over one tile: rasterizeTile<ShadeMode::Full> on 8 lanes, with the lane
/// protocol of `sink` (beginTile, cullDepthRow, countEarly / acceptLane, emitLane) and its scalar
/// protocol (accept, emit) for the tiles the lanes do not take.
template <class Sink>
MFR_TARGET_AVX2 void rasterizeTileAvx2(const RasterFrame& frame, const ShadingInputs& in, int tile,
                                       Sink& sink) {
  const TileRect r = frame.tileRect(tile);
  const uint32_t* end = frame.tileEnd(tile);
  for (const uint32_t* it = frame.tileBegin(tile); it != end; ++it) {
    // (the set-ups a few triangles ahead: raster_frame_impl.hpp's prefetchSetup)
    if (end - it > kPrefetchAhead) prefetchSetup(frame.setups()[it[kPrefetchAhead]]);
    const TriangleSetup& t = frame.setups()[*it];
    const ShadeMaterial& m = (*in.materials)[t.material];
    if (m.blend != BlendMode::Over) {
      frame.rasterizeTile<ShadeMode::Full>(tile, sink);  // no cull depths: all scalar
      return;
    }
  }
  sink.beginTile(r, frame.tileSize());
  PendingLanes pending;
  for (const uint32_t* it = frame.tileBegin(tile); it != end; ++it) {
    if (end - it > kPrefetchAhead) prefetchSetup(frame.setups()[it[kPrefetchAhead]]);
    const TriangleSetup& t = frame.setups()[*it];
    // the base colour of an untextured, uncoloured triangle (RasterFrame::surface gives the
    // material's colour and alpha, 1 when opaque, the override when set) and its alpha byte
    const ShadeMaterial& material = (*in.materials)[t.material];
    glm::vec4 base(material.color, material.alpha);
    if (material.mode != AlphaMode::Blend) base.a = 1.0f;  // opaque, or masked and passing
    if (material.alphaOverridden) base.a = material.overrideAlpha;
    const uint32_t alphaByte = alphaWordOf(base.a);
    const LaneShading shading(in, t, base, alphaByte);
    if (t.hasColor || material.texture != nullptr || material.mode == AlphaMode::Mask) {
      // a texture or vertex colours: the base colour and alpha per lane (RasterFrame::surface's
      // order)
      LaneTexture texture;
      if (material.texture != nullptr) {
        texture.rgba = material.texture->rgba.data();
        texture.tables = in.tables;
        texture.width = material.texture->width;
        texture.height = material.texture->height;
        texture.sampler = material.sampler;
      }
      const LaneColors colors(t, t.hasColor ? &frame.vertexColors(*it) : nullptr,
                              material.texture != nullptr ? &texture : nullptr, material,
                              alphaByte);
      rasterizeRectAvx2<true>(frame, in, t, r, shading, &colors, pending, sink);
    } else {
      rasterizeRectAvx2<false>(frame, in, t, r, shading, nullptr, pending, sink);
    }
  }
}

#undef MFR_TARGET_AVX2

}  // namespace detail
}  // namespace mfr

#endif
