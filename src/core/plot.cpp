// Line and grouped bar charts as raster images (see mfr/core/plot.hpp). Text, ticks and line widths
// scale by an integer factor with the image size. Axis ranges widen to whole tick steps (1, 2 or 5
// x 10^k, at most 5 intervals; whole decades on a log axis) and series are drawn over the frame so
// that points on the range ends stay visible. Integer rasterisation only, so the output is
// deterministic.
#include "mfr/core/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/draw_text.hpp"

namespace mfr {
namespace {

using detail::drawText;
using detail::putPixel;
using detail::textWidth;

const glm::vec3 kInk(0.1f), kGrid(0.9f), kFrame(0.55f), kWhite(1.0f);

struct Axis {
  double lo = 0.0, hi = 1.0;  // in plotted units (log10 of the value on a log axis)
  std::vector<double> ticks, minor;
  std::vector<std::string> labels;
};

std::string format(const char* fmt, double v, int decimals = 0) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, decimals, v);
  return buf;
}

Axis linearAxis(double lo, double hi) {
  if (hi - lo <= 1e-9 * std::max(std::fabs(lo), std::fabs(hi))) {  // constant data
    const double d = lo != 0.0 ? std::fabs(lo) * 0.1 : 1.0;
    lo -= d;
    hi += d;
  }
  const double raw = (hi - lo) / 5.0, mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10.0 * mag;
  for (double m : {1.0, 2.0, 5.0})
    if (m * mag >= raw * (1.0 - 1e-9)) {
      step = m * mag;
      break;
    }
  Axis a;
  const double i0 = std::floor(lo / step + 1e-9), i1 = std::ceil(hi / step - 1e-9);
  a.lo = i0 * step;
  a.hi = i1 * step;
  const bool plain = step >= 1e-3 && std::max(std::fabs(a.lo), std::fabs(a.hi)) < 1e6;
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  for (double i = i0; i <= i1; ++i) {
    a.ticks.push_back(i * step);
    a.labels.push_back(plain ? format("%.*f", i * step, decimals) : format("%.*g", i * step, 3));
  }
  return a;
}

Axis logAxis(double lo, double hi) {  // lo, hi: log10 of the data range
  if (hi - lo < 1e-9) {
    lo -= 0.5;
    hi += 0.5;
  }
  // labelled decades: every one, or multiples of 2, 3, ... so that there are at most about 6
  const int every = (static_cast<int>(std::ceil(hi - 1e-9) - std::floor(lo + 1e-9)) + 5) / 6;
  Axis a;
  a.lo = std::floor(std::floor(lo + 1e-9) / every) * every;
  a.hi = std::ceil(std::ceil(hi - 1e-9) / every) * every;
  const int decades = static_cast<int>(a.hi - a.lo);
  for (int k = 0; k <= decades; ++k) {
    const double e = a.lo + k;
    if (k % every != 0) {
      a.minor.push_back(e);
      continue;
    }
    a.ticks.push_back(e);
    a.labels.push_back(format("1e%.*f", e, 0));
    for (int m = 2; m <= 9 && every == 1 && k < decades; ++m) a.minor.push_back(e + std::log10(m));
  }
  return a;
}

struct Rect {
  int x0, y0, x1, y1;  // inclusive
};

// A filled disc of radius r centred at (cx, cy) in pixel-centre coordinates, clipped to `clip`.
void disc(Image8& img, const Rect& clip, double cx, double cy, double r, glm::vec3 c) {
  const int xa = std::max(clip.x0, static_cast<int>(std::floor(cx - r)));
  const int xb = std::min(clip.x1, static_cast<int>(std::ceil(cx + r)));
  const int ya = std::max(clip.y0, static_cast<int>(std::floor(cy - r)));
  const int yb = std::min(clip.y1, static_cast<int>(std::ceil(cy + r)));
  for (int y = ya; y <= yb; ++y)
    for (int x = xa; x <= xb; ++x)
      if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r) putPixel(img, x, y, c);
}

