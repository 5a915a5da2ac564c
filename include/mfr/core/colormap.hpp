// Colour-mapped visualisations of per-pixel quantities (depth complexity, k(p), error maps), with
// a legend strip so a figure can be read on its own.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/image.hpp"

namespace mfr {

enum class Colormap { Viridis, Magma };

/// sRGB colour of t in [0, 1] (polynomial fits of matplotlib's maps).
glm::vec3 colormap(Colormap map, float t);

/// Maps values in [0, maxValue] to colours and appends a legend strip (gradient bar with the
/// minimum, middle and maximum labelled, and a title) below the image.
Image8 colorMapWithLegend(const std::vector<float>& values, int width, int height, float maxValue,
                          const std::string& title, Colormap map = Colormap::Viridis);

}  // namespace mfr
