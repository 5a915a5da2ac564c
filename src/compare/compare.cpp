// mfr compare: the ground truth and every method at every budget, with image metrics, and the
// results as JSON and CSV (the HTML page is in report_html.cpp).
#include "mfr/compare/compare.hpp"

#include "mfr/method/pass_plan.hpp"
#include "mfr/method/peel.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "mfr/core/colormap.hpp"
#include "mfr/core/units.hpp"
#include "mfr/engine/scene_budgets.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/method/stats_json.hpp"
#include "mfr/metrics/image_metrics.hpp"

namespace mfr {
namespace {

// file-name safe form of a method name ("fkb+occupancy" -> "fkb-occupancy")
std::string fileStem(const std::string& name) {
  std::string s = name;
  for (char& c : s) {
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '-' || c == '_' || c == '.';
    if (!safe) c = '-';
  }
  return s;
}

Image8 colourMap(const std::vector<float>& values, int w, int h, float maxValue,
                 const std::string& title) {
  return colorMapWithLegend(values, w, h, std::max(maxValue, 1e-6f), title);
}

template <class T>
float maxOf(const std::vector<T>& values) {
  float m = 0.0f;
  for (const T& v : values) m = std::max(m, static_cast<float>(v));
  return m;
}

nlohmann::json finiteOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

const char* captureName(CaptureMode c) {
  return c == CaptureMode::TileOwned ? "tile" : "parallel";
}

nlohmann::json runToJson(const CompareRun& run) {
  nlohmann::json j;
  j["name"] = run.method;
  j["label"] = run.label;
  j["budget_bytes"] = run.budgetBytes ? nlohmann::json(*run.budgetBytes) : nlohmann::json(nullptr);
  j["compositing"] = toString(run.compositing);
  if (run.error) {
    j["error"] = *run.error;
    // the method's smallest budget on this frame (scene_budgets.hpp), where it has one
    j["minimum_bytes"] = run.minimumBytes ? nlohmann::json(*run.minimumBytes) : nlohmann::json();
    return j;
  }
  nlohmann::json stats = statsToJson(run.stats);
  stats.erase("method");
  stats.erase("budget_bytes");
  j.update(stats);
  j["repeats"] = run.timing.repeats;  // total_ms is the median render's; the spread beside it
  j["total_ms_median"] = run.timing.medianMs;
  j["total_ms_min"] = run.timing.minMs;
  j["total_ms_max"] = run.timing.maxMs;
  j["image"] = run.imageFile;
  if (!run.flipFile.empty()) j["flip_image"] = run.flipFile;
  if (!run.kMapFile.empty()) j["k_map_image"] = run.kMapFile;
  if (!run.importanceFile.empty()) j["importance_image"] = run.importanceFile;
  j["fm_slots"] = run.budgetBytes ? nlohmann::json(run.budgetSlots) : nlohmann::json(nullptr);
  j["memory_utilisation"] = run.memoryUtilisation();
  const CompareMetrics& m = run.metrics;
  j["mse"] = m.mseLinear;
  j["psnr"] = finiteOrNull(m.psnrLinear);
  j["mse_linear"] = m.mseLinear;
  j["psnr_linear"] = finiteOrNull(m.psnrLinear);
  j["mse_srgb"] = m.mseSrgb;
  j["psnr_srgb"] = finiteOrNull(m.psnrSrgb);
  j["flip_mean"] = m.flipMean;
  return j;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  q += '"';
  return q;
}

std::string number(double v, const char* format = "%.9g") {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, v);
  return buffer;
}

}  // namespace

double CompareRun::memoryUtilisation() const {
  const uint64_t slots = budgetBytes ? budgetSlots : stats.fragmentSlots;
  return slots ? static_cast<double>(stats.captured) / static_cast<double>(slots) : 0.0;
}

