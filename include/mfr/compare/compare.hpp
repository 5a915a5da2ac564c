// Side-by-side comparison of methods under memory budgets against the exact A-buffer: renders the
// ground truth once, then every method at every budget, and measures each image against the
// ground truth (MSE and PSNR on linear and on sRGB values, mean LDR-FLIP) together with the run's
// memory, fragment and timing statistics. Everything needed to write the images, results.json,
// results.csv and the HTML report is returned; nothing is printed or written here.
//
// Metrics are computed on the sRGB8 images exactly as they are written to PNG, so recomputing them
// from the files with the metrics API gives the same numbers.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/core/image.hpp"
#include "mfr/core/result.hpp"
#include "mfr/engine/engine.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/render_output.hpp"
#include "mfr/metrics/flip.hpp"

namespace mfr {

struct CompareOptions {
  std::vector<std::string> methods;  // preset names (methodPreset), at least one, no duplicates
  /// At least one, no duplicates; budgets[0] is "the" budget. Bytes, or shares of the exact
  /// A-buffer's node bytes ("30%", budget_spec.hpp: each method's own words on top).
  std::vector<BudgetSpec> budgets;
  /// The compositing rules to run the methods that take a choice under (kbuffer, hybrid: the
  /// k-buffer family, and depth peeling with maxPeels, whose hybrid form blends what remains into
  /// a tail): each such method runs once per rule, the oracle (optimal) too, so that it is the
  /// proven minimum of the rule printed beside it. Empty: each preset's own rule (hybrid for dkb*,
  /// optimal*; kbuffer for the others). The peer methods (wboit, mboit, mlab, ...) run once under
  /// their own rule. CompareRequest's default is both rules.
  std::vector<Compositing> rules;
  /// Deep k-buffer methods with a user model (`model`): run only under the rules the model was
  /// trained for instead of refusing the others (the default rule set of CompareRequest).
  bool modelPicksRules = false;
  /// Timing: each run is rendered `warmup` times untimed, then `repeat` times; the run keeps the
  /// first timed render's image and statistics with the passes of the median-time render
  /// (RunTiming). The ground truth too.
  int repeat = 1;
  int warmup = 0;
  /// The engine the ground truth is rendered on (--truth-engine); null: the comparison's engine.
  /// runComparison then takes the truth's view prepared on it. With truthFallback, truthEngine
  /// renders the truth only when the comparison's engine cannot (a GPU's limits refuse the
  /// A-buffer): CompareResult::truthNote says so.
  Engine* truthEngine = nullptr;
  bool truthFallback = false;
  /// `--budget auto`: `budgets` is chosen from the scene (autoBudgetSpecs) before the runs.
  bool autoBudgets = false;
  /// Depth peeling (peel, dual-peel): --max-peels, at most this many geometry passes (none: until
  /// no fragment remains); under hybrid compositing what remains goes to a tail.
  std::optional<uint32_t> maxPeels;
  CaptureMode capture = CaptureMode::TileOwned;
  glm::vec3 background{1.0f};  // linear RGB
  std::string scene;           // the scene's name or source, for the results
  double flipPixelsPerDegree = kFlipDefaultPixelsPerDegree;
  /// Importance methods (vkb, vkb-fill): seed of the noise term (Eq. 6).
  uint64_t seed = 1;
  /// Variable k-buffer methods: the previous frame's nearest |n.v| (nearestCosine()); empty: this
  /// frame's own.
  std::vector<float> previousNearestCosine;
  /// Deep k-buffer methods (dkb, dkb-fill): the network (null: the built-in model).
  std::shared_ptr<const learn::Model> model;
  /// Called before each step: (what, steps done, steps in all). May be empty.
  std::function<void(const std::string& stage, int done, int total)> progress;
  /// Memory pre-flight of every render (RenderOptions::memoryLimitBytes); none: the default.
  std::optional<uint64_t> memoryLimitBytes;
  /// Multisampled views: how every method stores the samples (the ground truth: per sample).
  SampleStorage sampleStorage = SampleStorage::Pixel;
};

/// Error of one image against the ground truth (both sRGB8 as written).
struct CompareMetrics {
  double mseLinear = 0.0;   // on decoded linear-light values in [0, 1]
  double mseSrgb = 0.0;     // on sRGB code / 255
  double psnrLinear = 0.0;  // dB, peak 1; +infinity when the MSE is 0
  double psnrSrgb = 0.0;
  double flipMean = 0.0;  // mean LDR-FLIP
};

/// The wall-clock spread of a run's timed renders (CompareOptions::repeat, after the warm-up).
struct RunTiming {
  int repeats = 1;
  double medianMs = 0.0;  // of the renders' totals (the lower median of an even count)
  double minMs = 0.0, maxMs = 0.0;
};

/// One method at one budget (or the ground truth).
struct CompareRun {
  std::string method;  // preset name
  /// What the run is called in tables and files: the preset name, or "NAME-RULE" ("fkb-hybrid")
  /// when the comparison runs the method under several compositing rules.
  std::string label;
  std::optional<uint64_t> budgetBytes;             // none for the ground truth
  Compositing compositing = Compositing::KBuffer;  // the rule this run composited with
  std::optional<std::string> error;  // the render failed (e.g. budget too small): no data below
  /// A failed run: the method's smallest budget on this frame (methodBudget), none where it has
  /// none; the error names it when the budget was below it.
  std::optional<uint64_t> minimumBytes;
  RenderStats stats;  // passes: the median-time render's
  RunTiming timing;
  uint64_t budgetSlots = 0;  // F(M) of the method's memory model (0 without a budget)
  CompareMetrics metrics;
  // images (sRGB8, as written), file names relative to the output folder
  Image8 image, flipMap, kMap, importanceMap;  // importanceMap: importance methods only
  std::string imageFile, flipFile, kMapFile, importanceFile;

