// Line charts rendered to an sRGB8 image (e.g. a training-loss curve per epoch): axes with nice
// tick labels (decades on a log y axis), light grid, legend, one thick polyline per series.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/image.hpp"
#include "mfr/core/result.hpp"

namespace mfr {

struct PlotSeries {
  std::string label;  // shown in the legend; a chart whose series have no labels has no legend
  std::vector<double> x, y;  // same length; a non-finite point (or y <= 0 on a log axis) is a gap
  glm::vec3 color{0.0f};     // sRGB in [0, 1]
};

struct PlotOptions {
  int width = 800, height = 500;  // each in [100, 8192]
  std::string title, xLabel, yLabel;
  bool logY = false;
};

/// Renders the series on a white background. Isolated points are drawn as dots. Errors: a size out
/// of range, x and y of different lengths, no finite point, or (logY) no positive y. Deterministic.
Result<Image8> plotLines(const std::vector<PlotSeries>& series, const PlotOptions& options);

}  // namespace mfr