void segment(Image8& img, const Rect& clip, glm::dvec2 a, glm::dvec2 b, double r, glm::vec3 c) {
  const int n =
      static_cast<int>(std::ceil(2.0 * std::max(std::fabs(b.x - a.x), std::fabs(b.y - a.y))));
  for (int i = 0; i <= n; ++i) {
    const glm::dvec2 p = n == 0 ? a : a + (b - a) * (static_cast<double>(i) / n);
    disc(img, clip, p.x, p.y, r, c);
  }
}

void fill(Image8& img, const Rect& r, glm::vec3 c) {
  for (int y = r.y0; y <= r.y1; ++y)
    for (int x = r.x0; x <= r.x1; ++x) putPixel(img, x, y, c);
}

// Text rotated a quarter turn anticlockwise (reading upwards), its left edge at x, centred on cy.
void drawTextUp(Image8& img, int x, int cy, const std::string& text, int s, glm::vec3 c) {
  Image8 tmp;
  tmp.width = textWidth(text, s);
  tmp.height = 12 * s;
  tmp.rgba.assign(static_cast<size_t>(tmp.width) * tmp.height * 4, 0);
  drawText(tmp, 0, 0, text, s, kWhite);
  for (int ty = 0; ty < tmp.height; ++ty)
    for (int tx = 0; tx < tmp.width; ++tx)
      if (tmp.rgba[(static_cast<size_t>(ty) * tmp.width + tx) * 4 + 3])
        putPixel(img, x + ty, cy + tmp.width / 2 - tx, c);
}

// A point is drawable when both coordinates are finite and, on a log axis, y is positive.
bool drawable(double x, double y, bool logY) {
  return std::isfinite(x) && std::isfinite(y) && (!logY || y > 0.0);
}

// The axes over the drawable points' range (y in log10 on a log axis), or why there is none.
struct Axes {
  Axis x, y;
};

Result<Axes> dataAxes(const std::vector<PlotSeries>& series, bool logY) {
  double xMin = INFINITY, xMax = -INFINITY, yMin = INFINITY, yMax = -INFINITY;
  bool anyFinite = false;
  for (const PlotSeries& s : series) {
    if (s.x.size() != s.y.size()) {
      std::string m = "plot series '";
      m += s.label + "' has " + std::to_string(s.x.size()) + " x values but " +
           std::to_string(s.y.size()) + " y values";
      return makeError(m);
    }
    for (size_t i = 0; i < s.x.size(); ++i) {
      anyFinite = anyFinite || (std::isfinite(s.x[i]) && std::isfinite(s.y[i]));
      if (!drawable(s.x[i], s.y[i], logY)) continue;
      const double y = logY ? std::log10(s.y[i]) : s.y[i];
      xMin = std::min(xMin, s.x[i]);
      xMax = std::max(xMax, s.x[i]);
      yMin = std::min(yMin, y);
      yMax = std::max(yMax, y);
    }
  }
  if (!anyFinite) return makeError("plot has no finite data point");
  if (xMin > xMax) return makeError("log-scale plot has no positive y value");
  if (!std::isfinite(xMax - xMin) || !std::isfinite(yMax - yMin))
    return makeError("plot data range is too large");
  return Axes{linearAxis(xMin, xMax), logY ? logAxis(yMin, yMax) : linearAxis(yMin, yMax)};
}

// Where everything goes: the text scale, the spacings and the plot area inside the margins.
struct Layout {
  int W, H;
  int s, charH, pad, tick, gap;
  Axes axes;
  bool logY;
  Rect plot;

  double px(double v) const {
    return plot.x0 + (v - axes.x.lo) / (axes.x.hi - axes.x.lo) * (plot.x1 - plot.x0);
  }
  double py(double v) const {
    return plot.y1 - (v - axes.y.lo) / (axes.y.hi - axes.y.lo) * (plot.y1 - plot.y0);
  }
  // a data point in pixel coordinates
  glm::dvec2 at(const PlotSeries& se, size_t k) const {
    return glm::dvec2(px(se.x[k]), py(logY ? std::log10(se.y[k]) : se.y[k]));
  }
};

