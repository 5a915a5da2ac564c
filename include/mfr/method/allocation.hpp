// The allocation step every engine shares: the method's policy, the budget M and what the
// earlier passes measured (n(p), importance I(p), the oracle's k(p)) give each pixel's slots k(p)
// and where its nodes live (an exclusive prefix sum). A pure function of its inputs: no frame, no
// engine. Policies and their papers: src/method/allocation.cpp.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

/// The frame's pixels and the order of the node pool: offsets run tile by tile (tileSize x
/// tileSize tiles, row-major inside a tile and over tiles; the S-buffer's clustering for
/// locality), or row by row when tileSize is 0 (a full-screen prefix sum on the GPU).
struct PixelLayout {
  int width = 0;
  int height = 0;
  int tileSize = 0;
  uint64_t pixels() const { return static_cast<uint64_t>(width) * static_cast<uint64_t>(height); }
};

/// Slots per pixel and where they live.
struct Allocation {
  std::vector<uint32_t> capacity;  // k(p)
  std::vector<uint64_t> offsets;   // first slot of pixel p
  std::vector<StoreKind> kind;     // store used by pixel p
  uint64_t slots = 0;              // total nodes materialised
  std::optional<uint32_t> globalK;
  // Importance allocation: the paper's k(p) may exceed n(p); those slots are reserved (and
  // accounted for) but never filled, so the engine materialises only min(k(p), n(p)).
  std::vector<uint32_t> reservedK;  // k(p) as allocated (empty: same as capacity)
  uint64_t reservedSlots = 0;       // sum of k(p): the nodes the memory model charges
  uint64_t scratchBytes = 0;        // temporary buffers of the policy (histogram, k before caps)
};

/// What a counted-k or dynamic-k allocation needs of n(p): a few numbers, so that an engine can
/// count and allocate on the GPU and check the budget on the host with allocate()'s words.
struct CountSummary {
  std::vector<uint64_t> histogram;  // kHistogramBins bins of n(p), the last n >= kHistogramBins - 1
  uint64_t maxN = 0;                // the largest n(p)
  uint64_t covered = 0;             // pixels with n(p) > 0
};
CountSummary summarizeCounts(const std::vector<uint32_t>& fragmentCounts);

/// Whether the method may give a covered pixel no slot, k(p) = 0 (issue 28): under hybrid
/// compositing such a pixel is composited from its order-independent tail alone, so the policies
/// that allocate per pixel from a count pass (counted k, dynamic k, importance, optimal) take any
/// budget down to the per-pixel words. Kbuffer compositing has no tail (a pixel without a slot
/// would lose all its fragments): one node per covered pixel stays its floor. Fixed k and the
/// A-buffer keep theirs under either rule.
bool allowsTailOnlyPixels(const MethodDesc& method);

/// allocate()'s first check, before any pass: the per-pixel words (and, unless the method keeps
/// no nodes or allowsTailOnlyPixels, one node) fit the budget. F(M) in nodes (UINT64_MAX without
/// a budget).
Result<uint64_t> budgetSlots(const PixelLayout& layout, const MethodDesc& method,
                             const MemoryModel& memory, std::optional<uint64_t> budget);
/// The global k of a counted-k (explicit or F(M) / |P|) or dynamic-k (the largest k whose
/// sum of min(n(p), k) fits F(M), from the histogram) allocation, with allocate()'s errors; 0
/// (every pixel tail-only) when no k >= 1 fits and allowsTailOnlyPixels.
Result<uint32_t> boundedK(const PixelLayout& layout, const MethodDesc& method,
                          const MemoryModel& memory, std::optional<uint64_t> budget,
                          const CountSummary& counts);
/// allocate()'s check that a counted/dynamic k's sum of min(n(p), k) = `slots` nodes fits.
Result<void> checkBoundedSlots(const PixelLayout& layout, const MethodDesc& method,
                               const MemoryModel& memory, std::optional<uint64_t> budget,
                               uint32_t k, uint64_t slots);
/// allocate()'s checks of an importance or optimal allocation: a budget, and one node per covered
/// pixel unless allowsTailOnlyPixels.
Result<void> checkCoveredPixels(const PixelLayout& layout, const MethodDesc& method,
                                const MemoryModel& memory, std::optional<uint64_t> budget,
                                uint64_t covered);

/// Turns the policy, the budget and (when a count pass ran) n(p) into k(p) and offsets.
/// `fragmentCounts`: n(p) (empty when the method does not count); `importance`: I(p) of the
/// importance policies; `oracleK`: the optimal policy's k(p). Errors (one line): a budget too
/// small for the per-pixel words and (unless allowsTailOnlyPixels) one node per (covered) pixel,
/// a bounded policy with neither budget nor k, an explicit k that does not fit. `reuse`: an
/// earlier allocation whose per-pixel arrays of exactly this frame's size are taken over instead
/// of allocated afresh (the CPU engine's FrameBuffers; the result is the same).
Result<Allocation> allocate(const PixelLayout& layout, const MethodDesc& method,
                            const MemoryModel& memory, std::optional<uint64_t> budget,
                            const std::vector<uint32_t>& fragmentCounts,
                            const std::vector<float>& importance,
                            const std::vector<uint32_t>& oracleK, Allocation* reuse = nullptr);

}  // namespace mfr
