// How an option is spelled where the user typed it. The library's checks of user options write
// their messages once, naming the command line's flag; spell() turns the flag into the Python
// keyword for the Python module, so both front ends report the same error in their own words.
#pragma once

#include <string>
#include <string_view>

namespace mfr {

enum class Spelling : unsigned char {
  Cli,     // --occupancy-d
  Python,  // occupancy_d
};

/// "--occupancy-d" -> "occupancy_d" for Python ("--width/--height" -> "width/height"); the flag
/// itself for the command line. Text that is not a flag is returned as it is.
inline std::string spell(Spelling spelling, std::string_view flag) {
  std::string out(flag);
  if (spelling == Spelling::Cli) return out;
  std::string python;
  for (size_t i = 0; i < out.size(); ++i) {
    if (out.compare(i, 2, "--") == 0 && (i == 0 || out[i - 1] == '/' || out[i - 1] == ' ')) {
      ++i;
      continue;
    }
    python += out[i] == '-' ? '_' : out[i];
  }
  return python;
}

}  // namespace mfr