// `legendRow`: a row under the title for the legend (bar charts: no corner of their plot is free)
Result<Layout> layOut(const PlotOptions& options, Axes axes, bool legendRow = false) {
  const int W = options.width, H = options.height;
  const int s = std::max(1, std::min(W / 400, H / 250));
  const int charH = 7 * s, pad = 8 * s, tick = 4 * s, gap = 3 * s;
  int yTickW = 0;
  for (const std::string& l : axes.y.labels) yTickW = std::max(yTickW, textWidth(l, s));
  const int top = pad + (options.title.empty() ? 0 : charH + pad) + (legendRow ? charH + pad : 0);
  const int left = pad + (options.yLabel.empty() ? 0 : charH + pad) + yTickW + gap + tick;
  const int bottom = tick + gap + charH + (options.xLabel.empty() ? 0 : pad + charH) + pad;
  const int right = pad + textWidth(axes.x.labels.back(), s) / 2;
  const Rect plot{left, top, W - 1 - right, H - 1 - bottom};
  if (plot.x1 - plot.x0 < 20 || plot.y1 - plot.y0 < 20)
    return makeError("plot size is too small for its labels");
  return Layout{W, H, s, charH, pad, tick, gap, std::move(axes), options.logY, plot};
}

// grid lines (vertical ones with xGrid), the frame and the tick marks
void drawGrid(Image8& img, const Layout& L, bool xGrid = true) {
  const Rect& plot = L.plot;
  for (double t : L.axes.x.ticks) {
    const int x = static_cast<int>(std::lround(L.px(t)));
    if (xGrid) fill(img, {x, plot.y0, x, plot.y1 + L.tick}, kGrid);
    fill(img, {x, plot.y1, x, plot.y1 + L.tick}, kInk);
  }
  for (double t : L.axes.y.ticks) {
    const int y = static_cast<int>(std::lround(L.py(t)));
    fill(img, {plot.x0 - L.tick, y, plot.x1, y}, kGrid);
    fill(img, {plot.x0 - L.tick, y, plot.x0, y}, kInk);
  }
  for (double t : L.axes.y.minor) {
    const int y = static_cast<int>(std::lround(L.py(t)));
    fill(img, {plot.x0 - L.tick / 2, y, plot.x0, y}, kInk);
  }
  fill(img, {plot.x0, plot.y0, plot.x1, plot.y0}, kFrame);
  fill(img, {plot.x0, plot.y1, plot.x1, plot.y1}, kInk);
  fill(img, {plot.x0, plot.y0, plot.x0, plot.y1}, kInk);
  fill(img, {plot.x1, plot.y0, plot.x1, plot.y1}, kFrame);
}

// tick labels, every n-th one when they would collide
void drawTickLabels(Image8& img, const Layout& L) {
  const Axis &ax = L.axes.x, &ay = L.axes.y;
  const int s = L.s, gap = L.gap;
  auto stride = [](double spacing, int size) {
    return std::max(1, static_cast<int>(std::ceil(size / std::max(1.0, std::fabs(spacing)))));
  };
  int xLabelW = 0;
  for (const std::string& l : ax.labels) xLabelW = std::max(xLabelW, textWidth(l, s));
  const int xEvery =
      ax.ticks.size() < 2 ? 1 : stride(L.px(ax.ticks[1]) - L.px(ax.ticks[0]), xLabelW + 2 * gap);
  const int yEvery =
      ay.ticks.size() < 2 ? 1 : stride(L.py(ay.ticks[1]) - L.py(ay.ticks[0]), L.charH + gap);
  for (size_t i = 0; i < ax.ticks.size(); i += xEvery) {
    const int w = textWidth(ax.labels[i], s);
    const int x = std::clamp(static_cast<int>(std::lround(L.px(ax.ticks[i]))) - w / 2, 0, L.W - w);
    drawText(img, x, L.plot.y1 + L.tick + gap, ax.labels[i], s, kInk);
  }
  for (size_t i = 0; i < ay.ticks.size(); i += yEvery) {
    const int y = static_cast<int>(std::lround(L.py(ay.ticks[i])));
    const int x = L.plot.x0 - L.tick - gap - textWidth(ay.labels[i], s);
    drawText(img, x, y - L.charH / 2, ay.labels[i], s, kInk);
  }
}

