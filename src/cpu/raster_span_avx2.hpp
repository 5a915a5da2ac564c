// The capture pass's tile rasterizer on 8 lanes (AVX2), chosen at run time from activeIsa()
// (k+-buffer paper, Vasilakis & Fudos 2014, sec. 3.2 and Algorithm 3: the k+ test runs before
// the fragment is shaded, against the pixel's current maximum).
//
// Per row span of a triangle, 8 pixels at a time:
//   1. barycentrics and depth of the 8 pixel centres: the edge values are exact integers, carried
//      in doubles (exact below 2^53) and rounded once to float, like the scalar int64 -> float;
//   2. the k+ test on all 8 (kbuffer compositing; a hybrid sink's cull depths are all INT32_MAX,
//      since it shades every fragment): each pixel of the tile has a 32-bit "cull depth" (below),
//      compared with the 8 depths' bits at once;
//   3. shading (n.v, headlight, sRGB encode with the colour tables as gathers) on the 8 lanes;
//   4. the surviving lanes, in x order, go to the sink's scalar insertion.
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
// A tile whose triangles all have untextured, non-masked materials takes the wide path (their
// alpha test cannot reject, so testing before the surface is the scalar order; the base colour is
// the material's, or for a vertex-coloured triangle the material's times the perspective-correct
// colour, per lane in the scalar operation order); any other tile runs the scalar rasterizeTile
// on the same sink.
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

/// The sRGB codes of 8 linear values, as packFragmentColor computes each: clamp (NaN -> 0), the
/// coarse guess from the 4096-entry table, the fix-up against the exact code boundaries.
[[gnu::always_inline]] inline MFR_TARGET_AVX2 __m256i encodeSrgb8x8(const ColorTables& tables,
                                                                    __m256 v) {
  const int* coarse = reinterpret_cast<const int*>(tables.coarseSrgb8.data());
  const float* lowerBound = tables.lowerBound.data();
  const __m256 c = _mm256_min_ps(_mm256_max_ps(v, _mm256_setzero_ps()), _mm256_set1_ps(1.0f));
  const __m256i index = _mm256_cvttps_epi32(
      _mm256_add_ps(_mm256_mul_ps(c, _mm256_set1_ps(4095.0f)), _mm256_set1_ps(0.5f)));
  // 4-byte gathers of the byte table (the last index reads into lowerBound, in the same struct)
  __m256i code =
      _mm256_and_si256(_mm256_i32gather_epi32(coarse, index, 1), _mm256_set1_epi32(0xff));
  const __m256 above =
      _mm256_i32gather_ps(lowerBound, _mm256_add_epi32(code, _mm256_set1_epi32(1)), 4);
  code = _mm256_sub_epi32(code, _mm256_castps_si256(_mm256_cmp_ps(c, above, _CMP_GE_OQ)));
  const __m256 below = _mm256_i32gather_ps(lowerBound, code, 4);
  return _mm256_add_epi32(code, _mm256_castps_si256(_mm256_cmp_ps(c, below, _CMP_LT_OQ)));
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
                                                       __m256 l2, int x, __m256 dy,
                                                       __m256 dySquared, __m256& ndotv) const {
    return shadeBase(tables, l1, l2, x, dy, dySquared, ndotv, baseR, baseG, baseB, alpha);
  }

  /// shade() with a base colour and alpha word per lane (vertex colours).
  [[gnu::always_inline]] MFR_TARGET_AVX2 __m256i shadeBase(const ColorTables& tables, __m256 l1,
                                                           __m256 l2, int x, __m256 dy,
                                                           __m256 dySquared, __m256& ndotv,
                                                           __m256 r, __m256 g, __m256 b,
                                                           __m256i alphaWord) const {
    const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
    const __m256 minusOne = _mm256_set1_ps(-1.0f);
    const __m256 absMask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
    const __m256 ambient = _mm256_set1_ps(kAmbient), diffuse = _mm256_set1_ps(1.0f - kAmbient);
    const __m256i laneIndex = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256 l0 = _mm256_sub_ps(_mm256_sub_ps(one, l1), l2);
    const __m256 nx = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0x, l0), _mm256_mul_ps(n1x, l1)),
                                    _mm256_mul_ps(n2x, l2));
    const __m256 ny = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0y, l0), _mm256_mul_ps(n1y, l1)),
                                    _mm256_mul_ps(n2y, l2));
    const __m256 nz = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0z, l0), _mm256_mul_ps(n1z, l1)),
                                    _mm256_mul_ps(n2z, l2));
    const __m256 px = _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_set1_epi32(x), laneIndex));
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
    return _mm256_or_si256(
        _mm256_or_si256(
            detail::encodeSrgb8x8(tables, _mm256_mul_ps(r, light)),
            _mm256_slli_epi32(detail::encodeSrgb8x8(tables, _mm256_mul_ps(g, light)), 8)),
        _mm256_or_si256(
            _mm256_slli_epi32(detail::encodeSrgb8x8(tables, _mm256_mul_ps(b, light)), 16),
            alphaWord));
  }
};

