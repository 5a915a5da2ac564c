// Temporal stability along a camera path (issue 14, sec. 5): `mfr compare --orbit N` compares
// the methods on each of N views (runComparison per frame) and measures how much each method
// flickers from one frame to the next beyond what the scene itself changes:
//
//   f_X(t)   = mean LDR-FLIP between frames t-1 and t of X          (t = 1 .. N-1)
//   flicker  = mean over t of f_X(t)
//   excess   = mean over t of (f_method(t) - f_ground truth(t))     ("excess flicker")
//   e_X(t)   = mean over pixels and RGB of |(X_t - G_t) - (X_t-1 - G_t-1)| / 255
//   error change = mean over t of e_X(t)
//
// The ground truth's own f(t) is the change the camera motion causes; a method whose images are
// the ground truth's (the A-buffer, or any method with room for every fragment) has excess 0
// exactly, and a method whose error pattern jumps between frames has a positive excess. Excess
// flicker alone can mislead: a lossy method renders a smoother image, which changes less between
// frames than the exact one, so its excess is often negative however its error behaves. The error
// change measures the error itself: 0 for a method with no error or a fixed one, and large when
// the error pattern moves or pops (a changing k(p), screen-space noise over moving content). The
// images compared are the sRGB8 images as written, like every metric of mfr compare. Frames are
// added one at a time and only the previous frame's images are kept, so a long path costs the
// memory of two frames.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/compare/compare.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/result.hpp"
#include "mfr/scene/camera.hpp"

namespace mfr {

/// The camera path of `mfr compare --orbit N [--orbit-step DEG]`: N cameras rotated about the
/// camera's up axis through its target, view i by i * stepDegrees (scene/camera.hpp's orbit spaces
/// N views over the full circle; a path for flicker wants small steps).
std::vector<Camera> orbitPath(const Camera& camera, int views, float stepDegrees);

/// One method at one budget along the path.
struct TemporalSeries {
  std::string method;
  std::string budgetLabel;
  std::vector<double> consecutiveFlip;  // f(t) for t = 1 .. N-1; NaN where a frame failed
  std::vector<double> errorFlip;        // mean FLIP against the ground truth per frame; NaN: failed
  std::vector<double> errorChange;      // e(t) for t = 1 .. N-1; NaN where a frame failed
  double flicker = 0.0;          // mean of consecutiveFlip (NaN if any transition is missing)
  double excessFlicker = 0.0;    // mean of consecutiveFlip - the ground truth's (NaN likewise)
  double meanErrorChange = 0.0;  // mean of errorChange (NaN likewise)
  double meanFlip = 0.0;  // mean of errorFlip: the error against the ground truth (NaN likewise)
};

struct TemporalResult {
  int frames = 0;
  std::vector<double> groundTruthConsecutiveFlip;  // f_ground truth(t), t = 1 .. N-1
  double groundTruthFlicker = 0.0;
  std::vector<TemporalSeries> series;  // budgets in order, methods in order within a budget
};

/// Accumulates frames of one path. Every frame must have the methods and budgets of the first.
class TemporalStability {
 public:
  explicit TemporalStability(double flipPixelsPerDegree = kFlipDefaultPixelsPerDegree);
  /// Adds the next frame. Errors: a frame whose methods, budgets or size differ from the first.
  Result<void> add(const CompareResult& frame);
  /// The measures so far (flicker 0 with fewer than two frames).
  TemporalResult result() const;

 private:
  double ppd_;
  int frames_ = 0;
  int width_ = 0, height_ = 0;
  Image8 previousTruth_;
  std::vector<Image8> previous_;  // per series; empty: the run failed
  TemporalResult result_;
};

/// results.json's "temporal" object: frames, definition, ground_truth {consecutive_flip, flicker},
/// series [{method, budget_label, consecutive_flip, error_flip, error_change, flicker,
/// excess_flicker, mean_error_change, mean_flip}] (NaN as null).
nlohmann::json temporalToJson(const TemporalResult& result);

/// The temporal comparison's results.csv: a header (method, budget_label, frames, mean_flip,
/// flicker, excess_flicker, mean_error_change) and one row per series after the ground truth's
/// (method abuffer, empty budget, mean_flip and excess 0); a NaN is an empty field.
std::string temporalToCsv(const TemporalResult& result);

/// What a temporal plot draws over t.
enum class TemporalMeasure { ExcessFlicker, ErrorChange };

/// f_method(t) - f_ground truth(t) (ExcessFlicker) or e_method(t) (ErrorChange) over t for every
/// method at `budgetLabel` (one line each).
Result<Image8> temporalPlot(const TemporalResult& result, const std::string& budgetLabel,
                            TemporalMeasure measure = TemporalMeasure::ExcessFlicker);

/// What the temporal report shows besides the measures.
struct TemporalReportPage {
  std::string scene;
  int width = 0, height = 0;
  float stepDegrees = 0.0f;
  std::string commandLine, mfrVersion, generated;  // as ReportInfo
  std::vector<std::string> frameFolders;           // frame_000, ...: each holds its own report
  /// Per frame, file names relative to its folder: the ground truth's image, then each series'
  /// image (TemporalResult::series order; empty where the run failed).
  std::vector<std::vector<std::string>> frameImages;
};

/// A self-contained page in the style of the one-view report (shared CSS, sortable tables): the
/// set-up, per budget the steadiest and the most accurate method, the table (method, budget,
/// mean FLIP against the ground truth, flicker, excess flicker, error change), inline SVG plots
/// over the frames per budget (mean FLIP, excess flicker, error change) and the frames as images
/// linked to their own reports.
std::string temporalReportHtml(const TemporalResult& result, const TemporalReportPage& page);

}  // namespace mfr
