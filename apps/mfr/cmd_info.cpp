// mfr info: what a scene is made of and what an exact A-buffer of it costs; with --methods, each
// method's smallest budget, the budget at which it keeps every fragment and its fixed memory
// (mfr/engine/scene_budgets.hpp).
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/compare/compare_request.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/engine/render_views.hpp"
#include "mfr/engine/scene_budgets.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/pass_plan.hpp"
#include "mfr/method/peel.hpp"

namespace mfr::cli {
namespace {

struct InfoArgs {
  SceneOptions scene;
  std::optional<std::string> methods;  // --methods LIST | all: the budget table
  std::string composite;               // --composite kbuffer|hybrid (k-buffer family)
  std::string capture = "tile";        // --capture tile|parallel
};

// --methods as compare takes it (compare_request.hpp: its presets, each under the rules of
// --composite, default both, labelled as compare's runs), or all; the rows' method is the label
Result<std::vector<ComparedMethod>> listedMethods(const InfoArgs& a, CaptureMode& capture) {
  CompareRequest request;
  request.methods = *a.methods == "all" ? presetNames() : splitCommaList(*a.methods);
  request.budgets = {"auto"};
  if (!a.composite.empty()) request.rules = splitCommaList(a.composite);
  request.capture = a.capture;
  request.seed = a.scene.seed;
  auto options = checkCompareRequest(request);
  if (!options) return options.error();
  capture = options->capture;
  return comparedMethods(options.value());
}

std::string bytesCell(const std::optional<uint64_t>& bytes) {
  return bytes ? formatBytes(*bytes) : std::string("-");
}

nlohmann::json bytesJson(const std::optional<uint64_t>& bytes) {
  return bytes ? nlohmann::json(*bytes) : nlohmann::json(nullptr);
}

nlohmann::json budgetsJson(const SceneBudgets& b) {
  nlohmann::json rows = nlohmann::json::array();
  for (const MethodBudget& r : b.methods)
    rows.push_back({{"method", r.method},
                    {"minimum_bytes", bytesJson(r.minimumBytes)},
                    {"minimum_percent", r.minimumPercent ? nlohmann::json(*r.minimumPercent)
                                                         : nlohmann::json(nullptr)},
                    {"exact_bytes", bytesJson(r.exactBytes)},
                    {"fixed_bytes", bytesJson(r.fixedBytes)},
                    {"note", r.note}});
  nlohmann::json autoList = nlohmann::json::array();
  for (const BudgetSpec& spec : autoBudgets(b)) autoList.push_back(spec.label);
  return {{"abuffer_bytes", b.abufferBytes},
          {"samples", b.samples},
          {"fragments", b.counts.fragments},
          {"covered_pixels", b.counts.coveredPixels},
          {"max_depth_complexity", b.maxDepthComplexity},
          {"mean_depth_complexity", b.meanDepthComplexity},
          {"methods", rows},
          {"auto_budgets", autoList}};
}

void printBudgets(const nlohmann::json& b) {
  std::string autoText;
  for (const auto& label : b["auto_budgets"])
    autoText += (autoText.empty() ? "" : ",") + label.get<std::string>();
  std::printf("  A-buffer %s (%llu B); auto budgets %s\n",
              formatBytes(b["abuffer_bytes"].get<uint64_t>()).c_str(),
              static_cast<unsigned long long>(b["abuffer_bytes"].get<uint64_t>()),
              autoText.empty() ? "-" : autoText.c_str());
  std::printf("  %-24s %-12s %-9s %-12s %-12s %s\n", "method", "minimum", "share", "exact at",
              "fixed", "note");
  for (const auto& r : b["methods"]) {
    const auto bytes = [&](const char* key) {
      return r[key].is_null() ? std::optional<uint64_t>() : r[key].get<uint64_t>();
    };
    std::string share = "-";
    if (!r["minimum_percent"].is_null()) {
      char buffer[32];
      std::snprintf(buffer, sizeof buffer, "%.2f%%", r["minimum_percent"].get<double>());
      share = r["minimum_percent"].get<double>() == 0.0 ? "any" : buffer;
    }
    std::printf("  %-24s %-12s %-9s %-12s %-12s %s\n", r["method"].get<std::string>().c_str(),
                bytesCell(bytes("minimum_bytes")).c_str(), share.c_str(),
                bytesCell(bytes("exact_bytes")).c_str(), bytesCell(bytes("fixed_bytes")).c_str(),
                oneLine(r["note"].get<std::string>(), 300).c_str());
  }
}

int run(const InfoArgs& a) {
  const SceneOptions& o = a.scene;
  std::vector<MethodDesc> methods;
  std::vector<std::string> labels;  // as compare labels the runs
  RenderOptions budgetOptions;
  if (a.methods) {
    auto listed = listedMethods(a, budgetOptions.capture);
    if (!listed) return fail(listed.error().message);
    for (ComparedMethod& m : listed.value()) {
      methods.push_back(std::move(m.desc));
      labels.push_back(std::move(m.label));
    }
    auto limit = o.memoryLimitBytes();
    if (!limit) return fail(limit.error().message);
    budgetOptions.memoryLimitBytes = limit.value();
    budgetOptions.sampleStorage = o.storage();
  } else if (!a.composite.empty() || a.capture != "tile") {
    return fail(std::string(a.composite.empty() ? "--capture" : "--composite") +
                ": applies to the budget table only (give --methods LIST)");
  }
  Progress progress(!o.quiet);
  progress.set("loading " + o.source);
  auto prepared = prepareScene(o);
  if (!prepared) return fail(prepared.error().message);
  const Scene& scene = prepared->scene;
  size_t blend = 0, mask = 0, opaque = 0;
  for (const Material& m : scene.materials)
    (m.alphaMode == AlphaMode::Blend ? blend : m.alphaMode == AlphaMode::Mask ? mask : opaque)++;
  nlohmann::json views = nlohmann::json::array();
  const MemoryModel abuffer = MemoryModel::of(methodPreset("abuffer").value());
  auto engine = makeSceneEngine(o);
  if (!engine) return fail(engine.error().message);
  // the variable k-buffer's previous frame (--orbit-view I: view I - 1), as render reads it
  std::vector<float> previousCosine;
  for (const MethodDesc& m : methods)
    if (m.allocation == AllocationPolicy::Importance &&
        m.importanceSource == ImportanceSource::Heuristic && previousCosine.empty()) {
      auto cosine = previousViewCosine(**engine, scene, o.source,
                                       {prepared->cameras, prepared->previousCamera}, o.width,
                                       o.height, o.sampleCount());
      if (!cosine) return fail(cosine.error().message);
      previousCosine = std::move(cosine.value());
    }
  if (!previousCosine.empty()) budgetOptions.previousNearestCosine = &previousCosine;
  for (size_t v = 0; v < prepared->cameras.size(); ++v) {
    progress.set("counting fragments", static_cast<int>(v),
                 static_cast<int>(prepared->cameras.size()));
    auto view = (*engine)->prepare(sceneView(*prepared, o, prepared->cameras[v]));
    if (!view) return fail(echoPath(o.source) + ": " + view.error().message);
    auto counted = (*engine)->countFragments(**view);
    if (!counted) return fail(echoPath(o.source) + ": " + counted.error().message);
    const std::vector<uint32_t>& n = counted.value();
    uint64_t total = 0, covered = 0;
    uint32_t maxN = 0;
    for (uint32_t c : n) {
      total += c;
      covered += c > 0;
      maxN = std::max(maxN, c);
    }
    const Camera& c = prepared->cameras[v];
    views.push_back(
        {{"view", v},
         {"camera",
          {{"eye", {c.eye.x, c.eye.y, c.eye.z}},
           {"target", {c.target.x, c.target.y, c.target.z}},
           {"up", {c.up.x, c.up.y, c.up.z}},
           {"fov", c.fovYDegrees}}},
         {"fragments", total},
         {"covered_pixels", covered},
         {"max_depth_complexity", maxN},
         {"mean_depth_complexity", covered ? double(total) / covered : 0.0},
         {"abuffer_bytes", abuffer.overhead((*view)->pixelCount()) + total * kNodeBytes}});
    if (a.methods) {
      progress.set("budgets", static_cast<int>(v), static_cast<int>(prepared->cameras.size()));
      auto budgets = sceneBudgets(**engine, **view, methods, budgetOptions);
      if (!budgets) return fail(echoPath(o.source) + ": " + budgets.error().message);
      for (size_t i = 0; i < labels.size(); ++i) budgets->methods[i].method = labels[i];
      views.back()["budgets"] = budgetsJson(budgets.value());
    }
  }
  // the file's cameras as --view N numbers them (fileCamera): the same list, the same index
  nlohmann::json fileCameras = nlohmann::json::array();
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    auto chosen = fileCamera(scene, o.source, static_cast<int>(i));
    const Camera& c = scene.cameras[i];
    nlohmann::json entry = {{"camera", i}};
    if (chosen)
      entry.update({{"eye", {c.eye.x, c.eye.y, c.eye.z}},
                    {"target", {c.target.x, c.target.y, c.target.z}},
                    {"up", {c.up.x, c.up.y, c.up.z}},
                    {"fov", c.fovYDegrees}});
    else
      entry["refused"] = oneLine(scene.cameraProblems[i], 300);
    fileCameras.push_back(entry);
  }
  nlohmann::json j = {{"scene", o.source},
                      {"triangles", scene.triangleCount()},
                      {"vertices", scene.vertexCount()},
                      {"materials", scene.materials.size()},
                      {"materials_blend", blend},
                      {"materials_mask", mask},
                      {"materials_opaque", opaque},
                      {"textures", scene.textures.size()},
                      {"cameras_in_file", scene.cameras.size()},
                      {"file_cameras", fileCameras},
                      {"width", o.width},
                      {"height", o.height},
                      {"engine", (*engine)->describe()},
                      {"views", views}};
  if (o.json) {
    std::printf("%s\n", jsonText(j).c_str());
    return 0;
  }
  if (o.quiet) return 0;
  progress.clear();
  std::printf("scene       %s\n", o.source.c_str());
  std::printf("triangles   %zu (%zu vertices)\n", scene.triangleCount(), scene.vertexCount());
  std::printf("materials   %zu (%zu blend, %zu mask, %zu opaque), %zu textures\n",
              scene.materials.size(), blend, mask, opaque, scene.textures.size());
  std::string engineText;
  for (const auto& [key, value] : (*engine)->describe())
    engineText += (engineText.empty() ? "" : ", ") + key + " " + value;
  std::printf("engine      %s\n", engineText.c_str());
  for (const auto& c : fileCameras)
    if (c.contains("refused"))
      std::printf("camera %-3d  --view %d refused: %s\n", c["camera"].get<int>(),
                  c["camera"].get<int>(), c["refused"].get<std::string>().c_str());
    else
      std::printf("camera %-3d  --view %d: eye %g, %g, %g, fov %g degrees\n",
                  c["camera"].get<int>(), c["camera"].get<int>(), c["eye"][0].get<double>(),
                  c["eye"][1].get<double>(), c["eye"][2].get<double>(), c["fov"].get<double>());
  for (const auto& v : views) {
    std::printf(
        "view %-3d    %dx%d: %llu fragments on %llu pixels, depth complexity max %u mean "
        "%.2f, A-buffer %s\n",
        v["view"].get<int>(), o.width, o.height,
        static_cast<unsigned long long>(v["fragments"].get<uint64_t>()),
        static_cast<unsigned long long>(v["covered_pixels"].get<uint64_t>()),
        v["max_depth_complexity"].get<uint32_t>(), v["mean_depth_complexity"].get<double>(),
        formatBytes(v["abuffer_bytes"].get<uint64_t>()).c_str());
    if (v.contains("budgets")) {
      std::printf("budgets     view %d at %dx%d, %d sample%s:\n", v["view"].get<int>(), o.width,
                  o.height, v["budgets"]["samples"].get<int>(),
                  v["budgets"]["samples"].get<int>() == 1 ? "" : "s");
      printBudgets(v["budgets"]);
    }
  }
  return 0;
}

}  // namespace

Runner addInfoCommand(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "Scene statistics, A-buffer cost and method budgets");
  args->scene.add(*cmd, true, true);
  cmd->add_option("--methods,-m", args->methods,
                  "Budget table of these methods (comma-separated, or all): each one's smallest "
                  "budget, the budget at which it keeps every fragment, its fixed memory. " +
                      presetHelp());
  cmd->add_option("--composite", args->composite,
                  "With --methods: the compositing rules, kbuffer, hybrid or both, as compare "
                  "runs them (default both: the methods that take a rule get a row per rule, "
                  "labelled as compare's runs, fkb-kbuffer, fkb-hybrid)");
  cmd->add_option("--capture", args->capture,
                  "With --methods: tile (default) or parallel, whose per-pixel lock words count");
  return [args] { return run(*args); };
}

}  // namespace mfr::cli