/// A vertex-coloured triangle's base colour on 8 lanes, as RasterFrame::surface computes it: the
/// perspective-correct colour ((c0 l0 + c1 l1) + c2 l2) / ((1/w0 l0 + 1/w1 l1) + 1/w2 l2) times
/// the material's colour and alpha (alpha 1 when opaque, the override when set: then constant),
/// the alpha as packFragmentColor's byte.
struct LaneColors {
  __m256 invW0, invW1, invW2;
  __m256 c[3][4];  // vertex i's colour / w, channel
  __m256 materialR, materialG, materialB, materialA;
  bool alphaVaries;
  __m256i constantAlpha;

  [[gnu::always_inline]] MFR_TARGET_AVX2 LaneColors(const TriangleSetup& t,
                                                    const TriangleColors& colors,
                                                    const ShadeMaterial& m, uint32_t alphaByte)
      : invW0(_mm256_set1_ps(t.invW[0])),
        invW1(_mm256_set1_ps(t.invW[1])),
        invW2(_mm256_set1_ps(t.invW[2])),
        materialR(_mm256_set1_ps(m.color.r)),
        materialG(_mm256_set1_ps(m.color.g)),
        materialB(_mm256_set1_ps(m.color.b)),
        materialA(_mm256_set1_ps(m.alpha)),
        alphaVaries(m.mode != AlphaMode::Opaque && !m.alphaOverridden),
        constantAlpha(_mm256_set1_epi32(static_cast<int>(alphaByte))) {
    for (int i = 0; i < 3; ++i)
      for (int ch = 0; ch < 4; ++ch) c[i][ch] = _mm256_set1_ps(colors.colorW[i][ch]);
  }

  /// Channel `ch` of the perspective-correct colour.
  [[gnu::always_inline]] MFR_TARGET_AVX2 __m256 channel(int ch, __m256 l0, __m256 l1, __m256 l2,
                                                        __m256 invQ) const {
    const __m256 sum =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(c[0][ch], l0), _mm256_mul_ps(c[1][ch], l1)),
                      _mm256_mul_ps(c[2][ch], l2));
    return _mm256_mul_ps(sum, invQ);
  }

  /// The base colour (r, g, b) and alpha word of the lanes at barycentrics (l1, l2).
  [[gnu::always_inline]] MFR_TARGET_AVX2 void base(__m256 l1, __m256 l2, __m256& r, __m256& g,
                                                   __m256& b, __m256i& alphaWord) const {
    const __m256 one = _mm256_set1_ps(1.0f);
    const __m256 l0 = _mm256_sub_ps(_mm256_sub_ps(one, l1), l2);
    const __m256 q =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(invW0, l0), _mm256_mul_ps(invW1, l1)),
                      _mm256_mul_ps(invW2, l2));
    const __m256 invQ = _mm256_div_ps(one, q);
    r = _mm256_mul_ps(materialR, channel(0, l0, l1, l2, invQ));
    g = _mm256_mul_ps(materialG, channel(1, l0, l1, l2, invQ));
    b = _mm256_mul_ps(materialB, channel(2, l0, l1, l2, invQ));
    if (!alphaVaries) {
      alphaWord = constantAlpha;
      return;
    }
    // packFragmentColor's alpha: min(max(a, 0), 1) (NaN -> 0), * 255 + 0.5, truncated, << 24
    const __m256 a = _mm256_mul_ps(materialA, channel(3, l0, l1, l2, invQ));
    const __m256 clamped = _mm256_min_ps(_mm256_max_ps(a, _mm256_setzero_ps()), one);
    alphaWord = _mm256_slli_epi32(
        _mm256_cvttps_epi32(
            _mm256_add_ps(_mm256_mul_ps(clamped, _mm256_set1_ps(255.0f)), _mm256_set1_ps(0.5f))),
        24);
  }
};

inline const TriangleColors kWhite{};  // an uncoloured triangle's (unread) colours