Result<void> checkComparisonFits(const Engine& engine, int width, int height,
                                 const CompareOptions& options) {
  auto abuffer = methodPreset("abuffer");
  if (!abuffer) return abuffer.error();
  RenderOptions ro;
  ro.capture = options.capture;
  ro.memoryLimitBytes = options.memoryLimitBytes;
  const Engine& truth =
      options.truthEngine && !options.truthFallback ? *options.truthEngine : engine;
  auto fits = truth.preflight(width, height, abuffer.value(), ro);
  if (!fits && options.truthEngine && options.truthFallback)
    fits = options.truthEngine->preflight(width, height, abuffer.value(), ro);
  if (!fits) return makeError("ground truth (abuffer): " + fits.error().message);
  return {};
}

Result<ComparedView> prepareComparedView(Engine& engine, const View& view,
                                         const CompareOptions& options) {
  ComparedView out;
  auto prepared = engine.prepare(view);
  if (!prepared) return prepared.error();
  out.view = std::move(prepared.value());
  if (options.truthEngine) {
    auto truth = options.truthEngine->prepare(view);
    if (!truth)
      return makeError("ground truth (" + std::string(options.truthEngine->name()) +
                       " engine): " + truth.error().message);
    out.truth = std::move(truth.value());
  }
  return out;
}

namespace {

// The rules `m` runs under: every one of `options.rules` for the k-buffer family (those its user
// model was trained for, with modelPicksRules) and for depth peeling bounded by --max-peels (its
// hybrid form blends what remains into a tail); its own rule otherwise.
std::vector<Compositing> methodRules(const MethodDesc& m, const CompareOptions& options) {
  // (the exact A-buffer keeps every fragment: a tail would only cost memory)
  const bool choice =
      (kBufferFamilyRule(m.compositing) && m.allocation != AllocationPolicy::Unbounded) ||
      (peelingRule(m.compositing) && m.maxPeels);
  if (!choice || options.rules.empty()) return {m.compositing};
  std::vector<Compositing> rules;
  for (const Compositing rule : options.rules) {
    MethodDesc variant = m;
    if (kBufferFamilyRule(m.compositing)) variant.compositing = rule;
    const bool userModel = options.model && checkMethodOption(MethodOption::Model, m);
    if (userModel && options.modelPicksRules && !checkModelForMethod(*options.model, "", variant))
      continue;
    rules.push_back(rule);
  }
  return rules;
}

}  // namespace

// The presets named in --methods, each under the comparison's rules, with its seed and model.
Result<std::vector<ComparedMethod>> comparedMethods(const CompareOptions& options) {
  std::vector<ComparedMethod> methods;
  std::set<std::string> seenMethods;
  for (const std::string& name : options.methods) {
    auto preset = methodPreset(name);
    if (!preset) return preset.error();
    if (!seenMethods.insert(name).second) return makeError("method '" + name + "': listed twice");
    MethodDesc m = preset.value();
    if (peelingRule(m.compositing)) m.maxPeels = options.maxPeels;  // --max-peels
    m.importance.seed = options.seed;
    m.model = options.model;
    const std::vector<Compositing> rules = methodRules(m, options);
    for (const Compositing rule : rules) {
      ComparedMethod& c = methods.emplace_back(ComparedMethod{m, name});
      // the peer methods (wboit, mboit, mlab, ...) keep their own rule (each run records it);
      // depth peeling's hybrid form blends what remains after its passes into a tail
      if (kBufferFamilyRule(m.compositing)) c.desc.compositing = rule;
      if (peelingRule(m.compositing)) c.desc.peelTail = rule == Compositing::Hybrid;
      if (rules.size() > 1) c.label += std::string("-") + toString(rule);
    }
  }
  return methods;
}

namespace {

// Every budget above zero and listed once.
Result<void> checkBudgetList(const std::vector<BudgetSpec>& budgets) {
  for (size_t i = 0; i < budgets.size(); ++i) {
    const BudgetSpec& b = budgets[i];
    if (b.bytes && *b.bytes == 0) return makeError("budget 0 B: must be at least 1 byte");
    if (!b.bytes && !(b.percent > 0.0 && std::isfinite(b.percent)))
      return makeError("budget " + b.label + ": a share must be above 0%");
    for (size_t j = 0; j < i; ++j)
      if (budgets[j] == b) return makeError("budget " + b.label + ": listed twice");
  }
  return {};
}

// Counts the steps (the ground truth, then one per run) for options.progress.
struct CompareProgress {
  const CompareOptions& options;
  int total;
  int step = 0;

