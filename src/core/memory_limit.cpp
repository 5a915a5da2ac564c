// Memory pre-flight (see mfr/core/memory_limit.hpp).
#include "mfr/core/memory_limit.hpp"

#include <unistd.h>

#include "mfr/core/units.hpp"

namespace mfr {

uint64_t physicalMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long pageSize = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return 0;
  return saturatingMul(static_cast<uint64_t>(pages), static_cast<uint64_t>(pageSize));
}

uint64_t defaultMemoryLimit() {
  const uint64_t physical = physicalMemoryBytes();
  if (physical == 0) return UINT64_MAX;
  return static_cast<uint64_t>(static_cast<double>(physical) * kDefaultMemoryShare);
}

Result<void> checkMemory(uint64_t bytes, uint64_t limit, const std::string& what) {
  if (bytes <= limit) return {};
  const std::string needed = bytes == UINT64_MAX
                                 ? std::string("more than 2^64 bytes")
                                 : formatBytes(bytes) + " (" + std::to_string(bytes) + " bytes)";
  return makeError(what + " need " + needed + ", more than the memory limit of " +
                   formatBytes(limit) + " (" + std::to_string(limit) + " bytes; --memory-limit)");
}

}  // namespace mfr
