// Pieces shared by the two HTML reports of `mfr compare` (report_html.cpp: one view;
// temporal.cpp: an orbit): text formatting, the page's CSS and inline script (sortable tables,
// image wipers), and inline SVG line and scatter plots. Internal to src/compare.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace mfr::report {

std::string format(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string escape(const std::string& s);
/// 1234567 -> "1 234 567" (thin spaces)
std::string grouped(uint64_t v);
/// scientific notation as HTML: 1.23 × 10<sup>−4</sup>
std::string sci(double v, int digits = 3);
/// "nice" linear ticks covering [lo, hi]
std::vector<double> niceTicks(double lo, double hi, int target);

/// Okabe & Ito's colour-blind safe palette (without yellow), cycled.
const char* paletteColour(size_t i);

/// <!DOCTYPE html> up to and including <main>: the title and the shared style and script.
std::string pageStart(const std::string& title);
/// </main></body></html>
std::string pageEnd();

/// A td with its sort key (data-v) when it sorts by number.
std::string numberCell(double sortKey, const std::string& text, const std::string& cls = "");

struct Series {
  std::string name;
  std::string colour;
  int marker = 0;  // 0 circle, 1 square, 2 triangle, 3 diamond, 4 cross...
  std::vector<std::pair<double, double>> points;  // (x, y); a line joins them in x order
  std::vector<std::string> labels;                // per point, a tooltip (optional)
  std::vector<bool> onFront;  // per point (optional): ringed, class "point front"
  bool line = true;           // false: markers only (a scatter)
  /// Said after the name in the legend (e.g. "needs >= 1.25 MiB" for a method refused at some
  /// budgets); empty: "(failed)" without points, "(exact)" for an error of 0 everywhere.
  std::string note;
};

struct Ticks {
  std::vector<double> at;
  std::vector<std::string> labels;
};

struct PlotSpec {
  std::string title, xLabel, yLabel;
  std::optional<Ticks> xTicks;  // none: automatic (1, 2, 5 per decade on a log axis)
  bool logX = false;
  /// y of non-negative errors: chooseAxisScale (log where the values span decades, 0 drawn at
  /// the floor and marked "exact"); otherwise linear
  bool errorY = false;
  bool zeroBased = true;  // linear y from 0 (else from a little under the data)
  double plotWidth = 400, height = 360;
  /// drawn as a dashed staircase through these (x, y) points, x ascending: a Pareto front
  std::vector<std::pair<double, double>> front;
};

/// A bytes-per-pixel x axis over [lo, hi]: log (automatic ticks) when it spans a decade, else
/// ticks at whole bytes from the data's range and nice values between, labelled "N B".
void setBytesPerPixelAxis(PlotSpec& spec, double lo, double hi);

/// An inline <svg> plot (aria-label: the title). Its frame carries the axes (data-x-scale,
/// data-x-lo, data-x-hi, data-y-*, data-y-floor on a log error axis) and each point its exact
/// values (g.point data-x, data-y), so the plot can be read back.
std::string svgPlot(const PlotSpec& spec, const std::vector<Series>& series);

}  // namespace mfr::report
