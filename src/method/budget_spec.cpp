// Absolute and relative budgets (issue 14, sec. 1; the memory model is DHOIT Eq. 1, see
// memory_model.hpp): parsing, the smallest share that works, and the bytes of a share.
#include "mfr/method/budget_spec.hpp"

#include <charconv>
#include <cmath>

#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/method/allocation.hpp"

namespace mfr {
namespace {

// shortest text that reads back as the same double ("30", "12.5")
std::string percentText(double p) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, p);
  return ec == std::errc() ? std::string(buffer, end) : std::to_string(p);
}

// nodes the policy must be able to give: one per pixel (fixed k: k per pixel), one per covered
// pixel, or every fragment (A-buffer); none when a covered pixel may go without a slot (hybrid
// compositing: its tail alone, allowsTailOnlyPixels)
uint64_t nodesNeeded(const MethodDesc& method, const FrameCounts& counts) {
  if (allowsTailOnlyPixels(method)) return 0;
  switch (method.allocation) {
    case AllocationPolicy::NoNodes:
      return 0;
    case AllocationPolicy::Pool:  // a pool of one node: the rest is dropped or tailed
      return 1;
    case AllocationPolicy::Unbounded:
      return counts.fragments;
    case AllocationPolicy::FixedK:
      return counts.pixels * std::max<uint64_t>(1, method.k.value_or(1));
    case AllocationPolicy::CountedK:
    case AllocationPolicy::DynamicK:
    case AllocationPolicy::Importance:
    case AllocationPolicy::Optimal:
      return counts.coveredPixels;
  }
  return counts.coveredPixels;
}

bool enough(double percent, uint64_t needed, const MemoryModel& memory, const FrameCounts& counts) {
  return memory.node == 0 || relativeNodeBytes(percent, counts) / memory.node >= needed;
}

}  // namespace

std::string budgetLabel(uint64_t bytes) {
  std::string s;
  if (bytes > 0 && bytes % (1ull << 20) == 0) {
    s = std::to_string(bytes >> 20);
    s += "MB";
  } else if (bytes > 0 && bytes % (1ull << 10) == 0) {
    s = std::to_string(bytes >> 10);
    s += "KB";
  } else {
    s = std::to_string(bytes);
    s += "B";
  }
  return s;
}

BudgetSpec::BudgetSpec(uint64_t b) : bytes(b), label(budgetLabel(b)) {}

BudgetSpec BudgetSpec::relative(double p) {
  BudgetSpec s;
  s.percent = p;
  s.label = percentText(p) + "%";
  return s;
}

std::string BudgetSpec::fileLabel() const {
  return bytes ? label : percentText(percent) + "pct";
}

Result<BudgetSpec> parseBudgetSpec(const std::string& text) {
  const size_t last = text.find_last_not_of(" \t");
  if (last == std::string::npos || text[last] != '%') {
    auto bytes = parseByteSize(text);
    if (!bytes) return bytes.error();
    return BudgetSpec(bytes.value());
  }
  const auto bad = [&] {
    return makeError("budget " + quoteInput(text) +
                     ": expected a share such as 30% or 12.5% (of the A-buffer's node bytes), "
                     "above 0 and at most 1000%");
  };
  const size_t first = text.find_first_not_of(" \t");
  double value = 0.0;
  const char* begin = text.data() + first;
  const char* end = text.data() + last;
  while (end > begin && (end[-1] == ' ' || end[-1] == '\t')) --end;
  const auto [ptr, ec] = std::from_chars(begin, end, value, std::chars_format::fixed);
  if (begin == end || ec != std::errc() || ptr != end || !std::isfinite(value) || value <= 0.0 ||
      value > 1000.0)
    return bad();
  return BudgetSpec::relative(value);
}

FrameCounts FrameCounts::of(const std::vector<uint32_t>& n) {
  FrameCounts c;
  c.pixels = n.size();
  for (uint32_t v : n) {
    c.coveredPixels += v > 0;
    c.fragments += v;
  }
  return c;
}

uint64_t relativeNodeBytes(double percent, const FrameCounts& counts) {
  // multiply first: a whole or half percent times 8 N is exact in long double, and so is its
  // quotient by 100 when that is a whole number (no 59255.999 for 60% of 8 * 12345)
  const long double bytes = static_cast<long double>(percent) *
                            static_cast<long double>(kNodeBytes * counts.fragments) / 100.0L;
  return static_cast<uint64_t>(std::floor(bytes));
}

double smallestWorkingPercent(const MethodDesc& method, const MemoryModel& memory,
                              const FrameCounts& counts) {
  const uint64_t needed = nodesNeeded(method, counts);
  if (needed == 0 || memory.node == 0) return 0.0;
  if (counts.fragments == 0) return INFINITY;
  const long double exact = 100.0L * static_cast<long double>(needed * memory.node) /
                            static_cast<long double>(kNodeBytes * counts.fragments);
  double p = static_cast<double>(std::ceil(exact * 100.0L) / 100.0L);
  while (!enough(p, needed, memory, counts)) p = std::round(p * 100.0 + 1.0) / 100.0;
  return p;
}

Result<uint64_t> resolveBudget(const BudgetSpec& spec, const MethodDesc& method,
                               const MemoryModel& memory, const FrameCounts& counts,
                               const std::string& size) {
  if (spec.bytes) return *spec.bytes;
  const uint64_t needed = nodesNeeded(method, counts);
  if (!enough(spec.percent, needed, memory, counts)) {
    const double smallest = smallestWorkingPercent(method, memory, counts);
    const char* what = method.allocation == AllocationPolicy::Unbounded ? "every fragment"
                       : method.allocation == AllocationPolicy::FixedK
                           ? "one node per pixel"
                           : "one node per covered pixel";
    // a policy that would take any share under hybrid compositing: say why this rule does not
    MethodDesc hybrid = method;
    hybrid.compositing = Compositing::Hybrid;
    const char* why = allowsTailOnlyPixels(hybrid)
                          ? "; kbuffer compositing keeps no tail, so a pixel without a slot would "
                            "lose all its fragments: hybrid compositing takes any share"
                          : "";
    return makeError("budget " + spec.label + ": too small for " + method.name + " at " + size +
                     " (" + what + " needs at least " +
                     (std::isfinite(smallest) ? percentText(smallest) + "%" : "a fragment") +
                     " of the A-buffer's " + std::to_string(counts.fragments) + " nodes" + why +
                     ")");
  }
  return memory.overhead(counts.pixels) + relativeNodeBytes(spec.percent, counts);
}

}  // namespace mfr
