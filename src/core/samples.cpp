#include "mfr/core/samples.hpp"

#include <algorithm>

#include "mfr/core/quote.hpp"

namespace mfr {

namespace {
constexpr SampleOffset kOne[] = {{0, 0}};
constexpr SampleOffset kTwo[] = {{4, 4}, {-4, -4}};
constexpr SampleOffset kFour[] = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
constexpr SampleOffset kEight[] = {{1, -3}, {-1, 3},  {5, 1}, {-3, -5},
                                   {-5, 5}, {-7, -1}, {3, 7}, {7, -7}};
}  // namespace

std::span<const SampleOffset> samplePattern(int samples) {
  switch (samples) {
    case 1:
      return kOne;
    case 2:
      return kTwo;
    case 4:
      return kFour;
    case 8:
      return kEight;
    default:
      return {};
  }
}

Result<int> parseSamples(const std::string& text, const std::string& name) {
  for (int s : {1, 2, 4, 8})
    if (text == std::to_string(s)) return s;
  return makeError(name + " " + quoteInput(text) + ": expected 1, 2, 4 or 8");
}

Result<std::vector<int>> parseSampleCounts(const std::string& list, const std::string& name) {
  std::vector<int> counts;
  size_t begin = 0;
  while (begin <= list.size()) {
    const size_t end = std::min(list.find(',', begin), list.size());
    std::string text = list.substr(begin, end - begin);
    const size_t b = text.find_first_not_of(" \t"), e = text.find_last_not_of(" \t");
    text = b == std::string::npos ? std::string() : text.substr(b, e - b + 1);
    auto count = parseSamples(text, name);
    if (!count) return count.error();
    if (std::find(counts.begin(), counts.end(), *count) != counts.end())
      return makeError(name + " " + quoteInput(list) + ": " + text + " listed twice");
    counts.push_back(*count);
    begin = end + 1;
  }
  return counts;
}

const char* toString(SampleStorage storage) {
  return storage == SampleStorage::Sample ? "sample" : "pixel";
}

Result<SampleStorage> parseSampleStorage(const std::string& text, const std::string& name) {
  if (text == "pixel") return SampleStorage::Pixel;
  if (text == "sample") return SampleStorage::Sample;
  return makeError(name + " " + quoteInput(text) + ": expected pixel or sample");
}

}  // namespace mfr
