#include "mfr/scene/cull_mode.hpp"

#include "mfr/core/quote.hpp"

namespace mfr {

const char* toString(CullMode mode) {
  switch (mode) {
    case CullMode::Auto:
      return "auto";
    case CullMode::None:
      return "none";
    case CullMode::Back:
      return "back";
  }
  return "auto";
}

Result<CullMode> parseCullMode(const std::string& text, const std::string& name) {
  for (CullMode mode : {CullMode::Auto, CullMode::None, CullMode::Back})
    if (text == toString(mode)) return mode;
  return makeError(name + " " + quoteInput(text) + ": expected auto, none or back");
}

}  // namespace mfr
