// Occupancy-map fragment culling (Vasilakis & Papaioannou 2015, "Improving k-buffer methods via
// Occupancy Maps", sec. 2 and Lemma 2.1).
//
// Per pixel, three passes before the capture:
//   depth range: nearest and farthest fragment depth zn, zf (a Coverage raster pass);
//   fill:        bit j of the pixel's S = 32*d bucket bitmap is set when a fragment falls into
//                bucket j = min(S-1, floor((z - zn) / (zf - zn) * S))   (j = 0 when zf == zn, so
//                the far bound maps to the last bucket and a zero range does not divide by zero);
//   count:       Kernighan's bit counting walks the occupied buckets to the k(p)-th one, j_k.
// The capture then rejects every fragment whose bucket is beyond j_k. The bucket function is
// monotone in z and shared by fill and test, so every one of the k nearest fragments lies
// in a bucket <= j_k and survives (Lemma 2.1). A pixel with fewer than k occupied buckets culls
// nothing.
//
// Memory per pixel (4 + 4 + 4 + 4d bytes):
//   +--------+--------+-----------+---------------------------------+
//   | zn f32 | zf f32 | j_k u32   | bitmap: d x u32 (bit j = bucket) |
//   +--------+--------+-----------+---------------------------------+
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "mfr/method/memory_model.hpp"

namespace mfr {

class OccupancyMap {
 public:
  static constexpr uint32_t kNoCulling = std::numeric_limits<uint32_t>::max();

  OccupancyMap() = default;
  OccupancyMap(size_t pixels, int words)
      : words_(words),
        zNear_(pixels, std::numeric_limits<float>::infinity()),
        zFar_(pixels, -std::numeric_limits<float>::infinity()),
        threshold_(pixels, kNoCulling),
        bits_(pixels * static_cast<size_t>(words), 0u) {}

  static size_t bytesPerPixel(int words) { return occupancyBytesPerPixel(words); }
  int words() const { return words_; }
  uint32_t buckets() const { return 32u * static_cast<uint32_t>(words_); }

  // depth range pass
  void expandRange(uint32_t pixel, float z) {
    if (z < zNear_[pixel]) zNear_[pixel] = z;
    if (z > zFar_[pixel]) zFar_[pixel] = z;
  }

  uint32_t bucket(uint32_t pixel, float z) const {
    const float zn = zNear_[pixel], zf = zFar_[pixel];
    if (!(zf > zn)) return 0;
    const float t = (z - zn) / (zf - zn) * static_cast<float>(buckets());
    const uint32_t b = t > 0.0f ? static_cast<uint32_t>(t) : 0u;
    return b < buckets() ? b : buckets() - 1;
  }

  // fill pass
  void mark(uint32_t pixel, float z) {
    const uint32_t b = bucket(pixel, z);
    bits_[static_cast<size_t>(pixel) * words_ + (b >> 5)] |= 1u << (b & 31u);
  }

  // count pass: the k-th occupied bucket by Kernighan's bit counting (O(k))
  void resolveThreshold(uint32_t pixel, uint32_t k) {
    uint32_t seen = 0;
    const uint32_t* words = &bits_[static_cast<size_t>(pixel) * words_];
    for (int w = 0; w < words_; ++w) {
      uint32_t bits = words[w];
      while (bits != 0) {
        if (++seen == k) {
          threshold_[pixel] = static_cast<uint32_t>(w) * 32u + std::countr_zero(bits);
          return;
        }
        bits &= bits - 1;
      }
    }
    threshold_[pixel] = kNoCulling;
  }

  /// True when the fragment lies behind the k-th occupied bucket and can be rejected early.
  bool culls(uint32_t pixel, float z) const {
    const uint32_t t = threshold_[pixel];
    return t != kNoCulling && bucket(pixel, z) > t;
  }

  /// Bytes this map's buffers hold (the CPU engine's measured memory).
  uint64_t allocatedBytes() const {
    return zNear_.capacity() * sizeof(float) + zFar_.capacity() * sizeof(float) +
           threshold_.capacity() * sizeof(uint32_t) + bits_.capacity() * sizeof(uint32_t);
  }

 private:
  int words_ = 1;
  std::vector<float> zNear_, zFar_;
  std::vector<uint32_t> threshold_;
  std::vector<uint32_t> bits_;
};

}  // namespace mfr
