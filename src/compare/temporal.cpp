// Temporal stability along a camera path (issue 14, sec. 5; see mfr/compare/temporal.hpp):
// consecutive-frame FLIP of each method against that of the ground truth, and the change of each
// method's per-pixel error from frame to frame; its results.csv and its HTML report (in the style
// of the one-view report: report_common.hpp).
#include "mfr/compare/temporal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "mfr/core/plot.hpp"
#include "mfr/metrics/flip.hpp"
#include "report_common.hpp"

namespace mfr {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double meanOf(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0.0;
  for (double x : v) s += x;  // a NaN (missing transition) makes the mean NaN
  return s / static_cast<double>(v.size());
}

nlohmann::json numbers(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double x : v) a.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr));
  return a;
}

nlohmann::json number(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

// distinct sRGB line colours (the report's palette)
const glm::vec3 kColours[] = {{0.12f, 0.47f, 0.71f}, {1.0f, 0.5f, 0.05f},  {0.17f, 0.63f, 0.17f},
                              {0.84f, 0.15f, 0.16f}, {0.58f, 0.4f, 0.74f}, {0.55f, 0.34f, 0.29f},
                              {0.89f, 0.47f, 0.76f}, {0.5f, 0.5f, 0.5f},   {0.74f, 0.74f, 0.13f},
                              {0.09f, 0.75f, 0.81f}};

// e(t): mean over pixels and RGB of |(method_t - truth_t) - (method_t-1 - truth_t-1)| / 255
double errorChange(const Image8& method, const Image8& truth, const Image8& previousMethod,
                   const Image8& previousTruth) {
  const size_t pixels = method.rgba.size() / 4;
  if (pixels == 0) return 0.0;
  int64_t sum = 0;
  for (size_t p = 0; p < pixels; ++p)
    for (size_t c = 0; c < 3; ++c) {
      const size_t i = p * 4 + c;
      const int now = int{method.rgba[i]} - int{truth.rgba[i]};
      const int before = int{previousMethod.rgba[i]} - int{previousTruth.rgba[i]};
      sum += std::abs(now - before);
    }
  return static_cast<double>(sum) / (255.0 * 3.0 * static_cast<double>(pixels));
}

}  // namespace

std::vector<Camera> orbitPath(const Camera& camera, int views, float stepDegrees) {
  std::vector<Camera> cameras;
  const glm::vec3 axis = glm::normalize(camera.up);
  for (int i = 0; i < views; ++i) {
    const float angle = glm::radians(stepDegrees) * static_cast<float>(i);
    const glm::mat4 rotation = glm::rotate(glm::mat4(1.0f), angle, axis);
    Camera c = camera;
    c.eye = camera.target + glm::vec3(rotation * glm::vec4(camera.eye - camera.target, 0.0f));
    cameras.push_back(c);
  }
  return cameras;
}

TemporalStability::TemporalStability(double flipPixelsPerDegree) : ppd_(flipPixelsPerDegree) {}

Result<void> TemporalStability::add(const CompareResult& frame) {
  size_t runs = 0;
  for (const CompareBudget& cb : frame.budgets) runs += cb.runs.size();
  if (frames_ == 0) {
    width_ = frame.width;
    height_ = frame.height;
    previous_.assign(runs, Image8{});
    for (const CompareBudget& cb : frame.budgets)
      for (const CompareRun& run : cb.runs) {
        TemporalSeries& s = result_.series.emplace_back();
        s.method = run.label;
        s.budgetLabel = cb.label;
      }
  } else if (frame.width != width_ || frame.height != height_ || runs != previous_.size()) {
    return makeError("frame " + std::to_string(frames_) +
                     ": its size, methods or budgets differ from the first frame's");
  }
  if (frames_ > 0) {
    auto truth = computeFlip(previousTruth_, frame.groundTruth.image, ppd_);
    if (!truth) return truth.error();
    result_.groundTruthConsecutiveFlip.push_back(truth->mean);
  }
  size_t index = 0;
  for (const CompareBudget& cb : frame.budgets)
    for (const CompareRun& run : cb.runs) {
      TemporalSeries& s = result_.series[index];
      if (s.method != run.label || s.budgetLabel != cb.label)
        return makeError("frame " + std::to_string(frames_) + ": run " + run.label + " at " +
                         cb.label + " where the first frame had " + s.method + " at " +
                         s.budgetLabel);
      Image8& previous = previous_[index++];
      s.errorFlip.push_back(run.ok() ? run.metrics.flipMean : kNaN);
      if (frames_ > 0) {
        double f = kNaN, e = kNaN;
        if (run.ok() && !previous.rgba.empty()) {
          auto flip = computeFlip(previous, run.image, ppd_);
          if (!flip) return flip.error();
          f = flip->mean;
          e = errorChange(run.image, frame.groundTruth.image, previous, previousTruth_);
        }
        s.consecutiveFlip.push_back(f);
        s.errorChange.push_back(e);
      }
      previous = run.ok() ? run.image : Image8{};
    }
  previousTruth_ = frame.groundTruth.image;
  ++frames_;
  return {};
}

