// Budgets as the user gives them: absolute bytes ("20MB") or relative to the frame ("30%").
//
// A relative budget (issue 14, sec. 1) means the same on every scene: a share s of the exact
// A-buffer's node bytes for this frame, on top of the method's own per-pixel and per-image words
// (its memory model, DHOIT Eq. 1):
//
//   M(s) = |P| * S_p + S_i + floor(s * 8 * N)       N = sum of n(p) (the count pass)
//
// so every method gets the same node bytes at the same share, whatever its overhead, and F(M) is
// floor(floor(s * 8 * N) / S_f) nodes (floor(s * N) for 8-byte nodes). A share is the smallest
// that works when it buys one node per pixel the policy must serve: every pixel for fixed k, every
// covered pixel (n(p) > 0) for the others; the A-buffer needs 100%; wboit and mboit, which keep no
// nodes, work at any share, and so do the per-pixel policies (counted, dynamic, importance,
// optimal) under hybrid compositing, where a pixel without a slot keeps its tail
// (allowsTailOnlyPixels, allocation.hpp; issue 28).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

/// "20MB" for whole MiB, "400KB" for whole KiB, else "12345B" (file-name safe).
std::string budgetLabel(uint64_t bytes);

/// A budget as parsed: bytes, or a percentage of the A-buffer's node bytes.
struct BudgetSpec {
  std::optional<uint64_t> bytes;  // absolute
  double percent = 0.0;           // relative (when bytes is empty), in (0, 1000]
  std::string label;              // as shown: "20MB" (budgetLabel), "30%"

  BudgetSpec() = default;
  /// An absolute budget of `b` bytes (so a list of byte counts converts).
  BudgetSpec(uint64_t b);  // NOLINT(google-explicit-constructor)
  /// A relative budget of `p` percent.
  static BudgetSpec relative(double p);
  bool isRelative() const { return !bytes.has_value(); }
  /// File-name safe form of the label: "20MB", "30pct", "12.5pct".
  std::string fileLabel() const;
  bool operator==(const BudgetSpec& o) const {
    return bytes == o.bytes && (bytes || percent == o.percent);
  }
};

/// "20MB", "512KB", "4096" (parseByteSize) or "30%", "12.5%" (a share in (0, 1000] percent).
/// Errors (one line) name the text.
Result<BudgetSpec> parseBudgetSpec(const std::string& text);

/// What a relative budget needs from the count pass: n(p) summed and the pixels it covers.
struct FrameCounts {
  uint64_t pixels = 0;
  uint64_t coveredPixels = 0;  // n(p) > 0
  uint64_t fragments = 0;      // N = sum n(p): the A-buffer keeps 8 * N node bytes
  static FrameCounts of(const std::vector<uint32_t>& n);
};

/// floor(percent / 100 * 8 * N): the node bytes a share buys.
uint64_t relativeNodeBytes(double percent, const FrameCounts& counts);

/// The smallest share (percent, rounded up to 0.01) with which `method` gets one node per pixel it
/// must serve (see above); 0 for methods without nodes and for allowsTailOnlyPixels, 100 for the
/// A-buffer.
double smallestWorkingPercent(const MethodDesc& method, const MemoryModel& memory,
                              const FrameCounts& counts);

/// Bytes of `spec` for `method` on a frame: the absolute bytes, or M(s) above. Errors (one line,
/// naming the label, the method and the smallest share that works): a share too small for one
/// node per (covered) pixel. `size` names the frame in messages ("1024x1024").
Result<uint64_t> resolveBudget(const BudgetSpec& spec, const MethodDesc& method,
                               const MemoryModel& memory, const FrameCounts& counts,
                               const std::string& size);

}  // namespace mfr
