// The HTML report of `mfr compare`: one self-contained page (inline CSS, inline SVG plots, no
// scripts, no external resources) next to the images it shows.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "mfr/compare/compare.hpp"
#include "mfr/core/units.hpp"
#include "mfr/metrics/magma.hpp"

namespace mfr {
namespace {

std::string format(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* f, ...) {
  va_list args, copy;
  va_start(args, f);
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, f, copy);
  va_end(copy);
  std::string out(n > 0 ? static_cast<size_t>(n) : 0u, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, f, args);
  va_end(args);
  return out;
}

std::string escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// 1234567 -> "1 234 567" (thin spaces)
std::string grouped(uint64_t v) {
  const std::string digits = std::to_string(v);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += "&#8201;";
    out += digits[i];
  }
  return out;
}

// scientific notation as HTML: 1.23 × 10<sup>−4</sup>
std::string sci(double v, int digits = 3) {
  if (std::isnan(v)) return "n/a";
  if (std::isinf(v)) return "&infin;";
  if (v == 0.0) return "0";
  const int exponent = static_cast<int>(std::floor(std::log10(std::fabs(v))));
  if (exponent == 0) return format("%.*f", digits - 1, v);
  const double mantissa = v / std::pow(10.0, exponent);
  std::string s = format("%.*f", digits - 1, mantissa);
  s += "&#8201;&times;&#8201;10<sup>";
  if (exponent < 0) s += "&minus;";
  s += std::to_string(std::abs(exponent));
  s += "</sup>";
  return s;
}

std::string psnrText(double psnr) {
  return std::isfinite(psnr) ? format("%.2f", psnr) : std::string("&infin;");
}

std::string mib(uint64_t bytes) {
  return format("%.2f", static_cast<double>(bytes) / (1024.0 * 1024.0));
}

std::string budgetTitle(uint64_t bytes) {
  std::string s = escape(formatBytes(bytes));
  s += " (";
  s += grouped(bytes);
  s += "&#8201;B)";
  return s;
}

// a relative budget: its share, the node bytes it buys, and that each method adds its own words
std::string budgetTitle(const CompareBudget& cb) {
  if (!cb.percent) return budgetTitle(cb.budgetBytes);
  return escape(cb.label) + " of the A-buffer&rsquo;s node bytes = " + budgetTitle(cb.budgetBytes) +
         " of nodes + each method&rsquo;s per-pixel words";
}

// ---- SVG line plots --------------------------------------------------------------------------

struct Series {
  std::string name;
  std::string colour;
  int marker = 0;  // 0 circle, 1 square, 2 triangle, 3 diamond, 4 cross...
  std::vector<std::pair<double, double>> points;  // (x, y), x ascending
};

struct Axis {
  double lo = 0.0, hi = 1.0;
  bool log = false;
  double map(double v, double p0, double p1) const {
    const double a = log ? std::log10(lo) : lo, b = log ? std::log10(hi) : hi;
    const double t = ((log ? std::log10(v) : v) - a) / (b - a);
    return p0 + t * (p1 - p0);
  }
};

// "nice" linear ticks covering [lo, hi]
std::vector<double> niceTicks(double lo, double hi, int target) {
  const double span = hi - lo;
  const double raw = span / std::max(1, target);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * magnitude >= raw) {
      step = m * magnitude;
      break;
    }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + step * 1e-9; t += step)
    ticks.push_back(std::fabs(t) < step * 1e-9 ? 0.0 : t);
  return ticks;
}

std::string tickLabel(double v) {
  const double a = std::fabs(v);
  if (a < 1e-300) return "0";
  if (a >= 1e-3 && a < 1e5) return format("%g", v);
  const int e = static_cast<int>(std::floor(std::log10(a) + 1e-9));
  const double mantissa = std::round(v / std::pow(10.0, e) * 100.0) / 100.0;
  std::string s = mantissa == 1.0 ? std::string() : format("%g&#215;", mantissa);
  s += "10<tspan dy=\"-6\" font-size=\"9\">";
  if (e < 0) s += "&#8722;";
  s += std::to_string(std::abs(e));
  s += "</tspan>";
  return s;
}

std::string markerSvg(int marker, double x, double y, const std::string& colour) {
  const std::string fill =
      format(" fill=\"%s\" stroke=\"white\" stroke-width=\"1\"", colour.c_str());
  switch (marker % 5) {
    case 1:
      return format("<rect x=\"%.1f\" y=\"%.1f\" width=\"8\" height=\"8\"", x - 4, y - 4) + fill +
             "/>";
    case 2:
      return format("<polygon points=\"%.1f,%.1f %.1f,%.1f %.1f,%.1f\"", x, y - 5, x + 5, y + 4,
                    x - 5, y + 4) +
             fill + "/>";
    case 3:
      return format("<polygon points=\"%.1f,%.1f %.1f,%.1f %.1f,%.1f %.1f,%.1f\"", x, y - 5.5,
                    x + 5.5, y, x, y + 5.5, x - 5.5, y) +
             fill + "/>";
    case 4:
      return format("<path d=\"M%.1f %.1fl8 8m0 -8l-8 8\" stroke=\"%s\" stroke-width=\"2.5\"/>",
                    x - 4, y - 4, colour.c_str());
    default:
      return format("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4.5\"", x, y) + fill + "/>";
  }
}