/// One triangle over one tile, 8 pixels at a time (see the file comment).
template <class Sink>
MFR_TARGET_AVX2 void rasterizeRectAvx2(const RasterFrame& frame, const ShadingInputs& in,
                                       const TriangleSetup& t, const TileRect& tile, Sink& sink) {
  const int x0 = std::max(tile.x0, t.minX), y0 = std::max(tile.y0, t.minY);
  const int x1 = std::min(tile.x1, t.maxX), y1 = std::min(tile.y1, t.maxY);
  if (x0 > x1 || y0 > y1) return;
  int64_t stepX[3], stepY[3], row[3], bias[3];
  const int64_t px0 = static_cast<int64_t>(x0) * 256 + 128;
  const int64_t py0 = static_cast<int64_t>(y0) * 256 + 128;
  for (int i = 0; i < 3; ++i) {
    const int a = (i + 1) % 3, b = (i + 2) % 3;
    const int64_t A = static_cast<int64_t>(t.y[a]) - t.y[b];
    const int64_t B = static_cast<int64_t>(t.x[b]) - t.x[a];
    stepX[i] = A * 256;
    stepY[i] = B * 256;
    bias[i] = (t.topLeft >> i) & 1 ? 0 : -1;
    row[i] = B * (py0 - t.y[a]) + A * (px0 - t.x[a]) + bias[i];
  }
  // per-triangle constants: the base colour (untextured and not masked: RasterFrame::surface
  // gives the material's colour and alpha, 1 when opaque, the override when set) and alpha byte
  const ShadeMaterial& material = (*in.materials)[t.material];
  glm::vec4 base(material.color, material.alpha);
  if (material.mode == AlphaMode::Opaque) base.a = 1.0f;
  if (material.alphaOverridden) base.a = material.overrideAlpha;
  const ColorTables& tables = *in.tables;
  const uint32_t alphaByte = packFragmentColor(tables, glm::vec3(0.0f), base.a) & 0xff000000u;
  const float dz1 = t.z[1] - t.z[0], dz2 = t.z[2] - t.z[0];

  const __m256 invArea = _mm256_set1_ps(t.invArea);
  const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
  const __m256 z0v = _mm256_set1_ps(t.z[0]), dz1v = _mm256_set1_ps(dz1), dz2v = _mm256_set1_ps(dz2);
  const __m256d laneLo = _mm256_setr_pd(0, 1, 2, 3), laneHi = _mm256_setr_pd(4, 5, 6, 7);
  const __m256i laneIndex = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const LaneShading shading(in, t, base, alphaByte);
  // vertex colours: the base colour and alpha per lane (RasterFrame::surface's order)
  const bool colored = t.hasColor;
  const LaneColors laneColors(
      t, colored ? frame.vertexColors(static_cast<size_t>(&t - frame.setups().data())) : kWhite,
      material, alphaByte);

  Fragment f;
  f.prim = t.prim;
  for (int y = y0; y <= y1; ++y) {
    int xs = x0, xe = x1;  // the covered span, exactly as rasterizeRect
    coveredSpan(row, stepX, x0, x1, xs, xe);
    if (xs <= xe) {
      const int64_t skip = xs - x0;
      // edge values less their bias, exact integers in doubles
      const double w1s = static_cast<double>(row[1] + skip * stepX[1] - bias[1]);
      const double w2s = static_cast<double>(row[2] + skip * stepX[2] - bias[2]);
      const __m256d st1 = _mm256_set1_pd(static_cast<double>(stepX[1]));
      const __m256d st2 = _mm256_set1_pd(static_cast<double>(stepX[2]));
      const float dyScalar = static_cast<float>(y) * in.rayScaleY + in.rayBiasY;
      const __m256 dy = _mm256_set1_ps(dyScalar);
      const __m256 dySquared = _mm256_set1_ps(dyScalar * dyScalar);
      const uint32_t rowPixel = static_cast<uint32_t>(y) * static_cast<uint32_t>(frame.width());
      int32_t* cull = sink.cullDepthRow(y - tile.y0);
      for (int x = xs; x <= xe; x += 8) {
        const int lanes = std::min(8, xe - x + 1);
        const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(lanes), laneIndex);
        const double k = static_cast<double>(x - xs);
        // w = w_start + (k + lane) * step, exact (|w| < 2^51)
        const __m256d k1 = _mm256_set1_pd(w1s), k2 = _mm256_set1_pd(w2s);
        const __m256d kk = _mm256_set1_pd(k);
        const __m256d w1lo = _mm256_add_pd(k1, _mm256_mul_pd(_mm256_add_pd(kk, laneLo), st1));
        const __m256d w1hi = _mm256_add_pd(k1, _mm256_mul_pd(_mm256_add_pd(kk, laneHi), st1));
        const __m256d w2lo = _mm256_add_pd(k2, _mm256_mul_pd(_mm256_add_pd(kk, laneLo), st2));
        const __m256d w2hi = _mm256_add_pd(k2, _mm256_mul_pd(_mm256_add_pd(kk, laneHi), st2));
        const __m256 w1 = _mm256_set_m128(_mm256_cvtpd_ps(w1hi), _mm256_cvtpd_ps(w1lo));
        const __m256 w2 = _mm256_set_m128(_mm256_cvtpd_ps(w2hi), _mm256_cvtpd_ps(w2lo));
        const __m256 l1 = _mm256_mul_ps(w1, invArea);
        const __m256 l2 = _mm256_mul_ps(w2, invArea);
        const __m256 z =
            _mm256_add_ps(_mm256_add_ps(z0v, _mm256_mul_ps(l1, dz1v)), _mm256_mul_ps(l2, dz2v));
        // z > 0 ? min(z, 1) : 0 (NaN -> 0): max returns its second operand on NaN and on +-0
        const __m256 depth = _mm256_min_ps(_mm256_max_ps(z, zero), one);
        const __m256i depthBits = _mm256_castps_si256(depth);
        const int32_t* cullAt = cull + (x - tile.x0);
        const __m256i cullDepth =
            _mm256_maskload_epi32(reinterpret_cast<const int*>(cullAt), valid);
        const __m256i pass = _mm256_and_si256(valid, _mm256_cmpgt_epi32(cullDepth, depthBits));
        const uint32_t validBits = (1u << lanes) - 1u;
        uint32_t passBits =
            static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(pass))) & validBits;
        if constexpr (!Sink::kCullsInLanes) {
          sink.countEarly(static_cast<uint32_t>(lanes),
                          static_cast<uint32_t>(lanes) - std::popcount(passBits));
          if (passBits == 0) continue;
        }
        // shading of the 8 lanes (only the passing ones are used)
        __m256 ndotv;
        __m256i rgba;
        if (colored) {
          __m256 r, g, b;
          __m256i alphaWord;
          laneColors.base(l1, l2, r, g, b, alphaWord);
          rgba = shading.shadeBase(tables, l1, l2, x, dy, dySquared, ndotv, r, g, b, alphaWord);
        } else {
          rgba = shading.shade(tables, l1, l2, x, dy, dySquared, ndotv);
        }
        alignas(32) float depths[8], cosines[8];
        alignas(32) uint32_t words[8];
        _mm256_store_ps(depths, depth);
        _mm256_store_ps(cosines, ndotv);
        _mm256_store_si256(reinterpret_cast<__m256i*>(words), rgba);
        if constexpr (Sink::kCullsInLanes) {
          // per-lane tests in the scalar order (occupancy before k+), for the counters
          for (int lane = 0; lane < lanes; ++lane) {
            f.pixel = rowPixel + static_cast<uint32_t>(x + lane);
            if (!sink.acceptLane(f.pixel, depths[lane], (passBits >> lane) & 1u)) continue;
            f.depth = depths[lane];
            f.rgba = words[lane];
            f.ndotv = cosines[lane];
            sink.emitLane(f, cull + (x + lane - tile.x0));
          }
        } else {
          while (passBits != 0) {
            const int lane = std::countr_zero(passBits);
            passBits &= passBits - 1;
            f.pixel = rowPixel + static_cast<uint32_t>(x + lane);
            f.depth = depths[lane];
            f.rgba = words[lane];
            f.ndotv = cosines[lane];
            sink.emitLane(f, cull + (x + lane - tile.x0));
          }
        }
      }
    }
    row[0] += stepY[0];
    row[1] += stepY[1];
    row[2] += stepY[2];
  }
}