// the half-width of a series' line
double lineRadius(const Layout& L) {
  return 0.5 * L.s + 0.5;
}

// series: runs of drawable points become polylines, lone points dots
void drawSeries(Image8& img, const Layout& L, const std::vector<PlotSeries>& series) {
  const double r = lineRadius(L);
  for (const PlotSeries& se : series) {
    const glm::vec3 c = glm::clamp(se.color, glm::vec3(0.0f), glm::vec3(1.0f));
    for (size_t i = 0; i < se.x.size();) {
      size_t j = i;
      while (j < se.x.size() && drawable(se.x[j], se.y[j], L.logY)) ++j;
      if (j == i + 1) disc(img, L.plot, L.at(se, i).x, L.at(se, i).y, 2.0 * r + 1.0, c);
      for (size_t k = i; k + 1 < j; ++k) segment(img, L.plot, L.at(se, k), L.at(se, k + 1), r, c);
      i = std::max(j, i + 1);
    }
  }
}

// legend in the plot corner covering the fewest drawn pixels (top right first); none if too big
void drawLegend(Image8& img, const Layout& L, const std::vector<PlotSeries>& series) {
  const int s = L.s, pad = L.pad;
  const Rect& plot = L.plot;
  int rows = 0, labelW = 0;
  for (const PlotSeries& se : series)
    if (!se.label.empty()) {
      ++rows;
      labelW = std::max(labelW, textWidth(se.label, s));
    }
  const int rowH = 12 * s, swatch = 20 * s, boxW = 3 * pad + swatch + labelW;
  const int boxH = rows * rowH + pad;
  if (rows == 0 || boxW + 2 * pad > plot.x1 - plot.x0 || boxH + 2 * pad > plot.y1 - plot.y0) return;
  Rect box{};
  size_t best = SIZE_MAX;
  for (int corner = 0; corner < 4; ++corner) {
    const int x0 = corner % 2 == 0 ? plot.x1 - pad - boxW : plot.x0 + pad;
    const int y0 = corner < 2 ? plot.y0 + pad : plot.y1 - pad - boxH;
    size_t drawn = 0;
    for (int y = y0; y <= y0 + boxH; ++y)
      for (int x = x0; x <= x0 + boxW; ++x) {
        const uint8_t* p = &img.rgba[(static_cast<size_t>(y) * L.W + x) * 4];
        const bool grey = p[0] == p[1] && p[1] == p[2];  // white or grid
        drawn += !(grey && (p[0] == 255 || p[0] == static_cast<uint8_t>(kGrid.r * 255.0f + 0.5f)));
      }
    if (drawn < best) best = drawn, box = {x0, y0, x0 + boxW, y0 + boxH};
  }
  fill(img, box, kFrame);
  fill(img, {box.x0 + 1, box.y0 + 1, box.x1 - 1, box.y1 - 1}, kWhite);
  const double r = lineRadius(L);
  int y = box.y0 + pad / 2 + rowH / 2;
  for (const PlotSeries& se : series) {
    if (se.label.empty()) continue;
    const glm::vec3 c = glm::clamp(se.color, glm::vec3(0.0f), glm::vec3(1.0f));
    segment(img, box, {box.x0 + pad, y}, {box.x0 + pad + swatch, y}, r, c);
    drawText(img, box.x0 + 2 * pad + swatch, y - L.charH / 2, se.label, s, kInk);
    y += rowH;
  }
}

