// mfr compare: the ground truth and every method at every budget, with image metrics, and the
// results as JSON and CSV (the HTML page is in report_html.cpp).
#include "mfr/compare/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "mfr/core/colormap.hpp"
#include "mfr/method/memory_model.hpp"
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
  j["budget_bytes"] = run.budgetBytes ? nlohmann::json(*run.budgetBytes) : nlohmann::json(nullptr);
  j["compositing"] = toString(run.compositing);
  if (run.error) {
    j["error"] = *run.error;
    return j;
  }
  nlohmann::json stats = statsToJson(run.stats);
  stats.erase("method");
  stats.erase("budget_bytes");
  j.update(stats);
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
  if (auto fits = engine.preflight(width, height, abuffer.value(), ro); !fits)
    return makeError("ground truth (abuffer): " + fits.error().message);
  return {};
}

Result<CompareResult> runComparison(Engine& engine, const PreparedView& view,
                                    const CompareOptions& options) {
  if (options.methods.empty()) return makeError("--methods: the method list is empty");
  if (options.budgets.empty()) return makeError("--budget: no budget given");
  std::vector<MethodDesc> methods;
  std::set<std::string> seenMethods;
  for (const std::string& name : options.methods) {
    auto preset = methodPreset(name);
    if (!preset) return preset.error();
    if (!seenMethods.insert(name).second) return makeError("method '" + name + "': listed twice");
    MethodDesc m = preset.value();
    // --composite chooses between the k-buffer family's rules; the peer methods (wboit, mboit,
    // mlab) keep their own (each run records the rule it used)
    if (options.compositing && kBufferFamilyRule(m.compositing))
      m.compositing = *options.compositing;
    m.importance.seed = options.seed;
    m.model = options.model;
    methods.push_back(m);
  }
  bool anyRelative = false;
  for (size_t i = 0; i < options.budgets.size(); ++i) {
    const BudgetSpec& b = options.budgets[i];
    if (b.bytes && *b.bytes == 0) return makeError("budget 0 B: must be at least 1 byte");
    if (!b.bytes && !(b.percent > 0.0 && std::isfinite(b.percent)))
      return makeError("budget " + b.label + ": a share must be above 0%");
    for (size_t j = 0; j < i; ++j)
      if (options.budgets[j] == b) return makeError("budget " + b.label + ": listed twice");
    anyRelative = anyRelative || b.isRelative();
  }
  if (!(options.flipPixelsPerDegree > 0.0 && std::isfinite(options.flipPixelsPerDegree)))
    return makeError("FLIP pixels per degree: must be finite and positive");

  const int w = view.width(), h = view.height();
  const uint64_t pixels = view.pixelCount();
  const int totalSteps = 1 + static_cast<int>(methods.size() * options.budgets.size());
  int step = 0;
  const auto progress = [&](const std::string& stage) {
    if (options.progress) options.progress(stage, step, totalSteps);
  };

  CompareResult result;
  result.scene = options.scene;
  result.engine = std::string(engine.name());
  result.width = w;
  result.height = h;
  result.compositing = options.compositing;
  result.capture = options.capture;
  result.flipPixelsPerDegree = options.flipPixelsPerDegree;

  RenderOptions renderOptions;
  renderOptions.capture = options.capture;
  renderOptions.background = options.background;
  renderOptions.memoryLimitBytes = options.memoryLimitBytes;
  if (!options.previousNearestCosine.empty())
    renderOptions.previousNearestCosine = &options.previousNearestCosine;

  // ground truth: the exact A-buffer, every fragment, sorted and composited
  progress("rendering the ground truth (abuffer)");
  auto abuffer = methodPreset("abuffer");
  if (!abuffer) return abuffer.error();
  auto truth = engine.render(view, abuffer.value(), renderOptions);
  if (!truth) return makeError("ground truth (abuffer): " + truth.error().message);
  ++step;
  CompareRun& gt = result.groundTruth;
  gt.method = "abuffer";
  gt.stats = std::move(truth->stats);
  gt.image = encodeSrgb(truth->image);
  gt.imageFile = "ground_truth.png";
  gt.metrics.psnrLinear = gt.metrics.psnrSrgb = psnrFromMse(0.0);
  result.depthComplexityMap =
      colourMap(std::vector<float>(truth->depthComplexity.begin(), truth->depthComplexity.end()), w,
                h, std::max(1.0f, maxOf(truth->depthComplexity)), "n(p)");
  result.depthComplexityFile = "ground_truth_depth_complexity.png";
  truth = Error{};  // release the frame-sized buffers
  // relative budgets: the A-buffer's node bytes of this frame (a count pass)
  FrameCounts counts;
  counts.pixels = pixels;
  if (anyRelative) {
    auto n = engine.countFragments(view);
    if (!n) return makeError("count pass: " + n.error().message);
    counts = FrameCounts::of(n.value());
  }
  const std::string sizeName = std::to_string(w) + "x" + std::to_string(h);

  std::vector<std::vector<uint32_t>> kMaps;  // per run, colour-mapped at the end (shared scale)
  float kScale = 1.0f;
  for (const BudgetSpec& spec : options.budgets) {
    CompareBudget& cb = result.budgets.emplace_back();
    cb.budgetBytes = spec.bytes ? *spec.bytes : relativeNodeBytes(spec.percent, counts);
    if (spec.isRelative()) cb.percent = spec.percent;
    cb.label = spec.label;
    for (const MethodDesc& method : methods) {
      CompareRun& run = cb.runs.emplace_back();
      run.method = method.name;
      run.compositing = method.compositing;
      const MemoryModel memory =
          MemoryModel::of(method, options.capture == CaptureMode::FragmentParallel);
      auto budget = resolveBudget(spec, method, memory, counts, sizeName);
      if (!budget) {
        run.error = budget.error().message;
        kMaps.emplace_back();
        ++step;
        continue;
      }
      run.budgetBytes = budget.value();
      run.budgetSlots = memory.fragmentSlots(budget.value(), pixels);
      progress("rendering " + method.name + " at " + cb.label);
      RenderOptions ro = renderOptions;
      ro.budgetBytes = budget.value();
      auto out = engine.render(view, method, ro);
      if (!out) {
        run.error = out.error().message;
        kMaps.emplace_back();
        ++step;
        continue;
      }
      run.stats = std::move(out->stats);
      run.image = encodeSrgb(out->image);
      progress("measuring " + method.name + " at " + cb.label);
      auto errors = compareImages(gt.image, run.image);
      if (!errors) return errors.error();
      auto flip = computeFlip(gt.image, run.image, options.flipPixelsPerDegree);
      if (!flip) return flip.error();
      run.metrics.mseLinear = errors->mseLinear;
      run.metrics.mseSrgb = errors->mseSrgb;
      run.metrics.psnrLinear = errors->psnrLinear;
      run.metrics.psnrSrgb = errors->psnrSrgb;
      run.metrics.flipMean = flip->mean;
      run.flipMap = flipErrorImage(*flip);
      const std::string stem = fileStem(method.name) + "_" + spec.fileLabel();
      run.imageFile = stem + ".png";
      run.flipFile = stem + "_flip.png";
      run.kMapFile = stem + "_kmap.png";
      if (!out->importance.importance.empty()) {
        run.importanceMap =
            colourMap(out->importance.importance, w, h, maxOf(out->importance.importance), "I(p)");
        run.importanceFile = stem + "_importance.png";
      }
      kScale = std::max(kScale, static_cast<float>(run.stats.kMax));
      kMaps.push_back(std::move(out->kMap));
      ++step;
    }
  }
  result.kMapScale = kScale;
  size_t index = 0;
  for (CompareBudget& cb : result.budgets)
    for (CompareRun& run : cb.runs) {
      const std::vector<uint32_t>& k = kMaps[index++];
      if (!run.ok()) continue;
      run.kMap = colourMap(std::vector<float>(k.begin(), k.end()), w, h, kScale, "k(p)");
    }
  if (options.progress) options.progress("done", totalSteps, totalSteps);
  return result;
}

