// Shared pieces of the comparison reports (report_common.hpp).
#include "report_common.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "mfr/compare/report_ranking.hpp"

namespace mfr::report {

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

std::string grouped(uint64_t v) {
  const std::string digits = std::to_string(v);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += "&#8201;";
    out += digits[i];
  }
  return out;
}

std::string sci(double v, int digits) {
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

const char* paletteColour(size_t i) {
  static const char* kPalette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                   "#E69F00", "#56B4E9", "#000000", "#999999"};
  return kPalette[i % (sizeof kPalette / sizeof kPalette[0])];
}

namespace {

const char* kCss = R"css(
:root { --ink: #1a1a1a; --muted: #5f6368; --rule: #c8c8c8; --accent: #0b5394; --win: #e8f3ea; }
* { box-sizing: border-box; }
body { margin: 0; color: var(--ink); background: #fff;
  font: 15px/1.5 "Source Sans Pro", "Helvetica Neue", Helvetica, Arial, sans-serif; }
main { max-width: 1480px; margin: 0 auto; padding: 28px 32px 48px; }
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
table.results tr.winner td { background: var(--win); }
table.results td.err { text-align: left; color: #b00020; white-space: normal; }
table.results td.passes { text-align: left; white-space: normal; color: var(--muted); font-size: 12px;
  min-width: 220px; }
table.results td.note { text-align: left; white-space: normal; color: var(--muted); font-size: 12.5px; }
table.results .best { font-weight: 700; }
table.ranking { width: auto; min-width: 760px; max-width: 1100px; }
table.ranking th:nth-child(2), table.ranking td:nth-child(2) { text-align: left; }
table[data-sortable] th { cursor: pointer; user-select: none; }
table[data-sortable] th:hover { background: #f1f4f8; }
table[data-sortable] th::after { content: " \2195"; color: #bbb; font-weight: 400; }
table[data-sortable] th[aria-sort="ascending"]::after { content: " \25B2"; color: var(--accent); }
table[data-sortable] th[aria-sort="descending"]::after { content: " \25BC"; color: var(--accent); }
.caption { color: var(--muted); font-size: 13px; margin: 4px 0 12px; }
.verdict { font-size: 16px; margin: 6px 0 4px; }
.verdict strong { color: #0a6b2d; }
ul.verdicts { margin: 6px 0 12px; padding-left: 20px; }
ul.verdicts li { margin: 3px 0; }
.fixed-note { border-left: 4px solid #E69F00; background: #fff8e6; padding: 8px 12px; margin: 12px 0;
  font-size: 14px; }
.tag { display: inline-block; font-size: 11px; padding: 0 5px; border-radius: 3px; margin-left: 4px;
  background: #eef1f5; color: var(--muted); font-style: normal; vertical-align: 1px; }
.tag.front { background: #e3ecf7; color: var(--accent); }
.tag.win { background: #d7eedc; color: #0a6b2d; }
.tag.fixed { background: #fdf0d5; color: #8a5a00; }
.plots { display: flex; flex-wrap: wrap; gap: 22px; }
.plots figure { margin: 0; }
.plots figcaption { color: var(--muted); font-size: 13px; max-width: 560px; }
.scroll { overflow-x: auto; }
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
.wiper { margin: 10px 0 20px; max-width: 100%; }
.wiper .controls .caption { margin: 0; }
.wiper .controls { display: flex; gap: 14px; align-items: center; font-size: 14px; margin-bottom: 6px; }
.wiper .stage { position: relative; width: 100%; border: 1px solid #ccc; background: #fff; }
.wiper .stage img { position: absolute; left: 0; top: 0; width: 100%; height: 100%;
  image-rendering: pixelated; }
.wiper .handle { position: absolute; top: 0; bottom: 0; width: 2px; margin-left: -1px;
  background: #fff; box-shadow: 0 0 0 1px rgba(0,0,0,.6); pointer-events: none; }
.wiper .side { position: absolute; top: 6px; font-size: 12px; background: rgba(0,0,0,.6); color: #fff;
  padding: 1px 6px; border-radius: 3px; pointer-events: none; }
.wiper .side.left { left: 6px; } .wiper .side.right { right: 6px; }
.wiper input[type=range] { width: 100%; margin: 6px 0 0; }
.crops { display: flex; flex-wrap: wrap; gap: 18px 28px; margin: 8px 0 18px; }
.cropset { margin: 0; }
.cropset .row { display: flex; gap: 6px; }
.cropset .title { font-weight: 600; font-size: 14px; }
.cropset figcaption { font-size: 12px; color: var(--muted); max-width: 600px; }
.crop { position: relative; overflow: hidden; border: 1px solid #bbb; background: #fff; }
.crop img { position: absolute; max-width: none; image-rendering: pixelated; }
.crop .label { position: absolute; left: 3px; bottom: 3px; font-size: 11px; background: rgba(0,0,0,.6);
  color: #fff; padding: 0 4px; border-radius: 2px; }
.frames td { vertical-align: top; text-align: center; padding: 4px; }
.frames img { display: block; image-rendering: pixelated; border: 1px solid #ddd; }
.notes { font-size: 13.5px; color: #333; }
.notes dt { font-weight: 600; margin-top: 8px; }
.notes dd { margin: 0 0 0 18px; }
footer { margin-top: 40px; padding-top: 8px; border-top: 1px solid var(--rule); color: var(--muted);
  font-size: 12.5px; }
@media print { main { max-width: none; padding: 0; } h2 { break-after: avoid; } .grid { break-inside: avoid; } }
)css";

// Sortable tables (click a header: ascending, again: descending; rows of class "pinned" stay on
// top and "failed" rows at the bottom) and image wipers (a range input clips the method's image
// over the ground truth; a select picks the method). No network, nothing logged.
const char* kScript = R"js(
(function () {
  'use strict';
  function key(row, i) {
    var c = row.cells[i];
    if (!c) return null;
    var v = c.getAttribute('data-v');
    return v === null ? c.textContent.trim().toLowerCase() : parseFloat(v);
  }
  function compare(a, b, i, dir) {
    var fa = a.classList.contains('failed'), fb = b.classList.contains('failed');
    if (fa || fb) return fa === fb ? 0 : (fa ? 1 : -1);
    var x = key(a, i), y = key(b, i);
    if (typeof x === 'number' && typeof y === 'number') return (x - y) * dir;
    return String(x).localeCompare(String(y)) * dir;
  }
  function sortBy(table, th) {
    var i = th.cellIndex, body = table.tBodies[0];
    var dir = th.getAttribute('aria-sort') === 'ascending' ? -1 : 1;
    Array.prototype.forEach.call(th.parentNode.cells, function (h) {
      h.removeAttribute('aria-sort');
    });
    th.setAttribute('aria-sort', dir > 0 ? 'ascending' : 'descending');
    var rows = Array.prototype.filter.call(body.rows, function (r) {
      return !r.classList.contains('pinned');
    });
    rows.sort(function (a, b) { return compare(a, b, i, dir); });
    rows.forEach(function (r) { body.appendChild(r); });
  }
  Array.prototype.forEach.call(document.querySelectorAll('table[data-sortable]'), function (table) {
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th) {
      th.title = 'sort by this column';
      th.addEventListener('click', function () { sortBy(table, th); });
    });
  });
  function wipe(w) {
    var v = w.querySelector('input[type=range]').value;
    w.querySelector('img.over').style.clipPath = 'inset(0 ' + (100 - v) + '% 0 0)';
    w.querySelector('.handle').style.left = v + '%';
  }
  function choose(w) {
    var s = w.querySelector('select'), o = s.options[s.selectedIndex];
    w.querySelector('img.over').src = o.value;
    w.querySelector('img.over').alt = o.textContent;
    w.querySelector('.side.left').textContent = o.textContent;
  }
  Array.prototype.forEach.call(document.querySelectorAll('.wiper'), function (w) {
    w.querySelector('input[type=range]').addEventListener('input', function () { wipe(w); });
    w.querySelector('select').addEventListener('change', function () { choose(w); });
    wipe(w);
  });
})();
)js";

}  // namespace

std::string pageStart(const std::string& title) {
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  h += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  h += "<link rel=\"icon\" href=\"data:,\">\n";
  h += "<title>" + title + "</title>\n";
  h += "<style>" + std::string(kCss) + "</style>\n</head>\n<body>\n<main>\n";
  return h;
}

std::string pageEnd() {
  return "</main>\n<script>" + std::string(kScript) + "</script>\n</body>\n</html>\n";
}

std::string numberCell(double sortKey, const std::string& text, const std::string& cls) {
  const double key = std::isnan(sortKey)   ? -1e308
                     : std::isinf(sortKey) ? (sortKey > 0 ? 1e308 : -1e308)
                                           : sortKey;
  return "<td" + (cls.empty() ? std::string() : " class=\"" + cls + "\"") +
         format(" data-v=\"%.17g\">", key) + text + "</td>";
}

// ---- SVG plots -------------------------------------------------------------------------------

namespace {

struct Axis {
  double lo = 0.0, hi = 1.0;
  bool log = false;
  double floor = 0.0;  // log axes: where 0 is drawn (0: no zeros to draw)
  double map(double v, double p0, double p1) const {
    if (log && v <= 0.0) v = floor;
    const double a = log ? std::log10(lo) : lo, b = log ? std::log10(hi) : hi;
    const double t = ((log ? std::log10(v) : v) - a) / (b - a);
    return p0 + t * (p1 - p0);
  }
};

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

// ticks at 1, 2, 5 x 10^e in [lo, hi] (only the decades when there are more than three)
std::vector<double> logTicks(double lo, double hi) {
  std::vector<double> ticks;
  const int e0 = static_cast<int>(std::floor(std::log10(lo)));
  const int e1 = static_cast<int>(std::ceil(std::log10(hi)));
  const bool decadesOnly = e1 - e0 > 3;
  for (int e = e0; e <= e1; ++e)
    for (double m : {1.0, 2.0, 5.0}) {
      if (decadesOnly && m != 1.0) continue;
      const double t = m * std::pow(10.0, e);
      if (t >= lo && t <= hi) ticks.push_back(t);
    }
  return ticks;
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

struct Range {
  double lo = INFINITY, hi = -INFINITY, minPositive = INFINITY;
  bool zeros = false;
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    if (v > 0.0) minPositive = std::min(minPositive, v);
    zeros |= v <= 0.0;
  }
};

// the x axis and its ticks: the data's and the given ticks' range, a log axis with a margin of
// 15 %, a linear one with 8 %
Axis xAxis(const PlotSpec& spec, const std::vector<Series>& series, Ticks& ticks) {
  Range r;
  for (const Series& s : series)
    for (const auto& p : s.points) r.add(p.first);
  if (spec.xTicks)
    for (double t : spec.xTicks->at) r.add(t);
  Axis ax;
  ax.log = spec.logX && r.minPositive > 0.0 && r.lo > 0.0;
  if (ax.log) {
    ax.lo = r.lo / 1.15;
    ax.hi = r.hi * 1.15;
  } else {
    const double pad = std::max((r.hi - r.lo) * 0.08 + std::fabs(r.lo) * 0.02, 1e-9);
    ax.lo = r.lo >= 0.0 ? std::max(0.0, r.lo - pad) : r.lo - pad;
    ax.hi = r.hi + pad;
  }
  if (spec.xTicks) {
    ticks = *spec.xTicks;
  } else {
    ticks.at = ax.log ? logTicks(ax.lo, ax.hi) : niceTicks(ax.lo, ax.hi, 5);
    for (double t : ticks.at) ticks.labels.push_back(tickLabel(t));
  }
  return ax;
}

// the y axis and its ticks; an error axis spanning decades is log with 0 at its floor
Axis yAxis(const PlotSpec& spec, const std::vector<Series>& series, std::vector<double>& ticks) {
  Range r;
  std::vector<double> values;
  for (const Series& s : series)
    for (const auto& p : s.points) {
      r.add(p.second);
      values.push_back(p.second);
    }
  Axis ay;
  const AxisScale scale = spec.errorY ? chooseAxisScale(values) : AxisScale{};
  if (scale.log) {
    ay.log = true;
    ay.floor = r.zeros ? scale.floor : 0.0;
    ay.lo = (r.zeros ? scale.floor : r.minPositive) / 1.5;
    ay.hi = r.hi * 1.5;
    for (double t : logTicks(ay.lo, ay.hi))
      if (!r.zeros || t > scale.floor * 1.5) ticks.push_back(t);
    return ay;
  }
  const double span = std::max(r.hi - r.lo, std::fabs(r.hi) * 0.05 + 1e-12);
  ay.lo = spec.zeroBased ? std::min(0.0, r.lo) : r.lo - span * 0.15;
  ay.hi = r.hi > ay.lo ? r.hi + (r.hi - ay.lo) * 0.08 : ay.lo + 1.0;
  ticks = niceTicks(ay.lo, ay.hi, 5);
  if (!spec.zeroBased) ay.lo = std::min(ay.lo, ticks.front());
  ay.hi = std::max(ay.hi, ticks.back());
  return ay;
}

struct Frame {
  double x0, x1, y0, y1, W, H;  // plot area (y0 bottom) and the whole picture
};

std::string gridSvg(const Frame& f, const Axis& ax, const Axis& ay, const Ticks& xTicks,
                    const std::vector<double>& yTicks) {
  std::string svg = format(
      "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"#fcfcfc\" "
      "stroke=\"#333\" stroke-width=\"1\" data-x-scale=\"%s\" data-x-lo=\"%.17g\" "
      "data-x-hi=\"%.17g\" data-y-scale=\"%s\" data-y-lo=\"%.17g\" data-y-hi=\"%.17g\"",
      f.x0, f.y1, f.x1 - f.x0, f.y0 - f.y1, ax.log ? "log" : "linear", ax.lo, ax.hi,
      ay.log ? "log" : "linear", ay.lo, ay.hi);
  if (ay.floor > 0.0) svg += format(" data-y-floor=\"%.17g\"", ay.floor);
  svg += "/>";
  for (double t : yTicks) {
    const double y = ay.map(t, f.y0, f.y1);
    if (y < f.y1 - 0.5 || y > f.y0 + 0.5) continue;
    svg += format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e3e3e3\"/>",
                  f.x0, y, f.x1, y);
    svg += format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#333\"/>",
                  f.x0 - 5, y, f.x0, y);
    svg += format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">", f.x0 - 8, y + 4) +
           tickLabel(t) + "</text>";
  }
  if (ay.floor > 0.0) {  // where the exact runs (error 0) are drawn
    const double y = ay.map(ay.floor, f.y0, f.y1);
    svg += format(
        "<line class=\"exact\" x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#0a6b2d\" "
        "stroke-dasharray=\"4 3\"/><text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" "
        "fill=\"#0a6b2d\">0 exact</text>",
        f.x0, y, f.x1, y, f.x0 - 6, y + 4);
  }
  double lastLabelX = -1e9;
  for (size_t i = 0; i < xTicks.at.size(); ++i) {
    const double x = ax.map(xTicks.at[i], f.x0, f.x1);
    if (x < f.x0 - 0.5 || x > f.x1 + 0.5) continue;
    svg += format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e3e3e3\"/>", x,
                  f.y1, x, f.y0);
    svg += format("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#333\"/>", x,
                  f.y0, x, f.y0 + 5);
    if (x - lastLabelX >= 44.0 && i < xTicks.labels.size()) {
      svg += format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">", x, f.y0 + 19) +
             xTicks.labels[i] + "</text>";
      lastLabelX = x;
    }
  }
  return svg;
}

std::string labelsSvg(const Frame& f, const PlotSpec& spec, const Axis& ax, const Axis& ay) {
  std::string xText = spec.xLabel + (ax.log ? " (log scale)" : "");
  std::string yText = spec.yLabel + (ay.log ? " (log scale)" : "");
  std::string svg = format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s</text>",
                           (f.x0 + f.x1) / 2, f.H - 12, escape(xText).c_str());
  svg +=
      format("<text transform=\"translate(18 %.1f) rotate(-90)\" text-anchor=\"middle\">%s</text>",
             (f.y0 + f.y1) / 2, escape(yText).c_str());
  return svg;
}

// each point carries its exact values (data-x, data-y) next to its drawn position
std::string seriesSvg(const Frame& f, const Axis& ax, const Axis& ay, const Series& s) {
  std::string svg = "<g class=\"series\" data-series=\"" + escape(s.name) + "\">";
  std::vector<std::pair<double, double>> sorted = s.points;
  std::sort(sorted.begin(), sorted.end());
  std::string path;
  for (const auto& [x, y] : sorted) {
    path += path.empty() ? "M" : " L";
    path += format("%.1f %.1f", ax.map(x, f.x0, f.x1), ay.map(y, f.y0, f.y1));
  }
  if (s.line && sorted.size() > 1)
    svg += format("<path d=\"%s\" fill=\"none\" stroke=\"%s\" stroke-width=\"2\"/>", path.c_str(),
                  s.colour.c_str());
  for (size_t i = 0; i < s.points.size(); ++i) {
    const auto [x, y] = s.points[i];
    const bool front = i < s.onFront.size() && s.onFront[i];
    const double px = ax.map(x, f.x0, f.x1), py = ay.map(y, f.y0, f.y1);
    svg += format("<g class=\"point%s\" data-x=\"%.17g\" data-y=\"%.17g\">", front ? " front" : "",
                  x, y);
    if (i < s.labels.size()) svg += "<title>" + escape(s.labels[i]) + "</title>";
    if (front)
      svg += format(
          "<circle class=\"ring\" cx=\"%.1f\" cy=\"%.1f\" r=\"8.5\" fill=\"none\" stroke=\"#111\" "
          "stroke-width=\"1.6\"/>",
          px, py);
    svg += markerSvg(s.marker, px, py, s.colour) + "</g>";
  }
  return svg + "</g>";
}

std::string frontSvg(const Frame& f, const Axis& ax, const Axis& ay,
                     const std::vector<std::pair<double, double>>& front) {
  if (front.empty()) return {};
  std::string path;
  for (size_t i = 0; i < front.size(); ++i) {
    const double x = ax.map(front[i].first, f.x0, f.x1), y = ay.map(front[i].second, f.y0, f.y1);
    if (i == 0)
      path += format("M%.1f %.1f", x, y);
    else
      path += format(" H%.1f V%.1f", x, y);
  }
  return format(
      "<path class=\"front-line\" d=\"%s\" fill=\"none\" stroke=\"#111\" stroke-width=\"1.2\" "
      "stroke-dasharray=\"5 3\"/>",
      path.c_str());
}

std::string legendSvg(const Frame& f, const std::vector<Series>& series, bool front, bool errorY) {
  std::string svg;
  double ly = f.y1 + 8;
  const double lx = f.x1 + 12;
  for (const Series& s : series) {
    bool exact = errorY && !s.points.empty();
    for (const auto& p : s.points) exact = exact && p.second == 0.0;
    if (s.line)
      svg += format(
          "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
          "stroke-width=\"2\"/>",
          lx, ly, lx + 22, ly, s.colour.c_str());
    svg += markerSvg(s.marker, lx + 11, ly, s.colour);
    const std::string note = !s.note.empty()    ? " (" + s.note + ")"
                             : s.points.empty() ? " (failed)"
                             : exact            ? " (exact)"
                                                : "";
    svg += format("<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\">%s</text>", lx + 28, ly + 4,
                  (escape(s.name) + note).c_str());
    ly += 20;
  }
  if (front) {
    svg += format(
        "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"7\" fill=\"none\" stroke=\"#111\" "
        "stroke-width=\"1.6\"/><text x=\"%.1f\" y=\"%.1f\" font-size=\"11\">on the Pareto "
        "front</text>",
        lx + 11, ly + 4, lx + 28, ly + 8);
  }
  return svg;
}

}  // namespace

void setBytesPerPixelAxis(PlotSpec& spec, double lo, double hi) {
  if (lo > 0.0 && hi / lo >= 10.0) {
    spec.logX = true;
    return;
  }
  Ticks t;
  const double a = std::max(1.0, std::floor(lo)), b = std::max(std::ceil(hi), a + 1.0);
  t.at.push_back(a);
  for (double v : niceTicks(a, b, 4))
    if (v > a + 0.5 && v < b - 0.5) t.at.push_back(std::round(v));
  t.at.push_back(b);
  for (double v : t.at) t.labels.push_back(format("%g B", v));
  spec.xTicks = t;
}

std::string svgPlot(const PlotSpec& spec, const std::vector<Series>& series) {
  size_t longest = spec.front.empty() ? 0 : 19;
  for (const Series& s : series)
    longest = std::max(longest, s.name.size() + (s.points.empty() ? 9 : 8));
  const double left = 66, right = 46 + 6.3 * static_cast<double>(longest);
  Frame f;
  f.W = std::ceil(left + spec.plotWidth + right);
  f.H = spec.height;
  f.x0 = left;
  f.x1 = f.W - right;
  f.y0 = f.H - 52;
  f.y1 = 34;
  // the legend beside the plot: 20 px an entry, the picture as tall as it needs (many methods)
  const size_t entries = series.size() + (spec.front.empty() ? 0 : 1);
  const double height = std::max(f.H, std::ceil(f.y1 + 8 + 20.0 * static_cast<double>(entries)));
  std::string svg = format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 %.0f %.0f\" width=\"%.0f\" "
      "height=\"%.0f\" role=\"img\" aria-label=\"%s\" font-family=\"inherit\" font-size=\"12\">",
      f.W, height, f.W, height, escape(spec.title).c_str());
  svg += format(
      "<text x=\"%.1f\" y=\"20\" text-anchor=\"middle\" font-size=\"14\" "
      "font-weight=\"600\">%s</text>",
      (f.x0 + f.x1) / 2, escape(spec.title).c_str());
  bool any = false;
  for (const Series& s : series)
    for (const auto& p : s.points) any = any || std::isfinite(p.second);
  if (!any)
    return svg +
           format("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">no successful runs</text>",
                  (f.x0 + f.x1) / 2, (f.y0 + f.y1) / 2) +
           "</svg>";
  Ticks xTicks;
  std::vector<double> yTicks;
  const Axis ax = xAxis(spec, series, xTicks), ay = yAxis(spec, series, yTicks);
  svg += gridSvg(f, ax, ay, xTicks, yTicks) + labelsSvg(f, spec, ax, ay);
  svg += frontSvg(f, ax, ay, spec.front);
  for (const Series& s : series) svg += seriesSvg(f, ax, ay, s);
  return svg + legendSvg(f, series, !spec.front.empty(), spec.errorY) + "</svg>";
}

}  // namespace mfr::report