TemporalResult TemporalStability::result() const {
  TemporalResult r = result_;
  r.frames = frames_;
  r.groundTruthFlicker = meanOf(r.groundTruthConsecutiveFlip);
  for (TemporalSeries& s : r.series) {
    s.flicker = meanOf(s.consecutiveFlip);
    std::vector<double> excess;
    for (size_t t = 0; t < s.consecutiveFlip.size(); ++t)
      excess.push_back(s.consecutiveFlip[t] - r.groundTruthConsecutiveFlip[t]);
    s.excessFlicker = meanOf(excess);
    s.meanErrorChange = meanOf(s.errorChange);
    s.meanFlip = meanOf(s.errorFlip);
  }
  return r;
}

nlohmann::json temporalToJson(const TemporalResult& r) {
  nlohmann::json j;
  j["frames"] = r.frames;
  j["definition"] =
      "flicker = mean over t of mean FLIP(frame t-1, frame t); excess_flicker = mean over t of "
      "(the method's consecutive-frame FLIP - the ground truth's); error_change[t] = mean over "
      "pixels and RGB of |(method_t - truth_t) - (method_t-1 - truth_t-1)| / 255 on the sRGB8 "
      "images; mean_error_change = its mean over t; mean_flip = the mean over the frames of the "
      "mean FLIP against the ground truth (error_flip)";
  j["ground_truth"] = {{"consecutive_flip", numbers(r.groundTruthConsecutiveFlip)},
                       {"flicker", number(r.groundTruthFlicker)}};
  nlohmann::json series = nlohmann::json::array();
  for (const TemporalSeries& s : r.series)
    series.push_back({{"method", s.method},
                      {"budget_label", s.budgetLabel},
                      {"consecutive_flip", numbers(s.consecutiveFlip)},
                      {"error_flip", numbers(s.errorFlip)},
                      {"error_change", numbers(s.errorChange)},
                      {"flicker", number(s.flicker)},
                      {"excess_flicker", number(s.excessFlicker)},
                      {"mean_error_change", number(s.meanErrorChange)},
                      {"mean_flip", number(s.meanFlip)}});
  j["series"] = series;
  return j;
}

Result<Image8> temporalPlot(const TemporalResult& r, const std::string& budgetLabel,
                            TemporalMeasure measure) {
  const bool excess = measure == TemporalMeasure::ExcessFlicker;
  std::vector<PlotSeries> lines;
  for (const TemporalSeries& s : r.series) {
    if (s.budgetLabel != budgetLabel) continue;
    PlotSeries& line = lines.emplace_back();
    line.label = s.method;
    line.color = kColours[(lines.size() - 1) % (sizeof kColours / sizeof kColours[0])];
    for (size_t t = 0; t < s.consecutiveFlip.size(); ++t) {
      line.x.push_back(static_cast<double>(t + 1));
      line.y.push_back(excess ? s.consecutiveFlip[t] - r.groundTruthConsecutiveFlip[t]
                              : s.errorChange[t]);
    }
  }
  PlotOptions options;
  options.width = 640;
  options.height = 360;
  options.title = (excess ? "excess flicker at " : "error change at ") + budgetLabel;
  options.xLabel = "frame t (vs t-1)";
  options.yLabel = excess ? "FLIP(t-1,t) - ground truth's" : "mean |error(t) - error(t-1)|";
  return plotLines(lines, options);
}

