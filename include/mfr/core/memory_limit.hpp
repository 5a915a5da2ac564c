// Memory pre-flight: before a large buffer is allocated, the bytes it needs are computed and
// checked against a limit, so a too-large request is a one-line error naming the input, the bytes
// needed and the limit instead of an out-of-memory crash or a std::bad_alloc.
#pragma once

#include <cstdint>
#include <string>

#include "mfr/core/result.hpp"

namespace mfr {

/// The default limit is this share of the physical memory.
inline constexpr double kDefaultMemoryShare = 0.75;

/// Installed physical memory in bytes (sysconf), 0 when unknown.
uint64_t physicalMemoryBytes();

/// kDefaultMemoryShare of the physical memory; no limit (UINT64_MAX) when it is unknown.
uint64_t defaultMemoryLimit();

/// Fails when `bytes` exceed `limit`: "<what> need(s) 8.60 GiB (9227468800 bytes), more than the
/// memory limit of 64.00 MiB (67108864 bytes; --memory-limit)".
Result<void> checkMemory(uint64_t bytes, uint64_t limit, const std::string& what);

/// a * b and a + b, saturating at UINT64_MAX (sizes computed from untrusted counts).
inline uint64_t saturatingMul(uint64_t a, uint64_t b) {
  uint64_t r = 0;
  return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}
inline uint64_t saturatingAdd(uint64_t a, uint64_t b) {
  uint64_t r = 0;
  return __builtin_add_overflow(a, b, &r) ? UINT64_MAX : r;
}

}  // namespace mfr
