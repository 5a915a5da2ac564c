#include "mfr/core/blend_mode.hpp"

#include "mfr/core/quote.hpp"

namespace mfr {

const char* toString(BlendMode mode) {
  switch (mode) {
    case BlendMode::Over:
      return "over";
    case BlendMode::Premultiplied:
      return "premultiplied";
    case BlendMode::Additive:
      return "additive";
    case BlendMode::Multiply:
      return "multiply";
  }
  return "over";
}

Result<BlendMode> parseBlendMode(const std::string& text, const std::string& name) {
  for (BlendMode mode : kBlendModes)
    if (text == toString(mode)) return mode;
  return makeError(name + " " + quoteInput(text) +
                   ": expected over, premultiplied, additive or multiply");
}

Result<BlendOverride> parseBlendOverride(const std::string& text, const std::string& name) {
  BlendOverride o;
  const size_t eq = text.rfind('=');
  const std::string mode = eq == std::string::npos ? text : text.substr(eq + 1);
  if (eq != std::string::npos) {
    o.material = text.substr(0, eq);
    if (o.material.empty())
      return makeError(name + " " + quoteInput(text) +
                       ": expected MODE or MATERIAL=MODE (the material name is empty)");
  }
  auto parsed = parseBlendMode(mode, name);
  if (!parsed)
    return makeError(name + " " + quoteInput(text) +
                     ": expected MODE or MATERIAL=MODE "
                     "with MODE over, premultiplied, additive or multiply");
  o.mode = *parsed;
  return o;
}

}  // namespace mfr
