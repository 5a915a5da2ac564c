// The HTML report of `mfr compare`: one self-contained page (inline CSS, inline SVG plots, a
// small inline script for sortable tables and image wipers, no external resources) next to the
// images it shows. The recommendation and the images are in report_recommend.cpp and
// report_images.cpp; the style, script and plots are shared with the temporal report
// (report_common.cpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "mfr/compare/compare.hpp"
#include "mfr/compare/report_ranking.hpp"
#include "mfr/core/units.hpp"
#include "mfr/metrics/magma.hpp"
#include "report_common.hpp"
#include "report_sections.hpp"

namespace mfr {
namespace report {

std::string psnrText(double psnr) {
  return std::isfinite(psnr) ? format("%.2f", psnr) : std::string("&infin;");
}

std::string mib(uint64_t bytes) {
  return format("%.2f", static_cast<double>(bytes) / (1024.0 * 1024.0));
}

namespace {
std::string budgetTitle(uint64_t bytes) {
  std::string s = escape(formatBytes(bytes));
  s += " (";
  s += grouped(bytes);
  s += "&#8201;B)";
  return s;
}
}  // namespace

// a relative budget: its share, the node bytes it buys, and that each method adds its own words
std::string budgetTitle(const CompareBudget& cb) {
  if (!cb.percent) return budgetTitle(cb.budgetBytes);
  return escape(cb.label) + " of the A-buffer&rsquo;s node bytes = " + budgetTitle(cb.budgetBytes) +
         " of nodes + each method&rsquo;s per-pixel words";
}

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

}  // namespace report

namespace {

using namespace report;

struct Best {
  double flip = INFINITY, mse = INFINITY, psnr = -INFINITY;
};

const char* kResultsHeader =
    "<thead><tr>"
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
    "<th>Time<span class=\"unit\">total, ms: median (min&ndash;max)</span></th>"
    "<th>Passes<span class=\"unit\">ms</span></th>"
    "</tr></thead><tbody>";

std::string passesText(const RenderStats& s) {
  std::string p;
  for (const PassTime& pt : s.passes) {
    if (!p.empty()) p += " &middot; ";
    p += escape(pt.name) + "&nbsp;" + format("%.1f", pt.ms);
  }
  return p;
}

// the ground truth's row, pinned on top when the table is sorted
std::string groundTruthRow(const CompareRun& gt) {
  const RenderStats& s = gt.stats;
  return "<tr class=\"gt pinned\"><td>abuffer (ground truth)</td><td>" + mib(s.bytesUsed) +
         "</td><td>&mdash;</td><td>" + format("%.1f", 100.0 * gt.memoryUtilisation()) +
         "</td><td>" + format("%u&ndash;%u", s.kMin, s.kMax) + "</td><td>" + grouped(s.captured) +
         "</td><td>" + format("%.2f", s.lostPercent()) +
         "</td><td>0</td><td>&infin;</td><td>0</td><td>&infin;</td><td>0</td><td>" +
         format("%.1f", s.totalMs()) +
         (gt.timing.repeats > 1
              ? format("<small> %.1f&ndash;%.1f</small>", gt.timing.minMs, gt.timing.maxMs)
              : std::string()) +
         "</td><td class=\"passes\">" + passesText(s) + "</td></tr>";
}

// the method cell: name, compositing, the oracle's bound and the report's tags
std::string methodCell(const CompareRun& run, bool winner, bool fixed) {
  std::string t = "<td>" + escape(run.label) + "<small> " + toString(run.compositing) + "</small>";
  if (winner) t += "<span class=\"tag win\">winner</span>";
  if (fixed) t += "<span class=\"tag fixed\">fixed memory</span>";
  if (run.ok() && run.stats.oracle) {
    const OracleReport& o = *run.stats.oracle;
    t += o.exact ? "<small>oracle: proven minimum under " + std::string(toString(run.compositing)) +
                       "</small>"
                 : "<small>oracle: error &le; lower bound " + sci(o.lowerBound) + " + gap " +
                       sci(o.gap()) + "</small>";
  }
  return t + "</td>";
}

std::string runRow(const CompareRun& run, const Best& best, bool winner, bool fixed) {
  if (!run.ok())
    return "<tr class=\"failed\">" + methodCell(run, false, false) +
           "<td class=\"err\" colspan=\"13\">failed: " + escape(*run.error) + "</td></tr>";
  const auto cls = [](bool isBest) { return isBest ? std::string("best") : std::string(); };
  const RenderStats& s = run.stats;
  const CompareMetrics& m = run.metrics;
  std::string t = winner ? "<tr class=\"winner\">" : "<tr>";
  t += methodCell(run, winner, fixed);
  t += numberCell(static_cast<double>(s.bytesUsed), mib(s.bytesUsed));
  t += numberCell(static_cast<double>(run.budgetSlots), grouped(run.budgetSlots));
  t += numberCell(run.memoryUtilisation(), format("%.1f", 100.0 * run.memoryUtilisation()));
  t += numberCell(s.kMax, format("%u&ndash;%u", s.kMin, s.kMax));
  t += numberCell(static_cast<double>(s.captured), grouped(s.captured));
  t += numberCell(s.lostPercent(), format("%.2f", s.lostPercent()));
  t += numberCell(m.mseLinear, sci(m.mseLinear), cls(m.mseLinear == best.mse));
  t += numberCell(m.psnrLinear, psnrText(m.psnrLinear), cls(m.mseLinear == best.mse));
  t += numberCell(m.mseSrgb, sci(m.mseSrgb), cls(m.psnrSrgb == best.psnr));
  t += numberCell(m.psnrSrgb, psnrText(m.psnrSrgb), cls(m.psnrSrgb == best.psnr));
  t += numberCell(m.flipMean, format("%.4f", m.flipMean), cls(m.flipMean == best.flip));
  // the median of --repeat timed renders, their range beside it
  t += numberCell(s.totalMs(),
                  format("%.1f", s.totalMs()) + (run.timing.repeats > 1
                                                     ? format("<small> %.1f&ndash;%.1f</small>",
                                                              run.timing.minMs, run.timing.maxMs)
                                                     : std::string()));
  return t + "<td class=\"passes\">" + passesText(s) + "</td></tr>";
}

// one budget's table, sortable by any column (the ground truth stays on top); the winner's row
// is highlighted
std::string resultsTable(const CompareResult& r, const CompareBudget& cb) {
  Best best;
  for (const CompareRun& run : cb.runs) {
    if (!run.ok()) continue;
    best.flip = std::min(best.flip, run.metrics.flipMean);
    best.mse = std::min(best.mse, run.metrics.mseLinear);
    best.psnr = std::max(best.psnr, run.metrics.psnrSrgb);
  }
  const Recommendation rec = recommend(cb);
  const std::vector<std::string> fixed = fixedMemoryMethods(r);
  std::string t = "<table class=\"results\" data-sortable>" + std::string(kResultsHeader);
  t += groundTruthRow(r.groundTruth);
  for (size_t i = 0; i < cb.runs.size(); ++i) {
    const bool isFixed = std::find(fixed.begin(), fixed.end(), cb.runs[i].label) != fixed.end();
    t += runRow(cb.runs[i], best, rec.winner == i, isFixed);
  }
  return t + "</tbody></table>";
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
  std::string h = pageStart("mfr compare &mdash; " + escape(r.scene) + ", " + size);
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
       "; rendered on the " + escape(r.truthEngine.empty() ? r.engine : r.truthEngine) + " engine" +
       (r.truthNote.empty() ? "" : " (" + escape(r.truthNote) + ")") + "</td></tr>\n";
  h += "<tr><th>Software</th><td>" + escape(info.mfrVersion.empty() ? "mfr" : info.mfrVersion) +
       ", the " + escape(r.engine) + " engine" +
       (r.engine == "cpu" ? std::string(" (the CPU reference engine)") : std::string()) +
       "</td></tr>\n";
  h += "<tr><th>Timing</th><td>" +
       format(
           "%d timed render%s per run after %d untimed; the tables show the median total and "
           "the range",
           r.repeat, r.repeat == 1 ? "" : "s", r.warmup) +
       "</td></tr>\n";
  if (!info.generated.empty())
    h += "<tr><th>Generated</th><td>" + escape(info.generated) + "</td></tr>\n";
  h += "<tr><th>Command</th><td><pre class=\"cmd\">" + escape(info.commandLine) +
       "</pre></td></tr>\n";
  h += "<tr><th>Contents</th><td><a href=\"#recommendation\">recommendation</a> &middot; "
       "<a href=\"#results\">results</a> &middot; " +
       std::string(r.budgets.size() > 1 ? "<a href=\"#plots\">plots</a> &middot; " : "") +
       "<a href=\"#images\">images</a> &middot; <a href=\"#notes\">notes</a></td></tr>\n";
  h += "<tr><th>Data</th><td><a href=\"results.json\">results.json</a> &middot; "
       "<a href=\"results.csv\">results.csv</a></td></tr>\n";
  h += "</table>\n";
  return h;
}

// Results: one table per budget
std::string resultsSection(const CompareResult& r, int section) {
  std::string h;
  h += format("<h2 id=\"results\">%d&ensp;Results</h2>\n", section);
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
       "are milliseconds of the " +
       escape(r.engine) + " engine (the median of " + std::to_string(r.repeat) +
       " timed renders, their range beside it). Click a column's header to sort by it.</p>\n";
  for (const CompareBudget& cb : r.budgets) {
    h += "<h3>M = " + budgetTitle(cb) + "</h3>\n";
    h += resultsTable(r, cb) + "\n";
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
      s.colour = paletteColour(m);
      s.marker = static_cast<int>(c);
      for (const CompareBudget& cb : sc.budgets) {
        if (m >= cb.runs.size() || !cb.runs[m].ok()) continue;
        const double bpp = static_cast<double>(cb.runs[m].stats.bytesUsed) / pixels;
        s.points.emplace_back(bpp, cb.runs[m].metrics.flipMean);
        lo = std::min(lo, bpp);
        hi = std::max(hi, bpp);
      }
      series.push_back(std::move(s));
    }
  if (!std::isfinite(lo)) return {};
  std::string counts;
  for (const SampleCountRuns& sc : r.sampleCounts)
    counts += (counts.empty() ? "" : ", ") + std::to_string(sc.samples);
  PlotSpec spec;
  spec.title = "Mean FLIP vs bytes per pixel at " + counts + " samples";
  spec.xLabel = "bytes per pixel charged (bytes_used / pixels)";
  spec.yLabel = "mean FLIP";
  spec.errorY = true;
  setBytesPerPixelAxis(spec, lo, hi);
  return "<figure>" + svgPlot(spec, series) +
         "<figcaption>Each method at each sample count (--sample-counts; marker: the count), "
         "against that count's own ground truth (the per-sample A-buffer, box-filtered), with " +
         escape(toString(r.sampleStorage)) +
         " storage: what antialiasing costs each method in memory.</figcaption></figure>\n";
}

// the budgets' indices, smallest budget first
std::vector<size_t> budgetOrder(const CompareResult& r) {
  std::vector<size_t> order(r.budgets.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return r.budgets[a].budgetBytes < r.budgets[b].budgetBytes;
  });
  return order;
}

// one series per method of value(run) over the budgets (failed runs: no point)
template <typename Value>
std::vector<Series> seriesOverBudgets(const CompareResult& r,
                                      const std::vector<std::string>& methodNames,
                                      const Value& value) {
  std::vector<Series> out;
  for (size_t m = 0; m < methodNames.size(); ++m) {
    Series s;
    s.name = methodNames[m];
    s.colour = paletteColour(m);
    s.marker = static_cast<int>(m);
    std::optional<uint64_t> minimum;  // refused somewhere: the method's smallest budget
    for (const CompareBudget& cb : r.budgets) {
      const CompareRun& run = cb.runs[m];
      if (run.ok())
        s.points.emplace_back(static_cast<double>(cb.budgetBytes), value(run));
      else if (run.minimumBytes)
        minimum = std::min(minimum.value_or(*run.minimumBytes), *run.minimumBytes);
    }
    if (minimum)
      s.note = (s.points.empty() ? "failed; needs &#8805; " : "needs &#8805; ") + mib(*minimum);
    out.push_back(std::move(s));
  }
  return out;
}

// a plot over the budgets: ticks at the budgets, a log x axis when they span 4x or more
PlotSpec budgetPlotSpec(const CompareResult& r, const std::string& title, const std::string& yLabel,
                        bool errorY) {
  PlotSpec spec;
  spec.title = title;
  spec.yLabel = yLabel;
  spec.xLabel = "memory budget M";
  spec.errorY = errorY;
  spec.zeroBased = errorY;
  Ticks ticks;
  for (size_t i : budgetOrder(r)) {
    ticks.at.push_back(static_cast<double>(r.budgets[i].budgetBytes));
    ticks.labels.push_back(escape(r.budgets[i].label));
  }
  spec.logX = ticks.at.back() / ticks.at.front() >= 4.0;
  spec.xTicks = ticks;
  return spec;
}

// Error vs memory budget: the plots over the budgets, smallest first (two budgets or more)
std::string budgetPlots(const CompareResult& r, const std::vector<std::string>& methodNames,
                        int section) {
  const auto figure = [&](const char* title, const char* yLabel, bool errorY, auto value,
                          const char* caption) {
    return "<figure>" +
           svgPlot(budgetPlotSpec(r, title, yLabel, errorY),
                   seriesOverBudgets(r, methodNames, value)) +
           "<figcaption>" + caption + "</figcaption></figure>\n";
  };
  std::string h = format("<h2 id=\"plots\">%d&ensp;Error vs memory budget</h2>\n", section);
  h += "<p class=\"caption\">Error axes turn logarithmic where the values span a decade or more; "
       "a run with no error at all (0) is then drawn on the dashed line marked "
       "<em>0 exact</em>.</p>\n";
  h += "<div class=\"plots\">\n";
  h += figure(
      "Mean FLIP vs budget", "mean FLIP", true,
      [](const CompareRun& run) { return run.metrics.flipMean; },
      "Mean LDR-FLIP error against the exact A-buffer (lower is better). Missing points: the "
      "method failed at that budget.");
  h += figure(
      "MSE (linear) vs budget", "MSE, linear", true,
      [](const CompareRun& run) { return run.metrics.mseLinear; },
      "Mean squared error on linear-light values (lower is better).");
  h += figure(
      "Fragments lost vs budget", "fragments lost, %", false,
      [](const CompareRun& run) { return run.stats.lostPercent(); },
      "Share of the generated fragments not in the final per-pixel cores.");
  return h + "</div>\n";
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
  int section = 2;
  h += recommendationSection(r, section++);
  h += resultsSection(r, section++);
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
  return h + pageEnd();
}

}  // namespace mfr