/// A line plot of y vs budget (x in bytes, ticks at the budgets), one polyline per series; or of
/// y vs another x (`xName`) with the ticks given in `budgets`.
std::string svgPlot(const std::string& title, const std::string& yLabel, bool allowLogY,
                    bool zeroBased, const std::vector<Series>& series,
                    const std::vector<uint64_t>& budgets,
                    const std::vector<std::string>& budgetLabels,
                    const std::string& xName = "memory budget M") {
  size_t longest = 0;
  for (const Series& s : series)
    longest = std::max(longest, s.name.size() + (s.points.empty() ? 9 : 0));
  const double left = 62, plotWidth = 220, right = 46 + 6.3 * static_cast<double>(longest);
  const double W = std::ceil(left + plotWidth + right), H = 300, top = 34, bottom = 52;
  const double x0 = left, x1 = W - right, y0 = H - bottom, y1 = top;
  double ymin = INFINITY, ymax = -INFINITY;
  for (const Series& s : series)
    for (const auto& [x, y] : s.points) {
      ymin = std::min(ymin, y);
      ymax = std::max(ymax, y);
    }
  std::string svg = format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 %.0f %.0f\" width=\"%.0f\" "
      "height=\"%.0f\" role=\"img\" aria-label=\"%s\" font-family=\"inherit\" font-size=\"12\">",
      W, H, W, H, escape(title).c_str());
  svg += format(
      "<text x=\"%.1f\" y=\"20\" text-anchor=\"middle\" font-size=\"14\" "
      "font-weight=\"600\">%s</text>",
      (x0 + x1) / 2, escape(title).c_str());
  if (!std::isfinite(ymin)) {
    svg +=
        format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">no successful runs</text></svg>",
               (x0 + x1) / 2, (y0 + y1) / 2);
    return svg;
  }
  // axes
  Axis ax, ay;
  const double bmin = static_cast<double>(budgets.front()),
               bmax = static_cast<double>(budgets.back());
  ax.log = bmax / bmin >= 4.0;
  if (ax.log) {
    ax.lo = bmin / 1.15;
    ax.hi = bmax * 1.15;
  } else {
    const double pad = (bmax - bmin) * 0.08 + bmin * 0.02;
    ax.lo = std::max(0.0, bmin - pad);
    ax.hi = bmax + pad;
  }
  std::vector<double> yTicks;
  ay.log = allowLogY && ymin > 0.0 && ymax / ymin > 20.0;
  if (ay.log) {
    // a little margin around the data; ticks at 1, 2, 5 x 10^e (only decades when they are many)
    ay.lo = ymin / 1.5;
    ay.hi = ymax * 1.5;
    const int e0 = static_cast<int>(std::floor(std::log10(ay.lo)));
    const int e1 = static_cast<int>(std::ceil(std::log10(ay.hi)));
    const bool decadesOnly = e1 - e0 > 3;
    for (int e = e0; e <= e1; ++e)
      for (double m : {1.0, 2.0, 5.0}) {
        if (decadesOnly && m != 1.0) continue;
        const double t = m * std::pow(10.0, e);
        if (t >= ay.lo && t <= ay.hi) yTicks.push_back(t);
      }
  } else {
    const double span = std::max(ymax - ymin, std::fabs(ymax) * 0.05 + 1e-12);
    ay.lo = zeroBased ? std::min(0.0, ymin) : ymin - span * 0.15;
    ay.hi = ymax > ay.lo ? ymax + (ymax - ay.lo) * 0.08 : ay.lo + 1.0;
    yTicks = niceTicks(ay.lo, ay.hi, 5);
    if (!zeroBased) ay.lo = std::min(ay.lo, yTicks.front());
    ay.hi = std::max(ay.hi, yTicks.back());
  }
  // frame and grid; the frame carries the axes' ranges (data-*) so the plot can be read back
  svg += format(
      "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"#fcfcfc\" "
      "stroke=\"#333\" stroke-width=\"1\" data-x-scale=\"%s\" data-x-lo=\"%.17g\" "
      "data-x-hi=\"%.17g\" data-y-scale=\"%s\" data-y-lo=\"%.17g\" data-y-hi=\"%.17g\"/>",
      x0, y1, x1 - x0, y0 - y1, ax.log ? "log" : "linear", ax.lo, ax.hi, ay.log ? "log" : "linear",
      ay.lo, ay.hi);
  for (double t : yTicks) {
    const double y = ay.map(t, y0, y1);
    if (y < y1 - 0.5 || y > y0 + 0.5) continue;
    svg += format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e3e3e3\"/>", x0,
                  y, x1, y);
    svg += format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#333\"/>", x0 - 5,
                  y, x0, y);
    svg += format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">", x0 - 8, y + 4) +
           tickLabel(t) + "</text>";
  }
  double lastLabelX = -1e9;
  for (size_t i = 0; i < budgets.size(); ++i) {
    const double x = ax.map(static_cast<double>(budgets[i]), x0, x1);
    svg += format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e3e3e3\"/>", x,
                  y1, x, y0);
    svg += format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#333\"/>", x, y0,
                  x, y0 + 5);
    if (x - lastLabelX >= 44.0) {
      svg += format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s</text>", x, y0 + 19,
                    escape(budgetLabels[i]).c_str());
      lastLabelX = x;
    }
  }
  std::string xLabel = xName;
  if (ax.log) xLabel += " (log scale)";
  svg += format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s</text>", (x0 + x1) / 2,
                H - 12, escape(xLabel).c_str());
  std::string yText = yLabel;
  if (ay.log) yText += " (log scale)";
  svg +=
      format("<text transform=\"translate(18 %.1f) rotate(-90)\" text-anchor=\"middle\">%s</text>",
             (y0 + y1) / 2, escape(yText).c_str());
  // series; each point carries its exact values (data-x, data-y) next to its drawn position
  for (const Series& s : series) {
    svg += "<g class=\"series\" data-series=\"" + escape(s.name) + "\">";
    std::string path;
    for (const auto& [x, y] : s.points) {
      path += path.empty() ? "M" : " L";
      path += format("%.1f %.1f", ax.map(x, x0, x1), ay.map(y, y0, y1));
    }
    if (s.points.size() > 1)
      svg += format("<path d=\"%s\" fill=\"none\" stroke=\"%s\" stroke-width=\"2\"/>", path.c_str(),
                    s.colour.c_str());
    for (const auto& [x, y] : s.points)
      svg += format("<g class=\"point\" data-x=\"%.17g\" data-y=\"%.17g\">", x, y) +
             markerSvg(s.marker, ax.map(x, x0, x1), ay.map(y, y0, y1), s.colour) + "</g>";
    svg += "</g>";
  }
  // legend
  double ly = y1 + 8;
  for (const Series& s : series) {
    const double lx = x1 + 12;
    svg += format(
        "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" stroke-width=\"2\"/>",
        lx, ly, lx + 22, ly, s.colour.c_str());
    svg += markerSvg(s.marker, lx + 11, ly, s.colour);
    svg += format("<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\">%s</text>", lx + 28, ly + 4,
                  (escape(s.name) + (s.points.empty() ? " (failed)" : "")).c_str());
    ly += 20;
  }
  svg += "</svg>";
  return svg;
}

