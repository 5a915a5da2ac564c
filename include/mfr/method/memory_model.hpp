// Memory accounting of every method, following DHOIT Eq. 1:
//   F(M) = floor((M - |P| * S_p - S_i) / S_f)
// the number of 8-byte fragment nodes (S_f = 8) a budget of M bytes buys once the per-pixel
// overhead S_p of the method (over all |P| = width * height pixels: full-screen buffers) and its
// image-level overhead S_i are paid. Per-pixel words by component:
//
//   word       bytes   what                                           who
//   counter    4       fragments stored so far (the count pass's too)  every method
//   offset     4       first slot of the pixel's region (prefix sum)   abuffer, kplus-sb, dynamic,
//                                                                      vkb, dkb
//   lock       4       spin-lock semaphore                             k+ family, vkb, dkb; any
//                                                                      method in fragment-parallel
//                                                                      mode
//                                                                      (for fkb / abuffer it stands
//                                                                      in for the GPU's atomics)
//   occupancy  12+4d   zn, zf, k-th bucket, 32d-bit bitmap             +occupancy
//   tail       20      sum(alpha rgb) 3 x f32, sum(alpha) f32, u32 t   hybrid
//   previous   1       |n.v| of the previous frame's nearest, unorm8   vkb (Fresnel term)
//   accum      20      sum(C w) 3 x f32, sum(a w) f32, revealage f32   wboit
//              36      b0, b1..b4 5 x f32; sum(T a c) 3 x f32, sum(T a) mboit
//   image      4096    depth-complexity histogram, 1024 x u32          kplus-dynamic (per image)
// wboit and mboit keep no nodes and no counter (counter 0, no offset: F(M) is unused); mlab's
// nodes are 20 B (depth, premultiplied r g b, transmittance: float32), so S_f = 20 for mlab, with
// the counter (nodes in use) and the k+ family's lock word:
//   wboit 20 B/pixel, mboit 36 B/pixel, mlab 8 B/pixel + 20 B per node (k = F(M) / |P|).
// The variable k-buffer's importance map lives in the offset word (importance, then k(p), then the
// prefix sum, computed in place), so it costs no extra bytes; the count pass's n(p) is the counter.
// The deep k-buffer's features live in a per-worker 16x16-tile scratch (deep_importance.hpp), and
// its predicted importance in the offset word like vkb's; it needs no previous-frame normal.
//
// The node pool, per allocation policy (pixels in tile-major order, 8 B per slot):
//
//   fixed k (fkb, kplus-array/heap, zbuffer): every pixel owns k slots at offset p * k
//     +---------------+---------------+---------------+-----+---------------+
//     | pixel 0: k    | pixel 1: k    | pixel 2: k    | ... | pixel P-1: k  |   P * k * 8 B
//     +---------------+---------------+---------------+-----+---------------+
//   exact (abuffer: k(p) = n(p); kplus-sb / dynamic: k(p) = min(n(p), k); vkb: k(p) = I-based)
//     +-----+-----------+++-------+-----+     offsets[p] = sum of k(q) for q before p
//     | p0  | p1        ||| p3    | ... |     (an empty pixel has k(p) = 0 and no slots)
//     +-----+-----------+++-------+-----+     sum k(p) * 8 B
//   Per pixel, beside the pool (each a full-screen buffer of 4 B words unless noted):
//     counter | [offset] | [lock] | [occupancy: zn zf j_k bitmap] | [tail: 5 words] | [prev 1 B]
//
// Worked example, 1024 x 1024, M = 20 MiB (20,971,520 B): fkb pays 4 B/pixel -> F = 2,097,152,
// k = 2; kplus-sb pays 12 B/pixel -> F = 1,048,576; kplus-dynamic also pays the 4 KiB histogram;
// hybrid compositing adds 20 B/pixel, more than fkb's whole share of such a budget.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "mfr/method/method.hpp"

namespace mfr {

inline constexpr uint64_t kNodeBytes = 8;
inline constexpr uint64_t kLinkedNodeBytes = 12;  // depth bits, RGBA8, next index
inline constexpr uint64_t kHistogramBins = 1024;

/// Bytes per pixel of an occupancy map of `words` 32-bit bucket words: near and far depth and the
/// culling threshold (4 bytes each), then the bitmap (occupancy-map-culling.txt, sec. 3).
inline constexpr uint64_t occupancyBytesPerPixel(int words) {
  return 12 + 4 * static_cast<uint64_t>(words);
}

// The linked list (linked-list, linked_list.hpp; Yang et al. 2010): no counter, a head word per
// pixel (the index of the pixel's newest node), one 4-byte pool counter per image and a pool of
// 12-byte nodes (depth bits, RGBA8, next index):
//   M = |P| * (4 [+ 20 hybrid tail]) + 4 + 12 * F(M),  F(M) = floor((M - |P| S_p - 4) / 12)
//     heads: | h(0) | h(1) | ... | h(P-1) |    h(p) = newest node of p, or 0xFFFFFFFF (empty)
//     pool:  | depth rgba next | depth rgba next | ... |   F(M) nodes, handed out by the counter
struct MemoryModel {
  uint64_t counter = 4, offset = 0, lock = 0, occupancy = 0, tail = 0, previous = 0;  // per pixel
  uint64_t head = 0;           // per pixel: the linked list's head word
  uint64_t poolCounter = 0;    // per image: the linked list's node counter
  uint64_t accum = 0;          // per pixel: wboit / mboit accumulators
  uint64_t image = 0;          // bytes per image
  uint64_t node = kNodeBytes;  // S_f: bytes of one node (mlab: 20; wboit, mboit: 0, no nodes)

  /// `fragmentParallel`: methods without a lock word of their own (fkb, abuffer) need one per
  /// pixel when fragments of a pixel arrive from several threads (it stands in for the GPU's
  /// atomic insertion), and it is charged.
  static MemoryModel of(const MethodDesc& method, bool fragmentParallel = false);
  uint64_t perPixel() const {
    return counter + offset + lock + occupancy + tail + previous + accum + head;
  }
  uint64_t overhead(uint64_t pixels) const { return pixels * perPixel() + image + poolCounter; }
  /// F(M): fragment slots a budget buys (0 when the overhead alone exceeds it, or without nodes).
  uint64_t fragmentSlots(uint64_t budget, uint64_t pixels) const {
    const uint64_t fixed = overhead(pixels);
    return budget > fixed && node ? (budget - fixed) / node : 0;
  }
  /// Bytes by category for `slots` allocated nodes.
  std::map<std::string, uint64_t> breakdown(uint64_t pixels, uint64_t slots) const;
};

}  // namespace mfr