/// The capture pass over one tile: rasterizeTile<ShadeMode::Full> on 8 lanes, with the lane
/// protocol of `sink` (beginTile, cullDepthRow, countEarly / acceptLane, emitLane) and its scalar
/// protocol (accept, emit) for the tiles the lanes do not take.
template <class Sink>
MFR_TARGET_AVX2 void rasterizeTileAvx2(const RasterFrame& frame, const ShadingInputs& in, int tile,
                                       Sink& sink) {
  const TileRect r = frame.tileRect(tile);
  sink.beginTile(r, frame.tileSize());
  for (const uint32_t* it = frame.tileBegin(tile); it != frame.tileEnd(tile); ++it) {
    const TriangleSetup& t = frame.setups()[*it];
    const ShadeMaterial& m = (*in.materials)[t.material];
    if (m.texture != nullptr || m.mode == AlphaMode::Mask) {
      frame.rasterizeTile<ShadeMode::Full>(tile, sink);
      return;
    }
  }
  for (const uint32_t* it = frame.tileBegin(tile); it != frame.tileEnd(tile); ++it)
    rasterizeRectAvx2(frame, in, frame.setups()[*it], r, sink);
}

#undef MFR_TARGET_AVX2

}  // namespace detail
}  // namespace mfr

#endif