// the legend as one row of filled boxes and labels, centred above the plot (bar charts)
void drawLegendRow(Image8& img, const Layout& L, const std::vector<BarSeries>& series) {
  const int s = L.s, pad = L.pad, swatch = 10 * s;
  int width = 0;
  for (const BarSeries& se : series)
    if (!se.label.empty()) width += (width ? 2 * pad : 0) + swatch + L.gap + textWidth(se.label, s);
  int x = std::max(0, (L.plot.x0 + L.plot.x1 - width) / 2);
  const int y = L.plot.y0 - pad - L.charH;
  for (const BarSeries& se : series) {
    if (se.label.empty()) continue;
    fill(img, {x, y, x + swatch - 1, y + L.charH - 1},
         glm::clamp(se.color, glm::vec3(0.0f), glm::vec3(1.0f)));
    drawText(img, x + swatch + L.gap, y, se.label, s, kInk);
    x += swatch + L.gap + textWidth(se.label, s) + 2 * pad;
  }
}

// title and axis labels
void drawTitles(Image8& img, const Layout& L, const PlotOptions& options) {
  const int s = L.s, pad = L.pad;
  const int cx = (L.plot.x0 + L.plot.x1) / 2;
  if (!options.title.empty())
    drawText(img, cx - textWidth(options.title, s) / 2, pad, options.title, s, kInk);
  if (!options.xLabel.empty())
    drawText(img, cx - textWidth(options.xLabel, s) / 2, L.H - pad - L.charH, options.xLabel, s,
             kInk);
  if (!options.yLabel.empty())
    drawTextUp(img, pad, (L.plot.y0 + L.plot.y1) / 2, options.yLabel, s, kInk);
}

Result<void> checkSize(const PlotOptions& options) {
  const int W = options.width, H = options.height;
  if (W >= 100 && H >= 100 && W <= 8192 && H <= 8192) return {};
  std::string m = "plot size ";
  m += std::to_string(W) + "x" + std::to_string(H) + " is outside [100, 8192]";
  return makeError(m);
}

Image8 whiteImage(const PlotOptions& options) {
  Image8 img;
  img.width = options.width;
  img.height = options.height;
  img.rgba.assign(static_cast<size_t>(img.width) * img.height * 4, 255);
  return img;
}

// The bar chart's axes: one x unit per category (its name at the tick), the y range over the
// drawable values and 0 (a linear axis), with room above the highest bar for its value.
Result<Axes> barAxes(const std::vector<std::string>& categories,
                     const std::vector<BarSeries>& series, bool logY) {
  if (categories.empty()) return makeError("bar chart has no category");
  double yMin = INFINITY, yMax = -INFINITY;
  bool anyFinite = false;
  for (const BarSeries& s : series) {
    if (s.values.size() != categories.size()) {
      std::string m = "bar series '";
      m += s.label + "' has " + std::to_string(s.values.size()) + " values for " +
           std::to_string(categories.size()) + " categories";
      return makeError(m);
    }
    for (double v : s.values) {
      anyFinite = anyFinite || std::isfinite(v);
      if (!drawable(0.0, v, logY)) continue;
      const double y = logY ? std::log10(v) : v;
      yMin = std::min(yMin, y);
      yMax = std::max(yMax, y);
    }
  }
  if (!anyFinite) return makeError("plot has no finite data point");
  if (yMin > yMax) return makeError("log-scale plot has no positive y value");
  if (!std::isfinite(yMax - yMin)) return makeError("plot data range is too large");
  Axes axes;
  axes.x.lo = -0.5;
  axes.x.hi = static_cast<double>(categories.size()) - 0.5;
  for (size_t i = 0; i < categories.size(); ++i) {
    axes.x.ticks.push_back(static_cast<double>(i));
    axes.x.labels.push_back(categories[i]);
  }
  if (logY) {
    axes.y = logAxis(yMin, yMax + 0.15);
  } else {
    const double lo = std::min(0.0, yMin), hi = std::max(0.0, yMax);
    const double room = 0.08 * (hi - lo);  // for the values written above (below) the bars
    axes.y = linearAxis(lo < 0.0 ? lo - room : lo, hi + room);
  }
  return axes;
}

