#include "mfr/core/units.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "mfr/core/quote.hpp"

namespace mfr {

Result<uint64_t> parseByteSize(const std::string& text) {
  const auto bad = [&] {
    return makeError("budget " + quoteInput(text) +
                     ": expected a size such as 20MB, 512KB or 1048576");
  };
  size_t i = 0;
  while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.'))
    ++i;
  if (i == 0) return bad();
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + i, value);
  if (ec != std::errc() || ptr != text.data() + i || !std::isfinite(value)) return bad();
  std::string unit;
  for (size_t j = i; j < text.size(); ++j)
    if (!std::isspace(static_cast<unsigned char>(text[j])))
      unit += static_cast<char>(std::tolower(static_cast<unsigned char>(text[j])));
  double scale = 0.0;
  if (unit.empty() || unit == "b")
    scale = 1.0;
  else if (unit == "k" || unit == "kb" || unit == "kib")
    scale = 1024.0;
  else if (unit == "m" || unit == "mb" || unit == "mib")
    scale = 1024.0 * 1024.0;
  else if (unit == "g" || unit == "gb" || unit == "gib")
    scale = 1024.0 * 1024.0 * 1024.0;
  else
    return bad();
  const double bytes = std::floor(value * scale);
  if (bytes < 1.0) return makeError("budget " + quoteInput(text) + ": must be at least 1 byte");
  if (bytes > 1024.0 * 1024.0 * 1024.0 * 1024.0)
    return makeError("budget " + quoteInput(text) + ": above the 1 TiB limit");
  return static_cast<uint64_t>(bytes);
}

std::string formatBytes(uint64_t bytes) {
  char buf[64];
  if (bytes >= (1ull << 30))
    std::snprintf(buf, sizeof buf, "%.2f GiB", static_cast<double>(bytes) / (1ull << 30));
  else if (bytes >= (1ull << 20))
    std::snprintf(buf, sizeof buf, "%.2f MiB", static_cast<double>(bytes) / (1ull << 20));
  else if (bytes >= (1ull << 10))
    std::snprintf(buf, sizeof buf, "%.2f KiB", static_cast<double>(bytes) / (1ull << 10));
  else
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  return buf;
}

}  // namespace mfr