  bool ok() const { return !error; }
  /// captured / F(M); captured / allocated slots when there is no budget.
  double memoryUtilisation() const;
};

struct CompareBudget {
  /// Absolute: the budget. Relative: the node bytes of the share (relativeNodeBytes), the same for
  /// every method; each run's budgetBytes adds that method's own per-pixel and per-image words.
  uint64_t budgetBytes = 0;
  std::optional<double> percent;  // relative budgets: the share, in percent
  std::string label;              // "20MB", "400KB", "1000B", "25%"
  std::vector<CompareRun> runs;   // in CompareOptions::methods order
};

/// `mfr compare --sample-counts`: the same methods and budgets at one sample count, each run
/// against that count's own ground truth (the per-sample A-buffer, box-filtered), for the report's
/// error against bytes per pixel per sample count. The runs keep their statistics and metrics,
/// not their images.
struct SampleCountRuns {
  int samples = 1;
  std::vector<CompareBudget> budgets;  // as CompareResult::budgets
};

struct CompareResult {
  std::string scene;
  std::string engine;       // the engine that rendered every run
  std::string truthEngine;  // the engine that rendered the ground truth
  std::string truthNote;    // why the truth ran on a fallback engine (empty: it did not)
  int width = 0, height = 0;
  std::vector<Compositing> rules;  // CompareOptions::rules (empty: each preset's own)
  int repeat = 1, warmup = 0;      // CompareOptions::repeat, warmup
  bool autoBudgets = false;        // the budgets were picked from the scene (--budget auto)
  CaptureMode capture = CaptureMode::TileOwned;
  int samples = 1;  // per pixel (View::samples)
  SampleStorage sampleStorage = SampleStorage::Pixel;
  double flipPixelsPerDegree = kFlipDefaultPixelsPerDegree;
  CompareRun groundTruth;     // abuffer, no budget, metrics against itself (all 0, PSNR infinite)
  Image8 depthComplexityMap;  // colour-mapped n(p) with legend
  std::string depthComplexityFile;
  float kMapScale = 1.0f;              // the k-maps share one colour scale, 0 .. kMapScale
  std::vector<CompareBudget> budgets;  // in CompareOptions::budgets order
  /// --sample-counts: every count asked for, in order (the one of `samples` is these budgets' runs)
  std::vector<SampleCountRuns> sampleCounts;
};

/// One run of a comparison's method list: a preset under one compositing rule.
struct ComparedMethod {
  MethodDesc desc;    // the preset with the rule, --max-peels, seed and model of the options
  std::string label;  // CompareRun::label: the name, or "NAME-RULE" under several rules
};

/// options.methods, each under the rules it runs under (CompareOptions::rules), in the order of
/// a budget's runs. Errors: an unknown or duplicated method.
Result<std::vector<ComparedMethod>> comparedMethods(const CompareOptions& options);

/// A comparison in which no method ran at any budget is an error for its caller (mfr compare
/// exits 1, mfr.compare raises, once the folder with the refusals is written): one line naming
/// the smallest budget that runs among the failed runs.
Result<void> checkSomeRunRan(const CompareResult& result);

/// The budgets `result` ran at, as specs (after --budget auto: the ones it picked).
std::vector<BudgetSpec> budgetSpecs(const CompareResult& result);

/// The runs of `result` without their images (what SampleCountRuns keeps).
SampleCountRuns sampleCountRuns(const CompareResult& result);

/// `--sample-counts`: `result` (a comparison of `view`) again at each of `counts` (1, 2, 4, 8, no
/// repeats: the CLI and Python check them), each against that count's own ground truth, into
/// result.sampleCounts in order; the count result.samples has reuses result's runs. Errors: the
/// engine cannot prepare a count (e.g. the GL engine on a driver without it) or a failed ground
/// truth, naming the count.
Result<void> addSampleCounts(Engine& engine, View view, const CompareOptions& options,
                             const std::vector<int>& counts, CompareResult& result);

/// Renders the ground truth and every method at every budget. Errors: an empty method or budget
/// list, an unknown or duplicated method, a duplicated or zero budget, or a failed ground truth.
/// A method failing at a budget is not an error: its run carries the message.
/// The result owns its images and statistics: the frame (and its scene) may go once it returns.
/// compare_output.hpp writes the result as `mfr compare` does (writeComparison).
/// With options.truthEngine, `truthView` is the same View prepared on it (prepareComparedView).
Result<CompareResult> runComparison(Engine& engine, const PreparedView& view,
                                    const CompareOptions& options,
                                    const PreparedView* truthView = nullptr);

/// A view prepared for runComparison: on the comparison's engine, and on the truth engine when
/// options.truthEngine is set.
struct ComparedView {
  std::unique_ptr<PreparedView> view, truth;
};
Result<ComparedView> prepareComparedView(Engine& engine, const View& view,
                                         const CompareOptions& options);

/// The memory pre-flight of runComparison that the image size alone decides: the ground truth's
/// (the A-buffer's) per-pixel buffers at width x height on `engine` (Engine::preflight), against
/// options.memoryLimitBytes. Checked before the view is prepared, so that a comparison that
/// cannot fit fails before the scene is set up.
Result<void> checkComparisonFits(const Engine& engine, int width, int height,
                                 const CompareOptions& options);

/// results.json: scene, width, height, compositing, capture, flip_pixels_per_degree,
/// budget_bytes (the first budget), ground_truth {name, image, depth_complexity_image, ...stats},
/// methods (the first budget's runs), budgets [{budget_bytes, budget_label, methods}], and each
/// run's keys (see docs/COMPARE.md). `mfrVersion` is recorded as mfr_version when not empty.
nlohmann::json compareToJson(const CompareResult& result, const std::string& mfrVersion = "");

/// results.csv: a header and one row per run (ground truth first), budgets in order. Every column
/// name is a snake_case identifier ([a-z0-9_]): budget_bytes, budget_label (the budget as given:
/// "20MB", "25%"; empty for the ground truth), ..., total_ms, time_PASS_ms per pass (the pass name
/// in lower case, other characters as '_': "peel 1" -> time_peel_1_ms), error.
std::string compareToCsv(const CompareResult& result);

struct ReportInfo {
  std::string mfrVersion;   // "mfr 0.1.0"
  std::string commandLine;  // as typed, shown verbatim
  std::string generated;    // optional date/time text
};

/// The HTML page (inline CSS, inline SVG plots, one small inline script for sortable tables and
/// image wipers, no external resources; the images are the PNG files beside it): the
/// recommendation per budget, the Pareto fronts, the results tables, the worst regions and, with
/// several budgets, error vs budget plots.
std::string compareReportHtml(const CompareResult& result, const ReportInfo& info);

}  // namespace mfr
