// Memory pre-flight: before a large buffer is allocated, the bytes it needs are computed and
// checked against a limit, so a too-large request is a one-line error naming the input, the bytes
// needed and the limit instead of an out-of-memory crash or a std::bad_alloc.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "mfr/core/result.hpp"

namespace mfr {

/// The default limit is this share of the memory the process may use.
inline constexpr double kDefaultMemoryShare = 0.75;

/// Installed physical memory in bytes (sysconf), 0 when unknown.
uint64_t physicalMemoryBytes();

/// What bounds the memory of this process, in bytes; 0 where unknown or unlimited.
struct MemoryBounds {
  uint64_t physical = 0;      // installed memory (physicalMemoryBytes)
  uint64_t addressSpace = 0;  // RLIMIT_AS, the soft limit (`ulimit -v`)
  uint64_t cgroup = 0;        // the tightest memory.max (v2) or memory.limit_in_bytes (v1) of the
                              // process's cgroup and its ancestors
};

/// The bounds of this process as they are now (sysconf, getrlimit, /proc/self/cgroup and
/// /sys/fs/cgroup).
MemoryBounds memoryBounds();

/// kDefaultMemoryShare of the smallest known bound (the address space and a cgroup hold the
/// process's code, scene and threads too, so each gets the same share as the physical memory); no
/// limit (UINT64_MAX) when none is known.
uint64_t defaultMemoryLimit(const MemoryBounds& bounds);

/// defaultMemoryLimit(memoryBounds()): what --memory-limit defaults to.
uint64_t defaultMemoryLimit();

/// A cgroup memory limit file's value in bytes: "max" (v2) and v1's "unlimited" (2^63 less a page)
/// give 0, as does anything that is not a number.
uint64_t parseCgroupMemoryLimit(std::string_view text);

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
