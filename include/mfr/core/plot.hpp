// Line and grouped bar charts rendered to an sRGB8 image (e.g. a training-loss curve per epoch, a
// frame time per scene and engine): axes with nice tick labels (decades on a log y axis), light
// grid, legend, one thick polyline per series or one bar per series and category.
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

struct BarSeries {
  std::string label;           // shown in the legend, as PlotSeries::label
  std::vector<double> values;  // one per category; a non-finite value (or <= 0 on a log axis) is
                               // no bar
  glm::vec3 color{0.0f};       // sRGB in [0, 1]
};

/// Grouped bars on a white background: per category (its name under the x axis) one bar per
/// series, side by side in the series' order, from 0 (a log axis: from its bottom) to the value,
/// with the value written above a bar where it fits; the labelled series' legend is a row above
/// the plot. Errors: as plotLines, no category, a series whose value count is not the categories'.
/// Deterministic.
Result<Image8> plotBars(const std::vector<std::string>& categories,
                        const std::vector<BarSeries>& series, const PlotOptions& options);

}  // namespace mfr