nlohmann::json compareToJson(const CompareResult& r, const std::string& mfrVersion) {
  nlohmann::json j;
  if (!mfrVersion.empty()) j["mfr_version"] = mfrVersion;
  j["scene"] = r.scene;
  j["engine"] = r.engine;
  j["width"] = r.width;
  j["height"] = r.height;
  j["compositing"] = r.compositing ? toString(*r.compositing) : "per-method";
  j["capture"] = captureName(r.capture);
  j["flip_pixels_per_degree"] = r.flipPixelsPerDegree;
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
  return j;
}

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

  std::ostringstream csv;
  csv << "budget_bytes,method,compositing,status,image,bytes_used,fm_slots,fragment_slots,"
         "memory_utilisation,k_min,k_max,fragments_generated,fragments_captured,fragments_lost,"
         "fragments_lost_percent,mse,psnr,mse_linear,psnr_linear,mse_srgb,psnr_srgb,flip_mean,"
         "total_ms";
  for (const std::string& p : passes) csv << ",time_" << p << "_ms";
  csv << ",error\n";
  const auto row = [&](const CompareRun& run) {
    csv << (run.budgetBytes ? std::to_string(*run.budgetBytes) : std::string()) << ','
        << csvField(run.method) << ',' << toString(run.compositing) << ',';
    if (run.error) {
      csv << "error";
      for (size_t i = 0; i < 20 + passes.size(); ++i) csv << ',';
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
        << number(s.totalMs(), "%.3f");
    for (const std::string& p : passes) {
      csv << ',';
      for (const PassTime& t : s.passes)
        if (t.name == p) csv << number(t.ms, "%.3f");
    }
    csv << ",\n";
  };
  row(r.groundTruth);
  for (const CompareBudget& cb : r.budgets)
    for (const CompareRun& run : cb.runs) row(run);
  return csv.str();
}

}  // namespace mfr
