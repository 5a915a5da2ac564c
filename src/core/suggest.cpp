#include "mfr/core/suggest.hpp"

#include <algorithm>
#include <cctype>

#include "mfr/core/quote.hpp"

namespace mfr {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

size_t editDistance(std::string_view a, std::string_view b) {
  // three rows of the dynamic programme: i - 2, i - 1 and i
  const size_t m = b.size();
  std::vector<size_t> before(m + 1), previous(m + 1), current(m + 1);
  for (size_t j = 0; j <= m; ++j) previous[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (size_t j = 1; j <= m; ++j) {
      const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        current[j] = std::min(current[j], before[j - 2] + 1);
    }
    std::swap(before, previous);
    std::swap(previous, current);
  }
  return previous[m];
}

std::vector<std::string> closestNames(std::string_view word,
                                      const std::vector<std::string>& known) {
  // long inputs (a pasted path, 5000 characters) are nobody's typo: not compared
  if (word.empty() || word.size() > 200) return {};
  const std::string w = lower(word);
  const size_t limit = std::clamp<size_t>(word.size() / 3, 1, 2);
  size_t best = limit + 1;
  std::vector<std::string> names;
  for (const std::string& name : known) {
    if (name == word) return {};
    const size_t d = editDistance(w, lower(name));
    if (d > limit || d > best) continue;
    if (d < best) names.clear();
    best = d;
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  }
  return names;
}

std::string didYouMean(std::string_view word, const std::vector<std::string>& known) {
  const std::vector<std::string> names = closestNames(word, known);
  if (names.empty()) return {};
  std::string text = "did you mean ";
  for (size_t i = 0; i < names.size(); ++i) {
    if (i > 0) text += i + 1 == names.size() ? " or " : ", ";
    text += quoteInput(names[i]);
  }
  return text + "?";
}

}  // namespace mfr
