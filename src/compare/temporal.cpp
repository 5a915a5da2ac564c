// Temporal stability along a camera path (issue 14, sec. 5; see mfr/compare/temporal.hpp):
// consecutive-frame FLIP of each method against that of the ground truth, and the change of each
// method's per-pixel error from frame to frame.
#include "mfr/compare/temporal.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "mfr/core/plot.hpp"
#include "mfr/metrics/flip.hpp"

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

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string cell(double x, const char* format = "%.4f") {
  if (!std::isfinite(x)) return "n/a";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
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
      "images; mean_error_change = its mean over t";
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
                      {"mean_error_change", number(s.meanErrorChange)}});
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

std::string temporalReportHtml(const TemporalResult& r, const std::string& scene, int width,
                               int height, const std::vector<std::string>& plotFiles,
                               const std::vector<std::string>& frameFolders,
                               const std::string& commandLine) {
  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>mfr compare: temporal stability</title>\n<style>body{font-family:sans-serif;"
      "margin:2em;max-width:70em}table{border-collapse:collapse}td,th{border:1px solid #ccc;"
      "padding:2px 8px;text-align:right}td:first-child,td:nth-child(2){text-align:left}"
      "</style>\n</head>\n<body>\n";
  h += "<h1>Temporal stability</h1>\n<p>Scene <code>" + escape(scene) + "</code>, " +
       std::to_string(width) + "&times;" + std::to_string(height) + ", " +
       std::to_string(r.frames) + " frames along the orbit. Command: <code>" + escape(commandLine) +
       "</code></p>\n";
  h += "<p>f(t) is the mean LDR-FLIP between frames t&minus;1 and t of one image sequence; "
       "<b>flicker</b> is its mean over t, <b>excess flicker</b> the mean of f<sub>method</sub>(t) "
       "&minus; f<sub>ground truth</sub>(t): how much more the method changes between frames "
       "than the exact image does (0 for a method that renders the ground truth). The ground "
       "truth's flicker is " +
       cell(r.groundTruthFlicker) +
       ". A lossy method's smoother image often changes less than the exact one, so its excess "
       "can be negative whatever its error does; the <b>error change</b> e(t), the mean over "
       "pixels and RGB of |(method<sub>t</sub> &minus; truth<sub>t</sub>) &minus; "
       "(method<sub>t&minus;1</sub> &minus; truth<sub>t&minus;1</sub>)| / 255, measures how much "
       "the error itself moves or pops (0 for an exact method).</p>\n";
  h += "<table>\n<tr><th>method</th><th>budget</th><th>flicker</th><th>excess flicker</th>"
       "<th>error change</th><th>mean FLIP vs ground truth</th></tr>\n";
  for (const TemporalSeries& s : r.series)
    h += "<tr><td><code>" + escape(s.method) + "</code></td><td>" + escape(s.budgetLabel) +
         "</td><td>" + cell(s.flicker) + "</td><td>" + cell(s.excessFlicker) + "</td><td>" +
         cell(s.meanErrorChange) + "</td><td>" + cell(meanOf(s.errorFlip)) + "</td></tr>\n";
  h += "</table>\n";
  for (const std::string& plot : plotFiles)
    h += "<figure><img src=\"" + escape(plot) + "\" alt=\"temporal measure over the frames\">" +
         "</figure>\n";
  h += "<h2>Frames</h2>\n<ul>\n";
  for (const std::string& f : frameFolders)
    h += "<li><a href=\"" + escape(f) + "/report.html\">" + escape(f) + "</a></li>\n";
  h += "</ul>\n</body>\n</html>\n";
  return h;
}

}  // namespace mfr
