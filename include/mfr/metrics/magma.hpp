// The magma colour map as a 256-entry table (matplotlib's data, which the FLIP tool uses for its
// error maps), and a helper that maps a scalar image through it.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mfr/core/image.hpp"

namespace mfr {

/// magma's 256 entries, sRGB-encoded values in [0, 1] (matplotlib's table).
const std::array<std::array<float, 3>, 256>& magmaTable();

/// The table entry for t in [0, 1] as the FLIP tool picks it: index int(t * 255 + 0.5), clamped;
/// NaN maps to entry 0.
int magmaIndex(float t);

/// The 8-bit sRGB colour of table entry `index` (each channel round(255 v), as the FLIP tool
/// writes its PNGs).
std::array<uint8_t, 3> magma8(int index);

/// Maps values / scale through magma into an opaque RGBA image of the given size (values.size()
/// must be width * height; scale > 0).
Image8 magmaImage(const std::vector<float>& values, int width, int height, float scale = 1.0f);

}  // namespace mfr