namespace {

std::string csvNumber(double x) {
  return std::isfinite(x) ? report::format("%.17g", x) : "";
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

std::string temporalToCsv(const TemporalResult& r) {
  std::string csv =
      "method,budget_label,frames,mean_flip,flicker,excess_flicker,mean_error_change\n";
  csv +=
      "abuffer,," + std::to_string(r.frames) + ",0," + csvNumber(r.groundTruthFlicker) + ",0,0\n";
  for (const TemporalSeries& s : r.series)
    csv += csvField(s.method) + "," + csvField(s.budgetLabel) + "," + std::to_string(r.frames) +
           "," + csvNumber(s.meanFlip) + "," + csvNumber(s.flicker) + "," +
           csvNumber(s.excessFlicker) + "," + csvNumber(s.meanErrorChange) + "\n";
  return csv;
}

// ---- the HTML report ---------------------------------------------------------------------------

namespace {

using report::escape;
using report::format;

std::string cell(double x) {
  return std::isfinite(x) ? format("%.4f", x) : std::string("n/a");
}

// a sortable cell; a missing value (a failed frame) sorts last
std::string measureCell(double x) {
  return report::numberCell(std::isfinite(x) ? x : 1e308, cell(x));
}

// the budget labels in the series' order, each once
std::vector<std::string> budgetLabels(const TemporalResult& r) {
  std::vector<std::string> labels;
  for (const TemporalSeries& s : r.series)
    if (std::find(labels.begin(), labels.end(), s.budgetLabel) == labels.end())
      labels.push_back(s.budgetLabel);
  return labels;
}

std::string setupTable(const TemporalResult& r, const TemporalReportPage& p) {
  std::string methods;
  for (const TemporalSeries& s : r.series)
    if (methods.find("<code>" + escape(s.method) + "</code>") == std::string::npos)
      methods += (methods.empty() ? "" : ", ") + ("<code>" + escape(s.method) + "</code>");
  std::string budgets;
  for (const std::string& b : budgetLabels(r)) budgets += (budgets.empty() ? "" : ", ") + escape(b);
  std::string h = "<h2 id=\"setup\">1&ensp;Set-up</h2>\n<table class=\"meta\">\n";
  h += "<tr><th>Scene</th><td><code>" + escape(p.scene) + "</code></td></tr>\n";
  h += format("<tr><th>Image</th><td>%d&#8201;&times;&#8201;%d pixels</td></tr>\n", p.width,
              p.height);
  h += format("<tr><th>Path</th><td>%d frames, %.3g&deg; apart about the camera's up axis</td>",
              r.frames, static_cast<double>(p.stepDegrees)) +
       "</tr>\n";
  h += "<tr><th>Budgets</th><td>" + budgets + "</td></tr>\n";
  h += "<tr><th>Methods</th><td>" + methods + "</td></tr>\n";
  h += "<tr><th>Ground truth</th><td>exact A-buffer; its own flicker (the change the camera "
       "motion causes) is " +
       cell(r.groundTruthFlicker) + "</td></tr>\n";
  h += "<tr><th>Software</th><td>" + escape(p.mfrVersion.empty() ? "mfr" : p.mfrVersion) +
       "</td></tr>\n";
  if (!p.generated.empty())
    h += "<tr><th>Generated</th><td>" + escape(p.generated) + "</td></tr>\n";
  h += "<tr><th>Command</th><td><pre class=\"cmd\">" + escape(p.commandLine) + "</pre></td></tr>\n";
  h += "<tr><th>Data</th><td><a href=\"results.json\">results.json</a> &middot; "
       "<a href=\"results.csv\">results.csv</a> &middot; each frame's own report below</td></tr>\n";
  return h + "</table>\n";
}

// the series at `budget` with the lowest finite `value`, or null
template <typename Value>
const TemporalSeries* lowest(const TemporalResult& r, const std::string& budget,
                             const Value& value) {
  const TemporalSeries* best = nullptr;
  for (const TemporalSeries& s : r.series)
    if (s.budgetLabel == budget && std::isfinite(value(s)) && (!best || value(s) < value(*best)))
      best = &s;
  return best;
}

// per budget: the most accurate method (mean FLIP over the frames) and the steadiest (error change)
std::string verdicts(const TemporalResult& r) {
  std::string h = "<ul class=\"verdicts\">";
  for (const std::string& b : budgetLabels(r)) {
    const TemporalSeries* accurate =
        lowest(r, b, [](const TemporalSeries& s) { return s.meanFlip; });
    const TemporalSeries* steady =
        lowest(r, b, [](const TemporalSeries& s) { return s.meanErrorChange; });
    h += "<li><b>" + escape(b) + "</b>: ";
    if (!accurate || !steady) {
      h += "no method ran on every frame.</li>";
      continue;
    }
    const std::string a = "<strong>" + escape(accurate->method) + "</strong>";
    const std::string flip = "mean FLIP " + cell(accurate->meanFlip);
    const std::string change = "error change " + cell(steady->meanErrorChange);
    if (accurate == steady)
      h += a + " is both the most accurate (" + flip + ") and the steadiest (" + change + ").";
    else
      h += a + " is the most accurate (" + flip + "), <strong>" + escape(steady->method) +
           "</strong> the steadiest (" + change + ").";
    h += "</li>";
  }
  return h + "</ul>\n";
}

std::string summaryTable(const TemporalResult& r) {
  std::string h =
      "<table class=\"results\" data-sortable><thead><tr><th>Method</th><th>Budget</th>"
      "<th>FLIP<span class=\"unit\">mean vs ground truth</span></th>"
      "<th>Flicker<span class=\"unit\">mean f(t)</span></th>"
      "<th>Excess flicker<span class=\"unit\">vs ground truth's</span></th>"
      "<th>Error change<span class=\"unit\">mean e(t)</span></th></tr></thead><tbody>";
  h += "<tr class=\"gt pinned\"><td>abuffer (ground truth)</td><td>&mdash;</td><td>0</td><td>" +
       cell(r.groundTruthFlicker) + "</td><td>0</td><td>0</td></tr>";
  for (const TemporalSeries& s : r.series)
    h += "<tr><td><code>" + escape(s.method) + "</code></td><td>" + escape(s.budgetLabel) +
         "</td>" + measureCell(s.meanFlip) + measureCell(s.flicker) + measureCell(s.excessFlicker) +
         measureCell(s.meanErrorChange) + "</tr>";
  return h + "</tbody></table>\n";
}

// whole-number ticks 0 .. n (about ten)
report::Ticks frameTicks(int first, int last) {
  report::Ticks t;
  const int step = std::max(1, (last - first + 9) / 10);
  for (int i = first; i <= last; i += step) {
    t.at.push_back(i);
    t.labels.push_back(std::to_string(i));
  }
  return t;
}

// one line per method at `budget` of value(series, t) over t = first .. first + count - 1
template <typename Value>
std::string framePlot(const TemporalResult& r, const std::string& budget, report::PlotSpec spec,
                      int first, const Value& value) {
  std::vector<report::Series> lines;
  int last = first;
  for (const TemporalSeries& s : r.series) {
    if (s.budgetLabel != budget) continue;
    report::Series& line = lines.emplace_back();
    line.name = s.method;
    line.colour = report::paletteColour(lines.size() - 1);
    line.marker = static_cast<int>(lines.size() - 1);
    for (int t = first; t < first + r.frames - (first ? 1 : 0); ++t) {
      const double v = value(s, static_cast<size_t>(t - first));
      if (std::isfinite(v)) line.points.emplace_back(t, v);
      last = std::max(last, t);
    }
  }
  spec.xTicks = frameTicks(first, last);
  return "<figure>" + report::svgPlot(spec, lines) + "</figure>\n";
}

report::PlotSpec frameSpec(const std::string& title, const std::string& yLabel, bool errorY) {
  report::PlotSpec spec;
  spec.title = title;
  spec.xLabel = "frame";
  spec.yLabel = yLabel;
  spec.errorY = errorY;
  spec.zeroBased = errorY;
  spec.plotWidth = 180;  // three plots in a row at 1400 px
  spec.height = 300;
  return spec;
}

std::string plotsSection(const TemporalResult& r) {
  std::string h = "<h2 id=\"plots\">3&ensp;Over the frames</h2>\n";
  for (const std::string& b : budgetLabels(r)) {
    h += "<h3>" + escape(b) + "</h3>\n<div class=\"plots\">\n";
    h += framePlot(r, b, frameSpec("Mean FLIP vs ground truth at " + b, "mean FLIP", true), 0,
                   [](const TemporalSeries& s, size_t t) { return s.errorFlip[t]; });
    h += framePlot(r, b, frameSpec("Excess flicker at " + b, "f(t) - ground truth's", false), 1,
                   [&r](const TemporalSeries& s, size_t t) {
                     return s.consecutiveFlip[t] - r.groundTruthConsecutiveFlip[t];
                   });
    h += framePlot(r, b, frameSpec("Error change at " + b, "e(t)", true), 1,
                   [](const TemporalSeries& s, size_t t) { return s.errorChange[t]; });
    h += "</div>\n";
  }
  return h;
}

// thumbnails about 160 px wide: small images upscaled by a whole factor
int thumbnailWidth(int width) {
  if (width <= 0) return 0;
  return width >= 160 ? 160 : width * std::max(1, 160 / width);
}

std::string thumbnail(const std::string& folder, const std::string& file, const std::string& alt,
                      const TemporalReportPage& p) {
  if (file.empty()) return "<td class=\"err\">failed</td>";
  const std::string src = escape(folder + "/" + file);
  const int w = thumbnailWidth(p.width);
  const int h =
      p.width > 0 ? static_cast<int>(std::lround(static_cast<double>(p.height) * w / p.width)) : 0;
  return "<td><a href=\"" + src + "\"><img src=\"" + src + "\" alt=\"" + escape(alt) + "\" " +
         format("width=\"%d\" height=\"%d\" loading=\"lazy\"></a></td>", w, h);
}

// per budget, a row per frame: its report, the ground truth, then each method's image
std::string framesSection(const TemporalResult& r, const TemporalReportPage& p) {
  std::string h =
      "<h2 id=\"frames\">4&ensp;Frames</h2>\n<p class=\"caption\">Every frame's "
      "images; the frame's name opens its own report (tables, FLIP maps, "
      "wiper, worst regions).</p>\n";
  for (const std::string& b : budgetLabels(r)) {
    h += "<h3>" + escape(b) +
         "</h3>\n<div class=\"scroll\"><table class=\"frames\"><tr>"
         "<th>frame</th><th>ground truth</th>";
    for (const TemporalSeries& s : r.series)
      if (s.budgetLabel == b) h += "<th>" + escape(s.method) + "</th>";
    h += "</tr>";
    for (size_t f = 0; f < p.frameFolders.size(); ++f) {
      const std::string& folder = p.frameFolders[f];
      const std::vector<std::string>& files =
          f < p.frameImages.size() ? p.frameImages[f] : std::vector<std::string>{};
      h += "<tr><td><a href=\"" + escape(folder) + "/report.html\">" + escape(folder) + "</a></td>";
      h += thumbnail(folder, files.empty() ? "" : files[0], folder + " ground truth", p);
      for (size_t i = 0; i < r.series.size(); ++i)
        if (r.series[i].budgetLabel == b)
          h += thumbnail(folder, i + 1 < files.size() ? files[i + 1] : "",
                         folder + " " + r.series[i].method, p);
      h += "</tr>";
    }
    h += "</table></div>\n";
  }
  return h;
}

const char* kDefinitions =
    "<p class=\"caption\">f(t) is the mean LDR-FLIP between frames t&minus;1 and t of one image "
    "sequence; <b>flicker</b> is its mean over t, <b>excess flicker</b> the mean of "
    "f<sub>method</sub>(t) &minus; f<sub>ground truth</sub>(t): how much more the method changes "
    "between frames than the exact image does (0 for a method that renders the ground truth). A "
    "lossy method's smoother image often changes less than the exact one, so its excess can be "
    "negative whatever its error does; the <b>error change</b> e(t), the mean over pixels and "
    "RGB of |(method<sub>t</sub> &minus; truth<sub>t</sub>) &minus; (method<sub>t&minus;1</sub> "
    "&minus; truth<sub>t&minus;1</sub>)| / 255, measures how much the error itself moves or pops "
    "(0 for an exact method). FLIP is each frame's mean FLIP against its ground truth, averaged "
    "over the frames. Lower is better everywhere; click a column's header to sort.</p>\n";

}  // namespace

std::string temporalReportHtml(const TemporalResult& r, const TemporalReportPage& p) {
  std::string h = report::pageStart("mfr compare &mdash; temporal stability, " + escape(p.scene));
  h += "<h1>Temporal stability along an orbit</h1>\n";
  h += "<p class=\"subtitle\">Scene <code>" + escape(p.scene) + "</code> &middot; " +
       format("%d&#8201;&times;&#8201;%d pixels &middot; %d frames", p.width, p.height, r.frames) +
       "</p>\n";
  h += setupTable(r, p);
  h += "<h2 id=\"summary\">2&ensp;Summary</h2>\n" + verdicts(r) + std::string(kDefinitions);
  h += summaryTable(r);
  h += plotsSection(r);
  h += framesSection(r, p);
  h += "<footer>Generated by " + escape(p.mfrVersion.empty() ? "mfr" : p.mfrVersion) +
       " <code>compare --orbit</code>. Every frame's images and report are in its "
       "folder.</footer>\n";
  return h + report::pageEnd();
}

}  // namespace mfr