  void report(const std::string& stage) const {
    if (options.progress) options.progress(stage, step, total);
  }
};

// Renders `method` options.warmup times untimed, then options.repeat times: the first timed
// render's output, with the passes of the median-time render and the spread of the totals.
Result<RenderOutput> timedRender(Engine& engine, const PreparedView& view, const MethodDesc& method,
                                 const RenderOptions& ro, const CompareOptions& options,
                                 RunTiming& timing) {
  for (int i = 0; i < options.warmup; ++i)
    if (auto warm = engine.render(view, method, ro); !warm) return warm.error();
  auto first = engine.render(view, method, ro);
  if (!first) return first.error();
  std::vector<std::pair<double, std::vector<PassTime>>> renders{
      {first->stats.totalMs(), first->stats.passes}};
  for (int i = 1; i < options.repeat; ++i) {
    auto again = engine.render(view, method, ro);
    if (!again) return again.error();
    renders.emplace_back(again->stats.totalMs(), std::move(again->stats.passes));
  }
  std::sort(renders.begin(), renders.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  const auto& median = renders[(renders.size() - 1) / 2];
  timing.repeats = static_cast<int>(renders.size());
  timing.medianMs = median.first;
  timing.minMs = renders.front().first;
  timing.maxMs = renders.back().first;
  first->stats.passes = median.second;
  return first;
}

// The ground truth on the truth engine (options.truthEngine with its view), or on the
// comparison's engine, falling back to the truth engine when that is only a fallback.
Result<RenderOutput> renderTruth(Engine& engine, const PreparedView& view,
                                 const PreparedView* truthView, const MethodDesc& abuffer,
                                 const RenderOptions& exact, const CompareOptions& options,
                                 CompareResult& result) {
  CompareRun& gt = result.groundTruth;
  const bool elsewhere = options.truthEngine && !options.truthFallback;
  Engine& first = elsewhere ? *options.truthEngine : engine;
  result.truthEngine = std::string(first.name());
  auto truth =
      timedRender(first, elsewhere ? *truthView : view, abuffer, exact, options, gt.timing);
  if (truth || !options.truthFallback || !options.truthEngine) return truth;
  result.truthNote = "ground truth on the " + std::string(options.truthEngine->name()) +
                     " engine: " + std::string(engine.name()) + ": " + truth.error().message;
  result.truthEngine = std::string(options.truthEngine->name());
  return timedRender(*options.truthEngine, *truthView, abuffer, exact, options, gt.timing);
}

// ground truth: the exact A-buffer, every fragment, sorted and composited
Result<void> renderGroundTruth(Engine& engine, const PreparedView& view,
                               const PreparedView* truthView, const RenderOptions& renderOptions,
                               const CompareOptions& options, CompareResult& result) {
  auto abuffer = methodPreset("abuffer");
  if (!abuffer) return abuffer.error();
  RenderOptions exact = renderOptions;  // multisampled: the per-sample A-buffer, box-filtered
  exact.sampleStorage = SampleStorage::Sample;
  auto truth = renderTruth(engine, view, truthView, abuffer.value(), exact, options, result);
  if (!truth) return makeError("ground truth (abuffer): " + truth.error().message);
  CompareRun& gt = result.groundTruth;
  gt.method = gt.label = "abuffer";
  gt.stats = std::move(truth->stats);
  gt.image = encodeSrgb(truth->image);
  gt.imageFile = "ground_truth.png";
  gt.metrics.psnrLinear = gt.metrics.psnrSrgb = psnrFromMse(0.0);
  result.depthComplexityMap =
      colourMap(std::vector<float>(truth->depthComplexity.begin(), truth->depthComplexity.end()),
                view.width(), view.height(), std::max(1.0f, maxOf(truth->depthComplexity)), "n(p)");
  result.depthComplexityFile = "ground_truth_depth_complexity.png";
  return {};
}

// What every run reads besides its method and budget.
struct RunSetting {
  Engine& engine;
  const PreparedView& view;
  const CompareOptions& options;
  const RenderOptions& renderOptions;
  const FrameCounts& counts;
  const std::string& sizeName;
  const Image8& truth;  // the ground truth, sRGB8
};

// One method at one budget: resolve the budget, render, measure against the ground truth and name
// the files. A budget or render failure is the run's error (an empty k map comes back); a failure
// to measure is the comparison's.
Result<std::vector<uint32_t>> compareOneRun(const RunSetting& s, const BudgetSpec& spec,
                                            const std::string& budgetLabel,
                                            const ComparedMethod& compared,
                                            const CompareProgress& progress, CompareRun& run) {
  const MethodDesc& method = compared.desc;
  run.method = method.name;
  run.label = compared.label;
  run.compositing = method.compositing;
  const MemoryModel memory = s.engine.memoryModel(method, s.renderOptions);
  const uint64_t storagePixels = s.view.storagePixels(sampleStorageOf(method, s.renderOptions));
  FrameCounts counts = s.counts;  // per-pixel words: per sample under per-sample storage
  counts.pixels = storagePixels;
  auto budget = resolveBudget(spec, method, memory, counts, s.sizeName);
  if (!budget) {
    run.error = budget.error().message;
    return std::vector<uint32_t>{};
  }
  run.budgetBytes = budget.value();
  run.budgetSlots = memory.fragmentSlots(budget.value(), storagePixels);
  progress.report("rendering " + run.label + " at " + budgetLabel);
  RenderOptions ro = s.renderOptions;
  ro.budgetBytes = budget.value();
  auto out = timedRender(s.engine, s.view, method, ro, s.options, run.timing);
  if (!out) {
    run.error = out.error().message;
    return std::vector<uint32_t>{};
  }
  run.stats = std::move(out->stats);
  run.image = encodeSrgb(out->image);
  progress.report("measuring " + run.label + " at " + budgetLabel);
  auto errors = compareImages(s.truth, run.image);
  if (!errors) return errors.error();
  auto flip = computeFlip(s.truth, run.image, s.options.flipPixelsPerDegree);
  if (!flip) return flip.error();
  run.metrics.mseLinear = errors->mseLinear;
  run.metrics.mseSrgb = errors->mseSrgb;
  run.metrics.psnrLinear = errors->psnrLinear;
  run.metrics.psnrSrgb = errors->psnrSrgb;
  run.metrics.flipMean = flip->mean;
  run.flipMap = flipErrorImage(*flip);
  const std::string stem = fileStem(run.label) + "_" + spec.fileLabel();
  run.imageFile = stem + ".png";
  run.flipFile = stem + "_flip.png";
  run.kMapFile = stem + "_kmap.png";
  if (!out->importance.importance.empty()) {
    run.importanceMap = colourMap(out->importance.importance, s.view.width(), s.view.height(),
                                  maxOf(out->importance.importance), "I(p)");
    run.importanceFile = stem + "_importance.png";
  }
  return std::move(out->kMap);
}

// the k maps of the successful runs, colour-mapped on one shared scale
void colourKMaps(const std::vector<std::vector<uint32_t>>& kMaps, int w, int h,
                 CompareResult& result) {
  size_t index = 0;
  for (CompareBudget& cb : result.budgets)
    for (CompareRun& run : cb.runs) {
      const std::vector<uint32_t>& k = kMaps[index++];
      if (!run.ok()) continue;
      run.kMap = colourMap(std::vector<float>(k.begin(), k.end()), w, h, result.kMapScale, "k(p)");
    }
}

// The scene's budget table (scene_budgets.hpp) of the compared methods, in their order.
Result<SceneBudgets> budgetTable(Engine& engine, const PreparedView& view,
                                 const std::vector<ComparedMethod>& methods,
                                 const RenderOptions& renderOptions) {
  std::vector<MethodDesc> descs;
  for (const ComparedMethod& m : methods) descs.push_back(m.desc);
  auto table = sceneBudgets(engine, view, descs, renderOptions);
  if (!table) return makeError("--budget auto: " + table.error().message);
  return table;
}

// A run refused at its budget: the method's smallest budget on this frame (`minimums`, counted
// once per run label), and the refusal naming it when the budget is below it.
void explainRefusal(const RunSetting& s, const ComparedMethod& method, const std::string& label,
                    std::map<std::string, std::optional<uint64_t>>& minimums, CompareRun& run) {
  auto found = minimums.find(method.label);
  if (found == minimums.end()) {
    auto row = methodBudget(s.engine, s.view, method.desc, s.renderOptions);
    std::optional<uint64_t> minimum;
    if (row) minimum = row->minimumBytes;
    found = minimums.emplace(method.label, minimum).first;
  }
  run.minimumBytes = found->second;
  // a share too small already names the smallest share that works (resolveBudget); a budget at
  // or above the minimum was refused for another reason
  if (!run.minimumBytes || !run.budgetBytes || *run.budgetBytes >= *run.minimumBytes) return;
  MethodBudget row;
  row.method = method.label;
  row.minimumBytes = run.minimumBytes;
  run.error = belowMinimumText(row, label, s.sizeName);
}

}  // namespace

Result<CompareResult> runComparison(Engine& engine, const PreparedView& view,
                                    const CompareOptions& options, const PreparedView* truthView) {
  if (options.truthEngine && !truthView)
    return makeError("runComparison: a truth engine needs the view prepared on it");
  if (options.repeat < 1 || options.warmup < 0)
    return makeError("runComparison: repeat must be at least 1 and warmup at least 0");
  if (options.methods.empty()) return makeError("--methods: the method list is empty");
  auto methods = comparedMethods(options);
  if (!methods) return methods.error();
  RenderOptions renderOptions;
  renderOptions.capture = options.capture;
  renderOptions.background = options.background;
  renderOptions.memoryLimitBytes = options.memoryLimitBytes;
  renderOptions.sampleStorage = options.sampleStorage;
  if (!options.previousNearestCosine.empty())
    renderOptions.previousNearestCosine = &options.previousNearestCosine;
  std::vector<BudgetSpec> budgets = options.budgets;
  // each run label's smallest budget on this frame: from --budget auto's table, else counted on
  // a label's first refusal (explainRefusal)
  std::map<std::string, std::optional<uint64_t>> minimums;
  if (options.autoBudgets) {  // log-spaced from the smallest minimum to the A-buffer's bytes
    auto table = budgetTable(engine, view, *methods, renderOptions);
    if (!table) return table.error();
    budgets = autoBudgets(table.value());
    if (budgets.empty())
      return makeError("--budget auto: none of the methods runs at any budget on this frame");
    for (size_t i = 0; i < methods->size(); ++i)
      minimums[(*methods)[i].label] = table->methods[i].minimumBytes;
  }
  if (budgets.empty()) return makeError("--budget: no budget given");
  MFR_TRY(checkBudgetList(budgets));
  const bool anyRelative = std::any_of(budgets.begin(), budgets.end(),
                                       [](const BudgetSpec& b) { return b.isRelative(); });
  MFR_TRY(checkFlipPixelsPerDegree(options.flipPixelsPerDegree));

  const int w = view.width(), h = view.height();
  CompareProgress progress{options, 1 + static_cast<int>(methods->size() * budgets.size())};

  CompareResult result;
  result.scene = options.scene;
  result.engine = std::string(engine.name());
  result.width = w;
  result.height = h;
  result.rules = options.rules;
  result.repeat = options.repeat;
  result.warmup = options.warmup;
  result.autoBudgets = options.autoBudgets;
  result.capture = options.capture;
  result.flipPixelsPerDegree = options.flipPixelsPerDegree;
  result.samples = view.samples();
  result.sampleStorage = options.sampleStorage;

  progress.report("rendering the ground truth (abuffer)");
  MFR_TRY(renderGroundTruth(engine, view, truthView, renderOptions, options, result));
  ++progress.step;
  // relative budgets: the A-buffer's node bytes of this frame (a count pass)
  FrameCounts counts;
  if (anyRelative) {
    auto n = engine.countFragments(view);
    if (!n) return makeError("count pass: " + n.error().message);
    counts = FrameCounts::of(n.value());
  }
  counts.pixels = view.pixelCount();  // each run's own storage pixels: compareOneRun
  const std::string sizeName = std::to_string(w) + "x" + std::to_string(h);
  const RunSetting setting{
      engine, view, options, renderOptions, counts, sizeName, result.groundTruth.image};

  std::vector<std::vector<uint32_t>> kMaps;  // per run, colour-mapped at the end (shared scale)
  float kScale = 1.0f;
  for (const BudgetSpec& spec : budgets) {
    CompareBudget& cb = result.budgets.emplace_back();
    cb.budgetBytes = spec.bytes ? *spec.bytes : relativeNodeBytes(spec.percent, counts);
    if (spec.isRelative()) cb.percent = spec.percent;
    cb.label = spec.label;
    for (const ComparedMethod& method : *methods) {
      CompareRun& run = cb.runs.emplace_back();
      auto kMap = compareOneRun(setting, spec, cb.label, method, progress, run);
      if (!kMap) return kMap.error();
      if (!run.ok()) explainRefusal(setting, method, cb.label, minimums, run);
      if (run.ok()) kScale = std::max(kScale, static_cast<float>(run.stats.kMax));
      kMaps.push_back(std::move(*kMap));
      ++progress.step;
    }
  }
  result.kMapScale = kScale;
  colourKMaps(kMaps, w, h, result);
  if (options.progress) options.progress("done", progress.total, progress.total);
  return result;
}

Result<void> checkSomeRunRan(const CompareResult& result) {
  const CompareRun* smallest = nullptr;  // the failed run of the smallest known minimum
  for (const CompareBudget& cb : result.budgets)
    for (const CompareRun& run : cb.runs) {
      if (run.ok()) return {};
      if (run.minimumBytes && (!smallest || *run.minimumBytes < *smallest->minimumBytes))
        smallest = &run;
    }
  if (result.budgets.empty() || result.budgets[0].runs.empty()) return {};
  std::string message = "no run succeeded: every method was refused at every budget";
  if (smallest)
    message += " (the smallest budget that runs: " + smallest->label + " at " +
               formatBytes(*smallest->minimumBytes) + "; mfr info --methods lists them all)";
  else
    message += " (" + *result.budgets[0].runs[0].error + ")";
  return makeError(message);
}

std::vector<BudgetSpec> budgetSpecs(const CompareResult& result) {
  std::vector<BudgetSpec> specs;
  for (const CompareBudget& cb : result.budgets) {
    BudgetSpec spec = cb.percent ? BudgetSpec::relative(*cb.percent) : BudgetSpec(cb.budgetBytes);
    spec.label = cb.label;
    specs.push_back(spec);
  }
  return specs;
}

SampleCountRuns sampleCountRuns(const CompareResult& result) {
  SampleCountRuns out;
  out.samples = result.samples;
  out.budgets = result.budgets;
  for (CompareBudget& cb : out.budgets)
    for (CompareRun& run : cb.runs) {
      run.image = run.flipMap = run.kMap = run.importanceMap = Image8{};
      run.imageFile = run.flipFile = run.kMapFile = run.importanceFile = {};
    }
  return out;
}

Result<void> addSampleCounts(Engine& engine, View view, const CompareOptions& options,
                             const std::vector<int>& counts, CompareResult& result) {
  for (const int count : counts) {
    if (count == result.samples) {
      result.sampleCounts.push_back(sampleCountRuns(result));
      continue;
    }
    const std::string what = "--sample-counts " + std::to_string(count) + ": ";
    view.samples = count;
    auto prepared = prepareComparedView(engine, view, options);
    if (!prepared) return makeError(what + prepared.error().message);
    CompareOptions o = options;
    o.budgets = budgetSpecs(result);  // --budget auto: the budgets the first count picked
    o.autoBudgets = false;
    if (options.progress)
      o.progress = [&options, count](const std::string& stage, int done, int total) {
        options.progress(std::to_string(count) + " samples: " + stage, done, total);
      };
    auto other = runComparison(engine, *prepared->view, o, prepared->truth.get());
    if (!other) return makeError(what + other.error().message);
    result.sampleCounts.push_back(sampleCountRuns(*other));
  }
  return {};
}

nlohmann::json compareToJson(const CompareResult& r, const std::string& mfrVersion) {
  nlohmann::json j;
  if (!mfrVersion.empty()) j["mfr_version"] = mfrVersion;
  j["scene"] = r.scene;
  j["engine"] = r.engine;
  j["truth_engine"] = r.truthEngine;
  if (!r.truthNote.empty()) j["truth_note"] = r.truthNote;
  j["width"] = r.width;
  j["height"] = r.height;
  // one rule: its name; several or none (each preset's own): "per-method", the rules listed
  j["compositing"] = r.rules.size() == 1 ? toString(r.rules[0]) : "per-method";
  nlohmann::json rules = nlohmann::json::array();
  for (const Compositing rule : r.rules) rules.push_back(toString(rule));
  j["compositing_rules"] = rules;
  j["repeat"] = r.repeat;
  j["budgets_auto"] = r.autoBudgets;
  j["warmup"] = r.warmup;
  j["capture"] = captureName(r.capture);
  j["cull"] = toString(r.groundTruth.stats.cull);  // every run rasterizes the same view
  j["flip_pixels_per_degree"] = r.flipPixelsPerDegree;
  j["samples"] = r.samples;
  j["sample_storage"] = toString(r.sampleStorage);
  j["budget_bytes"] =
      r.budgets.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.budgets[0].budgetBytes);
  nlohmann::json gt = runToJson(r.groundTruth);
  gt["depth_complexity_image"] = r.depthComplexityFile;
  j["ground_truth"] = gt;
  j["k_map_scale"] = r.kMapScale;
  nlohmann::json budgets = nlohmann::json::array();
  for (const CompareBudget& cb : r.budgets) {
    nlohmann::json runs = nlohmann::json::array();
    for (const CompareRun& run : cb.runs) runs.push_back(runToJson(run));
    nlohmann::json entry = {
        {"budget_bytes", cb.budgetBytes}, {"budget_label", cb.label}, {"methods", runs}};
    // relative: budget_bytes is the share's node bytes; each run's budget_bytes is its own M
    entry["budget_percent"] = cb.percent ? nlohmann::json(*cb.percent) : nlohmann::json(nullptr);
    budgets.push_back(entry);
  }
  j["methods"] = budgets.empty() ? nlohmann::json::array() : budgets[0]["methods"];
  j["budgets"] = budgets;
  if (!r.sampleCounts.empty()) {  // --sample-counts: the metrics and statistics per count
    nlohmann::json counts = nlohmann::json::array();
    for (const SampleCountRuns& sc : r.sampleCounts) {
      nlohmann::json perBudget = nlohmann::json::array();
      for (const CompareBudget& cb : sc.budgets) {
        nlohmann::json runs = nlohmann::json::array();
        for (const CompareRun& run : cb.runs) {
          nlohmann::json entry = runToJson(run);
          entry.erase("image");  // (no images at the other counts)
          runs.push_back(std::move(entry));
        }
        perBudget.push_back(
            {{"budget_bytes", cb.budgetBytes}, {"budget_label", cb.label}, {"methods", runs}});
      }
      counts.push_back({{"samples", sc.samples}, {"budgets", perBudget}});
    }
    j["sample_counts"] = counts;
  }
  return j;
}

