// Memory accounting of every method, following DHOIT Eq. 1:
//   F(M) = floor((M - |P| * S_p - S_i) / S_f)
// the number of 8-byte fragment nodes (S_f = 8) a budget of M bytes buys once the per-pixel
// overhead S_p of the method (over all |P| = width * height pixels: full-screen buffers) and its
// image-level overhead S_i are paid. Per-pixel words by component:
//
//   counter   4 B  fragments stored so far (also the count pass's counter)    every method
//   offset    4 B  first slot of the pixel's region (prefix sum)            abuffer, kplus-sb, dynamic
//   lock      4 B  spin-lock semaphore                                       k+-buffer family
//   occupancy 12 + 4d B  zn, zf, k-th bucket, 32d-bit bitmap                 +occupancy
//   tail      20 B  hybrid tail: sum(alpha * rgb) 3 x f32, sum(alpha) f32, count u32   hybrid
//   previous  1 B  |n.v| of the previous frame's nearest fragment, unorm8    vkb (Fresnel term)
//   image     4096 B  depth-complexity histogram, 1024 x u32                 kplus-dynamic
// The variable k-buffer's importance map lives in the offset word (importance, then k(p), then the
// prefix sum, computed in place), so it costs no extra bytes; the count pass's n(p) is the counter.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "mfr/method/method.hpp"

namespace mfr {

inline constexpr uint64_t kNodeBytes = 8;
inline constexpr uint64_t kHistogramBins = 1024;

struct MemoryModel {
  uint64_t counter = 4, offset = 0, lock = 0, occupancy = 0, tail = 0, previous = 0;  // per pixel
  uint64_t image = 0;                                                   // bytes per image

  /// `fragmentParallel`: methods without a lock word of their own (fkb, abuffer) need one per
  /// pixel when fragments of a pixel arrive from several threads (it stands in for the GPU's
  /// atomic insertion), and it is charged.
  static MemoryModel of(const MethodDesc& method, bool fragmentParallel = false);
  uint64_t perPixel() const { return counter + offset + lock + occupancy + tail + previous; }
  uint64_t overhead(uint64_t pixels) const { return pixels * perPixel() + image; }
  /// F(M): fragment slots a budget buys (0 when the overhead alone exceeds it).
  uint64_t fragmentSlots(uint64_t budget, uint64_t pixels) const {
    const uint64_t fixed = overhead(pixels);
    return budget > fixed ? (budget - fixed) / kNodeBytes : 0;
  }
  /// Bytes by category for `slots` allocated nodes.
  std::map<std::string, uint64_t> breakdown(uint64_t pixels, uint64_t slots) const;
};

}  // namespace mfr
