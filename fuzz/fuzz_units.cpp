// Strings of the command line that the library parses: sizes and budgets (parseByteSize: a value
// in [1 B, 1 TiB] that prints and parses back to itself), method names (methodPreset) and
// compositing rules (parseCompositing). Errors are one line.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.hpp"
#include "mfr/core/units.hpp"
#include "mfr/method/method.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto bytes = mfr::parseByteSize(text);
  if (!bytes) {
    mfr::fuzz::checkError(bytes.error());
  } else {
    FUZZ_CHECK(*bytes >= 1 && *bytes <= (uint64_t{1} << 40), std::to_string(*bytes));
    auto again = mfr::parseByteSize(std::to_string(*bytes));
    FUZZ_CHECK(again.ok() && *again == *bytes, "does not parse back: " + std::to_string(*bytes));
    FUZZ_CHECK(!mfr::formatBytes(*bytes).empty(), "formatBytes");
  }
  auto method = mfr::methodPreset(text);
  if (!method) {
    mfr::fuzz::checkError(method.error());
  } else {
    FUZZ_CHECK(method->name == text, "preset name " + method->name + " for " + text);
  }
  auto compositing = mfr::parseCompositing(text);
  if (!compositing) mfr::fuzz::checkError(compositing.error());
  return 0;
}