// Okabe & Ito's colour-blind safe palette (without yellow, which vanishes on white)
const char* kPalette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                          "#E69F00", "#56B4E9", "#000000", "#999999"};

std::string magmaGradient() {
  std::string g = "linear-gradient(to right";
  for (int i = 0; i <= 8; ++i) {
    const auto c = magma8(i * 255 / 8);
    g += format(", rgb(%d,%d,%d) %d%%", c[0], c[1], c[2], i * 100 / 8);
  }
  g += ")";
  return g;
}

std::string imageCell(const std::string& file, const Image8& image, const std::string& alt,
                      const std::string& caption) {
  if (file.empty()) return "<div class=\"cell empty\"></div>";
  std::string s = "<figure class=\"cell\"><a href=\"" + escape(file) + "\"><img src=\"" +
                  escape(file) + "\" width=\"" + std::to_string(image.width) + "\" height=\"" +
                  std::to_string(image.height) + "\" alt=\"" + escape(alt) + "\"></a>";
  if (!caption.empty()) s += "<figcaption>" + caption + "</figcaption>";
  s += "</figure>";
  return s;
}

const char* kCss = R"css(
:root { --ink: #1a1a1a; --muted: #5f6368; --rule: #c8c8c8; --accent: #0b5394; }
* { box-sizing: border-box; }
body { margin: 0; color: var(--ink); background: #fff;
  font: 15px/1.5 "Source Sans Pro", "Helvetica Neue", Helvetica, Arial, sans-serif; }
main { max-width: 1360px; margin: 0 auto; padding: 28px 32px 48px; }
h1 { font-size: 26px; margin: 0 0 4px; font-weight: 600; }
h2 { font-size: 20px; margin: 36px 0 10px; padding-bottom: 4px; border-bottom: 2px solid var(--ink); }
h3 { font-size: 16px; margin: 24px 0 8px; color: var(--accent); }
p { margin: 6px 0; }
.subtitle { color: var(--muted); font-size: 16px; margin-bottom: 18px; }
code, .mono { font-family: "DejaVu Sans Mono", Menlo, Consolas, monospace; font-size: 13px; }
pre.cmd { background: #f4f5f7; border: 1px solid #e0e0e0; border-radius: 4px; padding: 8px 10px;
  white-space: pre-wrap; word-break: break-all; margin: 0; }
table { border-collapse: collapse; font-variant-numeric: tabular-nums; }
table.meta th { text-align: left; font-weight: 600; padding: 3px 18px 3px 0; vertical-align: top;
  white-space: nowrap; }
table.meta td { padding: 3px 0; }
table.results { width: 100%; font-size: 13.5px; border-top: 2px solid var(--ink);
  border-bottom: 2px solid var(--ink); margin: 6px 0 4px; }
table.results th { font-weight: 600; padding: 6px 8px; border-bottom: 1px solid var(--ink);
  text-align: right; vertical-align: bottom; line-height: 1.25; }
table.results th .unit { display: block; font-weight: 400; color: var(--muted); font-size: 12px; }
table.results td { padding: 4px 8px; text-align: right; white-space: nowrap;
  border-bottom: 1px solid #eee; }
table.results th:first-child, table.results td:first-child { text-align: left; }
table.results tr.gt td { background: #f6f8fb; font-style: italic; }
table.results td.err { text-align: left; color: #b00020; white-space: normal; }
table.results td.passes { text-align: left; white-space: normal; color: var(--muted); font-size: 12px;
  min-width: 220px; }
table.results .best { font-weight: 700; }
.caption { color: var(--muted); font-size: 13px; margin: 4px 0 12px; }
.plots { display: flex; flex-wrap: wrap; gap: 18px; }
.plots figure { margin: 0; }
.plots figcaption { color: var(--muted); font-size: 13px; max-width: 420px; }
.grid { display: grid; gap: 10px 10px; align-items: start; margin: 8px 0 18px; }
.grid .head { font-weight: 600; text-align: center; font-size: 14px; align-self: end; }
.grid .head small { display: block; font-weight: 400; color: var(--muted); }
.grid .rowlabel { writing-mode: vertical-rl; transform: rotate(180deg); text-align: center;
  font-size: 13px; color: var(--muted); align-self: center; }
.cell { margin: 0; }
.cell img { width: 100%; height: auto; display: block; border: 1px solid #ddd;
  image-rendering: auto; background: #fff; }
.cell figcaption { font-size: 12px; color: var(--muted); text-align: center; margin-top: 2px; }
.cell.empty { min-height: 20px; }
.cell.failed { border: 1px dashed #b00020; color: #b00020; font-size: 12px; padding: 8px;
  aspect-ratio: 1 / 1; display: flex; align-items: center; justify-content: center;
  text-align: center; }
.colorbar { height: 10px; border: 1px solid #999; margin: 2px 0 0; }
.colorbar-labels { display: flex; justify-content: space-between; font-size: 11px;
  color: var(--muted); }
.notes { font-size: 13.5px; color: #333; }
.notes dt { font-weight: 600; margin-top: 8px; }
.notes dd { margin: 0 0 0 18px; }
footer { margin-top: 40px; padding-top: 8px; border-top: 1px solid var(--rule); color: var(--muted);
  font-size: 12.5px; }
@media print { main { max-width: none; padding: 0; } h2 { break-after: avoid; } .grid { break-inside: avoid; } }
)css";

struct Best {
  double flip = INFINITY, mse = INFINITY, psnr = -INFINITY;
};

std::string resultsTable(const CompareResult& r, const CompareBudget& cb) {
  Best best;
  for (const CompareRun& run : cb.runs) {
    if (!run.ok()) continue;
    best.flip = std::min(best.flip, run.metrics.flipMean);
    best.mse = std::min(best.mse, run.metrics.mseLinear);
    best.psnr = std::max(best.psnr, run.metrics.psnrSrgb);
  }
  const auto cls = [](bool isBest) {
    return isBest ? std::string(" class=\"best\"") : std::string();
  };
  std::string t =
      "<table class=\"results\"><thead><tr>"
      "<th>Method</th>"
      "<th>Memory used<span class=\"unit\">MiB</span></th>"
      "<th>F(M)<span class=\"unit\">node slots</span></th>"
      "<th>Utilisation<span class=\"unit\">captured / F(M), %</span></th>"
      "<th>k(p)<span class=\"unit\">min&ndash;max</span></th>"
      "<th>Captured<span class=\"unit\">fragments</span></th>"
      "<th>Lost<span class=\"unit\">%</span></th>"
      "<th>MSE<span class=\"unit\">linear</span></th>"
      "<th>PSNR<span class=\"unit\">linear, dB</span></th>"
      "<th>MSE<span class=\"unit\">sRGB</span></th>"
      "<th>PSNR<span class=\"unit\">sRGB, dB</span></th>"
      "<th>FLIP<span class=\"unit\">mean</span></th>"
      "<th>Time<span class=\"unit\">total, ms</span></th>"
      "<th>Passes<span class=\"unit\">ms</span></th>"
      "</tr></thead><tbody>";
  const auto passes = [](const RenderStats& s) {
    std::string p;
    for (const PassTime& pt : s.passes) {
      if (!p.empty()) p += " &middot; ";
      p += escape(pt.name) + "&nbsp;" + format("%.1f", pt.ms);
    }
    return p;
  };
  // ground-truth row
  {
    const CompareRun& gt = r.groundTruth;
    const RenderStats& s = gt.stats;
    t += "<tr class=\"gt\"><td>abuffer (ground truth)</td><td>" + mib(s.bytesUsed) +
         "</td><td>&mdash;</td><td>" + format("%.1f", 100.0 * gt.memoryUtilisation()) +
         "</td><td>" + format("%u&ndash;%u", s.kMin, s.kMax) + "</td><td>" + grouped(s.captured) +
         "</td><td>" + format("%.2f", s.lostPercent()) +
         "</td><td>0</td><td>&infin;</td><td>0</td><td>&infin;</td><td>0</td><td>" +
         format("%.1f", s.totalMs()) + "</td><td class=\"passes\">" + passes(s) + "</td></tr>";
  }
  for (const CompareRun& run : cb.runs) {
    t += "<tr><td>" + escape(run.label) + "<small> " + toString(run.compositing) + "</small>";
    if (run.ok() && run.stats.oracle) {
      const OracleReport& o = *run.stats.oracle;
      t += o.exact ? std::string("<small>oracle: proven minimum</small>")
                   : "<small>oracle: error &le; lower bound " + sci(o.lowerBound) + " + gap " +
                         sci(o.gap()) + "</small>";
    }
    t += "</td>";
    if (!run.ok()) {
      t += "<td class=\"err\" colspan=\"13\">failed: " + escape(*run.error) + "</td></tr>";
      continue;
    }
    const RenderStats& s = run.stats;
    const CompareMetrics& m = run.metrics;
    t += "<td>" + mib(s.bytesUsed) + "</td>";
    t += "<td>" + grouped(run.budgetSlots) + "</td>";
    t += "<td>" + format("%.1f", 100.0 * run.memoryUtilisation()) + "</td>";
    t += "<td>" + format("%u&ndash;%u", s.kMin, s.kMax) + "</td>";
    t += "<td>" + grouped(s.captured) + "</td>";
    t += "<td>" + format("%.2f", s.lostPercent()) + "</td>";
    t += "<td" + cls(m.mseLinear == best.mse) + ">" + sci(m.mseLinear) + "</td>";
    t += "<td" + cls(m.mseLinear == best.mse) + ">" + psnrText(m.psnrLinear) + "</td>";
    t += "<td" + cls(m.psnrSrgb == best.psnr) + ">" + sci(m.mseSrgb) + "</td>";
    t += "<td" + cls(m.psnrSrgb == best.psnr) + ">" + psnrText(m.psnrSrgb) + "</td>";
    t += "<td" + cls(m.flipMean == best.flip) + ">" + format("%.4f", m.flipMean) + "</td>";
    t += "<td>" + format("%.1f", s.totalMs()) + "</td>";
    t += "<td class=\"passes\">" + passes(s) + "</td></tr>";
  }
  t += "</tbody></table>";
  return t;
}

std::string imageGrid(const CompareResult& r, const CompareBudget& cb) {
  const CompareRun& gt = r.groundTruth;
  bool anyImportance = false;
  for (const CompareRun& run : cb.runs) anyImportance |= !run.importanceFile.empty();
  const size_t columns = 1 + cb.runs.size();
  std::string g = format(
      "<div class=\"grid\" style=\"grid-template-columns: 22px repeat(%zu, minmax(0, 1fr));\">",
      columns);
  // header
  g += "<div></div><div class=\"head\">ground truth<small>abuffer, exact</small></div>";
  for (const CompareRun& run : cb.runs) {
    g += "<div class=\"head\">" + escape(run.label);
    if (run.ok())
      g += "<small>" +
           format("FLIP %.4f &middot; PSNR %s dB", run.metrics.flipMean,
                  psnrText(run.metrics.psnrSrgb).c_str()) +
           "</small>";
    else
      g += "<small>failed</small>";
    g += "</div>";
  }
  // images
  g += "<div class=\"rowlabel\">image (sRGB)</div>";
  g += imageCell(gt.imageFile, gt.image, "ground truth (abuffer)", "");
  for (const CompareRun& run : cb.runs) {
    if (!run.ok()) {
      g += "<div class=\"cell failed\">" + escape(*run.error) + "</div>";
      continue;
    }
    g += imageCell(run.imageFile, run.image, run.label + " at " + cb.label, "");
  }
  // FLIP maps
  g += "<div class=\"rowlabel\">FLIP error</div>";
  g += "<div class=\"cell\"><div class=\"colorbar\" style=\"background: " + magmaGradient() +
       "\"></div><div class=\"colorbar-labels\"><span>0</span><span>FLIP error</span>"
       "<span>1</span></div></div>";
  for (const CompareRun& run : cb.runs)
    g += run.ok() ? imageCell(run.flipFile, run.flipMap, "FLIP error map of " + run.method,
                              format("mean %.4f", run.metrics.flipMean))
                  : std::string("<div class=\"cell empty\"></div>");
  // k-maps (the ground truth: its depth complexity, which is its k(p))
  g += "<div class=\"rowlabel\">k(p) / n(p)</div>";
  g += imageCell(r.depthComplexityFile, r.depthComplexityMap, "depth complexity n(p)",
                 gt.stats.maxDepthComplexity ? format("n(p), max %u", *gt.stats.maxDepthComplexity)
                                             : std::string("n(p)"));
  for (const CompareRun& run : cb.runs)
    g += run.ok() ? imageCell(run.kMapFile, run.kMap, "k(p) of " + run.method,
                              format("k %u&ndash;%u", run.stats.kMin, run.stats.kMax))
                  : std::string("<div class=\"cell empty\"></div>");
  if (anyImportance) {
    g += "<div class=\"rowlabel\">importance I(p)</div><div class=\"cell empty\"></div>";
    for (const CompareRun& run : cb.runs)
      g += run.ok() && !run.importanceFile.empty()
               ? imageCell(run.importanceFile, run.importanceMap, "importance map of " + run.method,
                           "I(p), Eqs. 3&ndash;6")
               : std::string("<div class=\"cell empty\"></div>");
  }
  g += "</div>";
  return g;
}

// the method names, in the order of the first budget's runs
std::vector<std::string> methodNamesOf(const CompareResult& r) {
  std::vector<std::string> methodNames;
  if (!r.budgets.empty())
    for (const CompareRun& run : r.budgets[0].runs) methodNames.push_back(run.label);
  return methodNames;
}

// the document head and the page title with its subtitle
std::string reportHead(const CompareResult& r, const std::string& size) {
  std::string budgetsText;
  for (const CompareBudget& cb : r.budgets) {
    if (!budgetsText.empty()) budgetsText += ", ";
    budgetsText += cb.percent ? escape(cb.label) : escape(formatBytes(cb.budgetBytes));
  }
  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  h += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  h += "<link rel=\"icon\" href=\"data:,\">\n";
  h += "<title>mfr compare &mdash; " + escape(r.scene) + ", " + size + "</title>\n";
  h += "<style>" + std::string(kCss) + "</style>\n</head>\n<body>\n<main>\n";

  h += "<h1>Multi-fragment rendering under a memory budget</h1>\n";
  h += "<p class=\"subtitle\">Scene <code>" + escape(r.scene) + "</code> &middot; " + size +
       " pixels &middot; budget" + (r.budgets.size() > 1 ? "s " : " ") + budgetsText +
       " &middot; " +
       (r.rules.size() == 1 ? escape(toString(r.rules[0])) + " compositing"
        : r.rules.empty()   ? std::string("each method's own compositing")
                            : std::string("kbuffer and hybrid compositing")) +
       "</p>\n";
  return h;
}

// 1 Set-up: the scene, the budgets, the methods, the ground truth and the command
std::string setupSection(const CompareResult& r, const ReportInfo& info,
                         const std::vector<std::string>& methodNames, const std::string& size) {
  const RenderStats& gs = r.groundTruth.stats;
  std::string methodsText;
  for (const std::string& m : methodNames) {
    if (!methodsText.empty()) methodsText += ", ";
    methodsText += "<code>" + escape(m) + "</code>";
  }
  std::string h;
  h += "<h2 id=\"setup\">1&ensp;Set-up</h2>\n<table class=\"meta\">\n";
  h += "<tr><th>Scene</th><td><code>" + escape(r.scene) + "</code></td></tr>\n";
  h += "<tr><th>Image</th><td>" + size + " = " +
       grouped(static_cast<uint64_t>(r.width) * static_cast<uint64_t>(r.height)) +
       " pixels</td></tr>\n";
  h += "<tr><th>Memory budgets M</th><td>";
  for (size_t i = 0; i < r.budgets.size(); ++i) {
    if (i) h += "; ";
    h += budgetTitle(r.budgets[i]);
  }
  h += " &mdash; binary units, 1&#8201;MiB = 2<sup>20</sup>&#8201;B</td></tr>\n";
  h += "<tr><th>Methods</th><td>" + methodsText + "</td></tr>\n";
  const char* kHybridText =
      " (sorted core + order-independent tail, 20&#8201;B/pixel of tail accumulators)";
  const char* kKBufferText =
      " (captured fragments sorted and blended front to back; the rest dropped)";
  h += "<tr><th>Compositing</th><td>" +
       (r.rules.size() == 1 ? escape(toString(r.rules[0])) +
                                  (r.rules[0] == Compositing::Hybrid ? kHybridText : kKBufferText)
        : r.rules.empty()
            ? std::string("each preset's own rule: hybrid") + kHybridText +
                  " for dkb* and optimal*, kbuffer" + kKBufferText +
                  " for the others (per run in the tables)"
            : std::string("every method that takes a rule under both, each row labelled with "
                          "its rule: kbuffer") +
                  kKBufferText + "; hybrid" + kHybridText +
                  "; the oracle (optimal) under each, so it is the proven minimum of the rule "
                  "beside it") +
       "</td></tr>\n";
  h += "<tr><th>Capture</th><td>" +
       std::string(r.capture == CaptureMode::TileOwned
                       ? "tile-owned (lock-free)"
                       : "fragment-parallel (per-pixel spin-locks)") +
       "</td></tr>\n";
  h += "<tr><th>Back faces</th><td><code>--cull " + std::string(toString(gs.cull)) + "</code>" +
       (gs.cull == CullMode::Auto
            ? " (culled where the file says so: glTF materials with doubleSided false)"
        : gs.cull == CullMode::Back ? " (every back face culled)"
                                    : " (none culled)") +
       "</td></tr>\n";
  h += "<tr><th>Ground truth</th><td>exact A-buffer: " + grouped(gs.fragmentsGenerated) +
       " fragments over " + grouped(gs.coveredPixels) + " covered pixels";
  if (gs.maxDepthComplexity)
    h += format(", depth complexity max %u, mean %.2f", *gs.maxDepthComplexity,
                gs.meanDepthComplexity.value_or(0.0));
  h += ", " + escape(formatBytes(gs.bytesUsed)) + format(", %.1f&#8201;ms", gs.totalMs()) +
       "</td></tr>\n";
  h += "<tr><th>Software</th><td>" + escape(info.mfrVersion.empty() ? "mfr" : info.mfrVersion) +
       " (CPU reference engine)</td></tr>\n";
  if (!info.generated.empty())
    h += "<tr><th>Generated</th><td>" + escape(info.generated) + "</td></tr>\n";
  h += "<tr><th>Command</th><td><pre class=\"cmd\">" + escape(info.commandLine) +
       "</pre></td></tr>\n";
  h += "<tr><th>Data</th><td><a href=\"results.json\">results.json</a> &middot; "
       "<a href=\"results.csv\">results.csv</a></td></tr>\n";
  h += "</table>\n";
  return h;
}

// 2 Results: one table per budget
std::string resultsSection(const CompareResult& r) {
  std::string h;
  h += "<h2 id=\"results\">2&ensp;Results</h2>\n";
  h += "<p class=\"caption\">Error of each method against the ground truth (lower MSE and FLIP, "
       "higher PSNR are better; the best value of each budget is in bold). MSE and PSNR are over "
       "R, G, B of the 8-bit images as written, on decoded linear-light values (<em>linear</em>) "
       "or on the sRGB code values / 255 (<em>sRGB</em>); PSNR has peak 1. FLIP is the mean "
       "LDR-FLIP error" +
       format(" at %.1f pixels per degree. ", r.flipPixelsPerDegree) +
       "F(M) = &lfloor;(M &minus; |P|&middot;S<sub>p</sub> &minus; S<sub>i</sub>) / 8&rfloor; is "
       "the number of 8-byte fragment nodes the budget buys after the method's per-pixel "
       "(S<sub>p</sub>) "
       "and per-image (S<sub>i</sub>) overhead; utilisation is captured fragments / F(M). Times "
       "are wall-clock milliseconds of the CPU engine.</p>\n";
  for (const CompareBudget& cb : r.budgets) {
    h += "<h3>M = " + budgetTitle(cb) + "</h3>\n";
    h += resultsTable(r, cb) + "\n";
  }
  return h;
}

// ticks of a bytes-per-pixel axis from lo to hi: the data's range (whole bytes) and nice values
// between
void bytesPerPixelTicks(double lo, double hi, std::vector<uint64_t>& ticks,
                        std::vector<std::string>& tickLabels) {
  const double a = std::max(1.0, std::floor(lo)), b = std::max(std::ceil(hi), a + 1.0);
  ticks.push_back(static_cast<uint64_t>(a));
  tickLabels.push_back(format("%g B", a));
  for (double t : niceTicks(a, b, 4))
    if (t > a + 0.5 && t < b - 0.5) {
      ticks.push_back(static_cast<uint64_t>(std::llround(t)));
      tickLabels.push_back(format("%g B", std::round(t)));
    }
  ticks.push_back(static_cast<uint64_t>(b));
  tickLabels.push_back(format("%g B", b));
}

// every method's error against the bytes per pixel it was charged (bytes_used / pixels):
// methods that do not spend the whole budget (wboit, mboit, vkb) sit where they really are; byBytes
// holds the mean FLIP over the budgets in `order`. Empty when no run succeeded.
std::string bytesPerPixelFigure(const CompareResult& r, const std::vector<size_t>& order,
                                std::vector<Series> byBytes) {
  std::string h;
  const double pixels = static_cast<double>(r.width) * static_cast<double>(r.height);
  double lo = INFINITY, hi = 0.0;
  for (size_t m = 0; m < byBytes.size(); ++m) {
    size_t j = 0;
    for (size_t i : order) {
      const CompareRun& run = r.budgets[i].runs[m];
      if (!run.ok()) continue;
      const double bpp = static_cast<double>(run.stats.bytesUsed) / pixels;
      byBytes[m].points[j++].first = bpp;
      lo = std::min(lo, bpp);
      hi = std::max(hi, bpp);
    }
    std::sort(byBytes[m].points.begin(), byBytes[m].points.end());
  }
  if (std::isfinite(lo)) {
    std::vector<uint64_t> ticks;
    std::vector<std::string> tickLabels;
    bytesPerPixelTicks(lo, hi, ticks, tickLabels);
    h += "<figure>" +
         svgPlot("Mean FLIP vs bytes per pixel", "mean FLIP", false, true, byBytes, ticks,
                 tickLabels, "bytes per pixel charged (bytes_used / pixels)") +
         "<figcaption>Every method's error against the memory it was charged per pixel, "
         "across all budgets: which method buys the most quality per byte.</figcaption>"
         "</figure>\n";
  }
  return h;
}

// --sample-counts: each method's error against the bytes per pixel it was charged, one series per
// method and sample count (colour: the method, marker: the count), each count against its own
// ground truth. Empty without sample counts or successful runs.
std::string sampleCountsFigure(const CompareResult& r,
                               const std::vector<std::string>& methodNames) {
  if (r.sampleCounts.empty()) return {};
  const double pixels = static_cast<double>(r.width) * static_cast<double>(r.height);
  std::vector<Series> series;
  double lo = INFINITY, hi = 0.0;
  for (size_t m = 0; m < methodNames.size(); ++m)
    for (size_t c = 0; c < r.sampleCounts.size(); ++c) {
      const SampleCountRuns& sc = r.sampleCounts[c];
      Series s;
      s.name = methodNames[m] + format(", %d sample%s", sc.samples, sc.samples == 1 ? "" : "s");
      s.colour = kPalette[m % (sizeof kPalette / sizeof kPalette[0])];
      s.marker = static_cast<int>(c);
      for (const CompareBudget& cb : sc.budgets) {
        if (m >= cb.runs.size() || !cb.runs[m].ok()) continue;
        const double bpp = static_cast<double>(cb.runs[m].stats.bytesUsed) / pixels;
        s.points.emplace_back(bpp, cb.runs[m].metrics.flipMean);
        lo = std::min(lo, bpp);
        hi = std::max(hi, bpp);
      }
      std::sort(s.points.begin(), s.points.end());
      series.push_back(std::move(s));
    }
  if (!std::isfinite(lo)) return {};
  std::vector<uint64_t> ticks;
  std::vector<std::string> tickLabels;
  bytesPerPixelTicks(lo, hi, ticks, tickLabels);
  std::string counts;
  for (const SampleCountRuns& sc : r.sampleCounts)
    counts += (counts.empty() ? "" : ", ") + std::to_string(sc.samples);
  return "<figure>" +
         svgPlot("Mean FLIP vs bytes per pixel at " + counts + " samples", "mean FLIP", false, true,
                 series, ticks, tickLabels, "bytes per pixel charged (bytes_used / pixels)") +
         "<figcaption>Each method at each sample count (--sample-counts; marker: the count), "
         "against that count's own ground truth (the per-sample A-buffer, box-filtered), with " +
         escape(toString(r.sampleStorage)) +
         " storage: what antialiasing costs each method in memory.</figcaption></figure>\n";
}

// 3 Error vs memory budget: the plots over the budgets, smallest first (two budgets or more)
std::string budgetPlots(const CompareResult& r, const std::vector<std::string>& methodNames,
                        int section) {
  std::string h;
  std::vector<uint64_t> budgets;
  std::vector<std::string> labels;
  std::vector<size_t> order(r.budgets.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return r.budgets[a].budgetBytes < r.budgets[b].budgetBytes;
  });
  for (size_t i : order) {
    budgets.push_back(r.budgets[i].budgetBytes);
    labels.push_back(r.budgets[i].label);
  }
  const auto seriesOf = [&](auto value) {
    std::vector<Series> out;
    for (size_t m = 0; m < methodNames.size(); ++m) {
      Series s;
      s.name = methodNames[m];
      s.colour = kPalette[m % (sizeof kPalette / sizeof kPalette[0])];
      s.marker = static_cast<int>(m);
      for (size_t i : order) {
        const CompareRun& run = r.budgets[i].runs[m];
        if (run.ok())
          s.points.emplace_back(static_cast<double>(r.budgets[i].budgetBytes), value(run));
      }
      out.push_back(std::move(s));
    }
    return out;
  };
  h += format("<h2 id=\"plots\">%d&ensp;Error vs memory budget</h2>\n", section);
  h += "<div class=\"plots\">\n<figure>" +
       svgPlot("Mean FLIP vs budget", "mean FLIP", false, true,
               seriesOf([](const CompareRun& run) { return run.metrics.flipMean; }), budgets,
               labels) +
       "<figcaption>Mean LDR-FLIP error against the exact A-buffer (lower is better). "
       "Missing points: the method failed at that budget.</figcaption></figure>\n";
  h += "<figure>" +
       svgPlot("MSE (linear) vs budget", "MSE, linear", true, true,
               seriesOf([](const CompareRun& run) { return run.metrics.mseLinear; }), budgets,
               labels) +
       "<figcaption>Mean squared error on linear-light values (lower is better).</figcaption>"
       "</figure>\n";
  h += "<figure>" +
       svgPlot("Fragments lost vs budget", "fragments lost, %", false, false,
               seriesOf([](const CompareRun& run) { return run.stats.lostPercent(); }), budgets,
               labels) +
       "<figcaption>Share of the generated fragments not in the final per-pixel "
       "cores.</figcaption>"
       "</figure>\n";
  h += bytesPerPixelFigure(r, order,
                           seriesOf([](const CompareRun& run) { return run.metrics.flipMean; }));
  h += "</div>\n";
  return h;
}

// Images: per budget, the image, FLIP, k(p) and importance grid
std::string imagesSection(const CompareResult& r, int section) {
  std::string h;
  h += format("<h2 id=\"images\">%d&ensp;Images</h2>\n", section);
  h += format(
      "<p class=\"caption\">Columns: the ground truth, then each method. Rows: the image "
      "(sRGB), the FLIP error map (magma, 0&ndash;1), the slots per pixel k(p) (viridis, "
      "one scale 0&ndash;%g shared by all runs; the ground-truth column shows its depth "
      "complexity n(p), on its own scale)",
      static_cast<double>(r.kMapScale));
  h += ", and for the variable k-buffer its importance map I(p). Click an image for full "
       "size.</p>\n";
  for (const CompareBudget& cb : r.budgets) {
    h += "<h3>M = " + budgetTitle(cb) + "</h3>\n";
    h += imageGrid(r, cb) + "\n";
  }
  return h;
}

// the legend of the methods in this run, from the preset table (method.hpp)
std::string methodLegend(const CompareResult& r) {
  std::string h;
  std::vector<std::string> listed;
  auto describe = [&](const std::string& method) {
    const size_t plus = method.find("+occupancy");
    const std::string base = plus == std::string::npos ? method : method.substr(0, plus);
    if (std::find(listed.begin(), listed.end(), base) != listed.end()) return;
    listed.push_back(base);
    for (const PresetInfo& p : presetTable())
      if (p.name == base)
        h += "<dt><code>" + escape(p.name) + "</code></dt><dd>" + escape(p.summary) + " (" +
             escape(p.paper) + ")</dd>";
  };
  describe(r.groundTruth.method);
  for (const CompareBudget& cb : r.budgets)
    for (const CompareRun& run : cb.runs) describe(run.method);
  return h;
}

// Notes: memory, fragments and the methods' legend
std::string notesSection(const CompareResult& r, int section) {
  std::string h;
  h += format("<h2 id=\"notes\">%d&ensp;Notes</h2>\n<dl class=\"notes\">\n", section);
  h += "<dt>Memory</dt><dd>Every store holds 8-byte fragment nodes (float32 depth + RGBA8) plus "
       "the method's per-pixel words over all pixels (counter 4&#8201;B; offset 4&#8201;B for "
       "count-pass methods; lock 4&#8201;B for the k<sup>+</sup>-buffer family; hybrid tail "
       "20&#8201;B; occupancy 12&#8201;+&#8201;4d&#8201;B; previous-frame |n&middot;v| 1&#8201;B "
       "for vkb) and image-level data (dynamic-k histogram, 4&#8201;KiB). Memory used never "
       "exceeds M.</dd>\n";
  h += "<dt>Fragments</dt><dd>Captured: fragments in the final per-pixel cores. Lost: generated "
       "minus captured (with hybrid compositing they still contribute to the order-independent "
       "tail).</dd>\n";
  h += "<dt>Methods</dt><dd><dl class=\"legend\">";
  h += methodLegend(r);
  h += "</dl><code>+occupancy</code> adds occupancy-map culling (Vasilakis &amp; Papaioannou). "
       "Each run names the compositing rule it used.</dd>\n";
  h += "</dl>\n";
  return h;
}

}  // namespace

std::string compareReportHtml(const CompareResult& r, const ReportInfo& info) {
  const std::vector<std::string> methodNames = methodNamesOf(r);
  const std::string size = format("%d&#8201;&times;&#8201;%d", r.width, r.height);
  std::string h;
  h.reserve(1 << 16);
  h += reportHead(r, size);
  h += setupSection(r, info, methodNames, size);
  h += resultsSection(r);
  int section = 3;
  if (r.budgets.size() > 1) h += budgetPlots(r, methodNames, section++);
  if (!r.sampleCounts.empty()) {
    h += format("<h2 id=\"samples\">%d&ensp;Error vs bytes per pixel per sample count</h2>\n",
                section++);
    h += "<div class=\"plots\">\n" + sampleCountsFigure(r, methodNames) + "</div>\n";
  }
  h += imagesSection(r, section++);
  h += notesSection(r, section);
  h += "<footer>Generated by " + escape(info.mfrVersion.empty() ? "mfr" : info.mfrVersion) +
       " <code>compare</code>. All images are files next to this page.</footer>\n";
  h += "</main>\n</body>\n</html>\n";
  return h;
}

}  // namespace mfr
