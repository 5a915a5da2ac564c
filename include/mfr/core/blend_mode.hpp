// Blend modes (`--blend`, a procedural scene's `blend=`): how a material's fragments combine with
// what lies behind them. Every mode is one affine step per channel, C = e + t C_behind, applied in
// depth order:
//   over           e = a c,                     t = 1 - a           (straight alpha, the default)
//   premultiplied  e = c (already times alpha), t = 1 - a           (Porter & Duff's over on
//                  premultiplied colour; alpha 0 with a colour is additive)
//   additive       e = a c,                     t = 1               (GL_SRC_ALPHA, GL_ONE)
//   multiply       e = 0,                       t = 1 - a + a c     (GL_DST_COLOR, GL_ZERO faded
//                  by alpha; per channel)
// c: the shaded linear colour, a: the alpha. How each mode travels in the 8-byte node and which
// methods take which mode: core/color.hpp (packBlendedColor) and method/blend_support.hpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"

namespace mfr {

enum class BlendMode : uint8_t { Over, Premultiplied, Additive, Multiply };

inline constexpr BlendMode kBlendModes[] = {BlendMode::Over, BlendMode::Premultiplied,
                                            BlendMode::Additive, BlendMode::Multiply};

/// Sets of modes as bit masks (a scene's modes, the modes a method takes).
constexpr uint32_t blendBit(BlendMode mode) {
  return 1u << static_cast<uint32_t>(mode);
}
inline constexpr uint32_t kEveryBlendMode = 0xfu;

/// "over", "premultiplied", "additive", "multiply".
const char* toString(BlendMode mode);
/// Parses toString's names; the error names the input as `name` ("--blend glow: expected over,
/// premultiplied, additive or multiply").
Result<BlendMode> parseBlendMode(const std::string& text, const std::string& name);

/// One `--blend` override: "MODE" (every material) or "MATERIAL=MODE" (the materials so named).
struct BlendOverride {
  std::string material;  // empty: every material
  BlendMode mode = BlendMode::Over;
};
Result<BlendOverride> parseBlendOverride(const std::string& text, const std::string& name);

}  // namespace mfr