// a bar's value: whole numbers from 100 up, else three significant digits
std::string barLabel(double v) {
  const double a = std::fabs(v);
  return format("%.*f", v, a >= 100.0 ? 0 : a >= 10.0 ? 1 : a >= 1.0 ? 2 : 3);
}

// the bars, in groups of one bar per series around each category's tick, and their values
void drawBars(Image8& img, const Layout& L, const std::vector<BarSeries>& series) {
  const double group = 0.8, width = group / static_cast<double>(series.size());
  const double base = L.logY ? L.axes.y.lo : 0.0;
  const int yBase = static_cast<int>(std::lround(L.py(base)));
  const Rect inside{L.plot.x0 + 1, L.plot.y0 + 1, L.plot.x1 - 1, L.plot.y1 - 1};
  for (size_t j = 0; j < series.size(); ++j) {
    const BarSeries& se = series[j];
    const glm::vec3 c = glm::clamp(se.color, glm::vec3(0.0f), glm::vec3(1.0f));
    for (size_t i = 0; i < se.values.size(); ++i) {
      const double v = se.values[i];
      if (!drawable(0.0, v, L.logY)) continue;
      const double x0 = static_cast<double>(i) - group / 2 + static_cast<double>(j) * width;
      int px0 = static_cast<int>(std::lround(L.px(x0)));
      const int px1 = static_cast<int>(std::lround(L.px(x0 + width))) - 1;
      if (px1 - px0 >= 4) ++px0;  // a white column between neighbouring bars
      const int yTop = static_cast<int>(std::lround(L.py(L.logY ? std::log10(v) : v)));
      const Rect bar{std::max(px0, inside.x0), std::max(std::min(yTop, yBase), inside.y0),
                     std::min(px1, inside.x1), std::min(std::max(yTop, yBase), inside.y1)};
      fill(img, bar, c);
      const std::string text = barLabel(v);
      const int w = textWidth(text, L.s);
      if (w > px1 - px0 + 1 + 2 * L.gap) continue;  // no room for the value
      const int ty = v >= 0.0 ? bar.y0 - L.gap - L.charH : bar.y1 + L.gap;
      if (ty < inside.y0 || ty + L.charH > inside.y1) continue;
      drawText(img, (px0 + px1 + 1 - w) / 2, ty, text, L.s, kInk);
    }
  }
}

}  // namespace

Result<Image8> plotLines(const std::vector<PlotSeries>& series, const PlotOptions& options) {
  MFR_TRY(checkSize(options));
  auto axes = dataAxes(series, options.logY);
  if (!axes) return axes.error();
  auto layout = layOut(options, std::move(*axes));
  if (!layout) return layout.error();

  Image8 img = whiteImage(options);
  drawGrid(img, *layout);
  drawTickLabels(img, *layout);
  drawSeries(img, *layout, series);
  drawLegend(img, *layout, series);
  drawTitles(img, *layout, options);
  return img;
}

Result<Image8> plotBars(const std::vector<std::string>& categories,
                        const std::vector<BarSeries>& series, const PlotOptions& options) {
  MFR_TRY(checkSize(options));
  auto axes = barAxes(categories, series, options.logY);
  if (!axes) return axes.error();
  const bool labelled = std::any_of(series.begin(), series.end(),
                                    [](const BarSeries& b) { return !b.label.empty(); });
  auto layout = layOut(options, std::move(*axes), labelled);
  if (!layout) return layout.error();

  Image8 img = whiteImage(options);
  drawGrid(img, *layout, false);
  drawTickLabels(img, *layout);
  drawBars(img, *layout, series);
  if (labelled) drawLegendRow(img, *layout, series);
  drawTitles(img, *layout, options);
  return img;
}

}  // namespace mfr
