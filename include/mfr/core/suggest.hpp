// "Did you mean": the known names closest to a mistyped one, for one-line errors that name what
// the user probably meant ("method 'kplus-arary': unknown; did you mean 'kplus-array'? ...").
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace mfr {

/// Edit distance between `a` and `b` as optimal string alignment: inserting, deleting or
/// replacing a character, or swapping two neighbouring ones, each counts 1 ("kplsu" -> "kplus"
/// is 1).
size_t editDistance(std::string_view a, std::string_view b);

/// The names of `known` closest to `word`, compared in lower case, when close enough to be a typo:
/// a distance of at most 2 and at most a third of `word`'s length (1 for words of up to 5
/// characters); every name at the smallest such distance, in `known`'s order. Empty when none is
/// that close (or `word` is one of them).
std::vector<std::string> closestNames(std::string_view word, const std::vector<std::string>& known);

/// "did you mean 'kplus-array'?" ("did you mean 'a' or 'b'?", "'a', 'b' or 'c'"), or "" when no
/// known name is close (closestNames).
std::string didYouMean(std::string_view word, const std::vector<std::string>& known);

}  // namespace mfr
