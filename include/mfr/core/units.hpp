// Parsing of user-facing quantities.
#pragma once

#include <cstdint>
#include <string>

#include "mfr/core/result.hpp"

namespace mfr {

/// "20MB", "512KiB", "1.5GB", "4096" (bytes). Units are binary: KB = KiB = 2^10, MB = MiB = 2^20,
/// GB = GiB = 2^30 (the convention of the papers' GPU budgets). Case-insensitive; at most 1 TiB.
Result<uint64_t> parseByteSize(const std::string& text);

/// "20.0 MiB"-style rendering of a byte count.
std::string formatBytes(uint64_t bytes);

}  // namespace mfr