namespace {

/// A pass name as part of a CSV column name: lower case letters and digits, every run of other
/// characters one '_' ("peel 1" -> "peel_1").
std::string columnIdentifier(const std::string& name) {
  std::string id;
  for (char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) && u < 0x80)
      id += static_cast<char>(std::tolower(u));
    else if (!id.empty() && id.back() != '_')
      id += '_';
  }
  while (!id.empty() && id.back() == '_') id.pop_back();
  return id.empty() ? "pass" : id;
}

}  // namespace

std::string compareToCsv(const CompareResult& r) {
  // pass columns: the union of the runs' pass names, in order of first appearance
  std::vector<std::string> passes;
  const auto addPasses = [&](const CompareRun& run) {
    for (const PassTime& p : run.stats.passes)
      if (std::find(passes.begin(), passes.end(), p.name) == passes.end()) passes.push_back(p.name);
  };
  addPasses(r.groundTruth);
  for (const CompareBudget& cb : r.budgets)
    for (const CompareRun& run : cb.runs) addPasses(run);

  // every column name a snake_case identifier: "time_peel_1_ms" for pass "peel 1" (two names
  // that would give one column get _2, _3, ...)
  std::ostringstream csv;
  csv << "budget_bytes,budget_label,method,label,compositing,status,image,bytes_used,fm_slots,"
         "fragment_slots,memory_utilisation,k_min,k_max,fragments_generated,fragments_captured,"
         "fragments_lost,fragments_lost_percent,mse,psnr,mse_linear,psnr_linear,mse_srgb,"
         "psnr_srgb,flip_mean,total_ms,repeats,total_ms_min,total_ms_max";
  std::vector<std::string> columns;
  for (const std::string& p : passes) {
    const std::string base = "time_" + columnIdentifier(p) + "_ms";
    std::string column = base;
    for (int n = 2; std::find(columns.begin(), columns.end(), column) != columns.end(); ++n)
      column = base + "_" + std::to_string(n);
    columns.push_back(column);
    csv << ',' << column;
  }
  csv << ",error\n";
  // budget_label: the budget as given ("20MB", "25%"), empty for the ground truth
  const auto row = [&](const CompareRun& run, const std::string& budgetLabel) {
    csv << (run.budgetBytes ? std::to_string(*run.budgetBytes) : std::string()) << ','
        << csvField(budgetLabel) << ',' << csvField(run.method) << ',' << csvField(run.label) << ','
        << toString(run.compositing) << ',';
    if (run.error) {
      csv << "error";
      for (size_t i = 0; i < 23 + passes.size(); ++i) csv << ',';
      csv << csvField(*run.error) << "\n";
      return;
    }
    const RenderStats& s = run.stats;
    const CompareMetrics& m = run.metrics;
    csv << "ok," << csvField(run.imageFile) << ',' << s.bytesUsed << ','
        << (run.budgetBytes ? std::to_string(run.budgetSlots) : std::string()) << ','
        << s.fragmentSlots << ',' << number(run.memoryUtilisation()) << ',' << s.kMin << ','
        << s.kMax << ',' << s.fragmentsGenerated << ',' << s.captured << ',' << s.lost << ','
        << number(s.lostPercent()) << ',' << number(m.mseLinear) << ',' << number(m.psnrLinear)
        << ',' << number(m.mseLinear) << ',' << number(m.psnrLinear) << ',' << number(m.mseSrgb)
        << ',' << number(m.psnrSrgb) << ',' << number(m.flipMean) << ','
        << number(s.totalMs(), "%.3f") << ',' << run.timing.repeats << ','
        << number(run.timing.minMs, "%.3f") << ',' << number(run.timing.maxMs, "%.3f");
    for (const std::string& p : passes) {
      csv << ',';
      for (const PassTime& t : s.passes)
        if (t.name == p) csv << number(t.ms, "%.3f");
    }
    csv << ",\n";
  };
  row(r.groundTruth, "");
  for (const CompareBudget& cb : r.budgets)
    for (const CompareRun& run : cb.runs) row(run, cb.label);
  return csv.str();
}

}  // namespace mfr
