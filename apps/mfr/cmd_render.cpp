// mfr render: one method on a scene, with images, maps and statistics.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/core/atomic_file.hpp"
#include "mfr/core/colormap.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/method/stats_json.hpp"

namespace mfr::cli {
namespace {

struct RenderArgs {
  SceneOptions scene;
  std::string out = "mfr.png";
  std::string depthComplexity;
  std::string kMap;
  std::string statsJson;
  std::string method = "abuffer";
  std::string budget;
  std::optional<uint32_t> k;
  std::string composite;  // empty: the preset's own rule
  int occupancyD = 1;
  std::string capture = "tile";
  // variable k-buffer
  std::string importanceMap;
  std::string importanceFactors;
  std::string model;  // deep k-buffer
  ImportanceParams importance;
  std::vector<double> fovea;
  bool noDepthTerm = false, noPeripheryTerm = false, noFresnelTerm = false, noNoise = false;
  const CLI::App* command = nullptr;  // which options were given
  bool given(const char* flag) const { return command->count(flag) > 0; }
};

// An option given for a method it does not apply to is an error, not silently ignored.
Result<void> checkApplicable(const RenderArgs& a, const MethodDesc& m) {
  const std::pair<const char*, MethodOption> flags[] = {
      {"--k", MethodOption::K},
      {"--occupancy-d", MethodOption::OccupancyD},
      {"--model", MethodOption::Model},
      {"--importance-map", MethodOption::ImportanceMap},
      {"--importance-factors", MethodOption::ImportanceParams},
      {"--importance-alpha", MethodOption::ImportanceParams},
      {"--n-limit", MethodOption::ImportanceParams},
      {"--periphery-d", MethodOption::ImportanceParams},
      {"--fovea", MethodOption::ImportanceParams},
      {"--noise", MethodOption::ImportanceParams},
      {"--no-depth-term", MethodOption::ImportanceParams},
      {"--no-periphery-term", MethodOption::ImportanceParams},
      {"--no-fresnel-term", MethodOption::ImportanceParams},
      {"--no-noise", MethodOption::ImportanceParams},
      {"--composite", MethodOption::Composite}};
  for (const auto& [flag, option] : flags)
    if (a.given(flag))
      if (auto ok = checkMethodOption(option, m, flag); !ok) return ok.error();
  return {};
}

Result<MethodDesc> buildMethod(const RenderArgs& a) {
  auto method = methodPreset(a.method);
  if (!method) return method.error();
  MethodDesc m = method.value();
  if (auto ok = checkApplicable(a, m); !ok) return ok.error();
  if (a.k) {
    if (*a.k < 1 || *a.k > (1u << 20)) return makeError("--k: must be in [1, 1048576]");
    if (m.name.rfind("zbuffer", 0) == 0 && *a.k != 1) return makeError("--k: zbuffer has k = 1");
    m.k = *a.k;
  }
  if (!a.composite.empty()) {  // otherwise the preset's own rule
    auto compositing = parseCompositing(a.composite);
    if (!compositing) return makeError("--composite: " + compositing.error().message);
    m.compositing = compositing.value();
  }
  if (!a.model.empty()) {
    auto model = loadDkbModel(a.model);
    if (!model) return model.error();
    m.model = model.value();
    if (auto ok = checkModelForMethod(*m.model, a.model, m); !ok)
      return makeError("--model: " + ok.error().message);
  }
  if (m.allocation == AllocationPolicy::Importance) {
    ImportanceParams ip = a.importance;
    if (!(ip.alpha >= 0.0f && ip.alpha <= 1.0f))
      return makeError("--importance-alpha: must be in [0, 1]");
    if (!(ip.nLimit >= 1.0f && ip.nLimit <= 1e6f))
      return makeError("--n-limit: must be in [1, 1e6]");
    if (!(ip.peripheryExponent > 0.0f && ip.peripheryExponent <= 100.0f))
      return makeError("--periphery-d: must be in (0, 100]");
    if (!(ip.noise >= 0.0f && ip.noise <= 1.0f)) return makeError("--noise: must be in [0, 1]");
    if (!a.fovea.empty()) {
      if (a.fovea.size() != 2 || !std::isfinite(a.fovea[0]) || !std::isfinite(a.fovea[1]))
        return makeError("--fovea: expected two finite pixel coordinates X,Y");
      ip.fovea = glm::vec2(a.fovea[0], a.fovea[1]);
    }
    ip.seed = a.scene.seed;
    ip.useDepth = !a.noDepthTerm;
    ip.usePeriphery = !a.noPeripheryTerm;
    ip.useFresnel = !a.noFresnelTerm;
    ip.useNoise = !a.noNoise;
    m.importance = ip;
  }
  if (m.occupancyWords > 0) {
    if (a.occupancyD < 1 || a.occupancyD > 64)
      return makeError("--occupancy-d: must be in [1, 64]");
    m.occupancyWords = a.occupancyD;
  }
  return m;
}

template <class T>
void writeMap(const std::string& path, const std::vector<T>& values, int w, int h,
              const std::string& title) {
  std::vector<float> v(values.begin(), values.end());
  float maxValue = std::is_integral_v<T> ? 1.0f : 0.0f;
  for (float x : v) maxValue = std::max(maxValue, x);
  auto written = writePng(path, colorMapWithLegend(v, w, h, maxValue, title));
  if (!written) throw std::runtime_error(written.error().message);
}

int run(const RenderArgs& a) {
  auto method = buildMethod(a);
  if (!method) return fail(method.error().message);
  RenderOptions options;
  std::optional<BudgetSpec> budget;  // a relative one is resolved per view (its count pass)
  if (!a.budget.empty()) {
    auto parsed = parseBudgetSpec(a.budget);
    if (!parsed) return fail("--budget: " + parsed.error().message);
    budget = parsed.value();
    options.budgetBytes = budget->bytes;
  }
  if (a.capture == "parallel")
    options.capture = CaptureMode::FragmentParallel;
  else if (a.capture != "tile")
    return fail("--capture " + quoteInput(a.capture) + ": expected tile or parallel");
  if (a.out.empty()) return fail("--out: empty path");

  auto memoryLimit = a.scene.memoryLimitBytes();
  if (!memoryLimit) return fail(memoryLimit.error().message);
  options.memoryLimitBytes = memoryLimit.value();
  auto engine = makeSceneEngine(a.scene);
  if (!engine) return fail(engine.error().message);
  // what the image size alone decides, before the scene is loaded and set up
  if (auto fits = (*engine)->preflight(a.scene.width, a.scene.height, *method, options); !fits)
    return fail(echoPath(a.scene.source) + ": " + fits.error().message);

  Progress progress(!a.scene.quiet);
  progress.set("loading " + a.scene.source);
  auto prepared = prepareScene(a.scene);
  if (!prepared) return fail(prepared.error().message);
  const Scene& scene = prepared->scene;
  options.background = scene.background;
  const int views = static_cast<int>(prepared->cameras.size());
  nlohmann::json allStats = nlohmann::json::array();
  std::vector<float> previousCosine;  // importance methods: nearest |n.v| of the previous view
  if (prepared->previousCamera && method->allocation == AllocationPolicy::Importance &&
      method->importanceSource == ImportanceSource::Heuristic) {
    // --orbit-view I: view I - 1 precedes it, as in the full orbit
    auto previous = (*engine)->prepare(sceneView(*prepared, a.scene, *prepared->previousCamera));
    if (!previous) return fail(echoPath(a.scene.source) + ": " + previous.error().message);
    auto cosine = (*engine)->nearestCosine(**previous);
    if (!cosine) return fail(echoPath(a.scene.source) + ": " + cosine.error().message);
    previousCosine = std::move(cosine.value());
  }
  const int width = a.scene.width, height = a.scene.height;
  for (int v = 0; v < views; ++v) {
    progress.set("rendering " + method->name, v, views);
    auto view = (*engine)->prepare(sceneView(*prepared, a.scene, prepared->cameras[v]));
    if (!view) return fail(echoPath(a.scene.source) + ": " + view.error().message);
    options.previousNearestCosine = previousCosine.empty() ? nullptr : &previousCosine;
    if (budget && budget->isRelative()) {
      auto counted = (*engine)->countFragments(**view);
      if (!counted) return fail(echoPath(a.scene.source) + ": " + counted.error().message);
      auto bytes = resolveBudget(
          *budget, method.value(),
          MemoryModel::of(method.value(), options.capture == CaptureMode::FragmentParallel),
          FrameCounts::of(counted.value()), std::to_string(width) + "x" + std::to_string(height));
      if (!bytes) return fail(echoPath(a.scene.source) + ": " + bytes.error().message);
      options.budgetBytes = bytes.value();
    }
    auto result = (*engine)->render(**view, method.value(), options);
    if (!result) return fail(echoPath(a.scene.source) + ": " + result.error().message);
    previousCosine = result->nearestCosine;
    const std::string out = viewPath(a.out, v, views);
    auto written = writePng(out, encodeSrgb(result->image));
    if (!written) return fail(written.error().message);
    try {
      if (!a.depthComplexity.empty()) {
        std::vector<uint32_t> n = result->depthComplexity;
        if (n.empty()) {
          auto counted = (*engine)->countFragments(**view);
          if (!counted) return fail(echoPath(a.scene.source) + ": " + counted.error().message);
          n = std::move(counted.value());
        }
        writeMap(viewPath(a.depthComplexity, v, views), n, width, height, "fragments per pixel");
      }
      if (!a.kMap.empty())
        writeMap(viewPath(a.kMap, v, views), result->kMap, width, height, "k(p)");
      const ImportanceMaps& imp = result->importance;
      if (!a.importanceMap.empty() && !imp.importance.empty())
        writeMap(viewPath(a.importanceMap, v, views), imp.importance, width, height,
                 "importance I(p)");
      if (!a.importanceFactors.empty() && !imp.importance.empty()) {
        const std::filesystem::path dir(a.importanceFactors);
        char suffix[32];
        std::snprintf(suffix, sizeof suffix, views > 1 ? "_v%03d.png" : ".png", v);
        const std::pair<const char*, const std::vector<float>*> factors[] = {
            {"importance", &imp.importance},
            {"depth", &imp.depth},
            {"periphery", &imp.periphery},
            {"fresnel", &imp.fresnel}};
        for (const auto& [name, values] : factors)
          writeMap((dir / (std::string(name) + suffix)).string(), *values, width, height,
                   std::string("I_") + name);
        std::vector<float> noise(imp.noise.size());
        for (size_t i = 0; i < noise.size(); ++i) noise[i] = imp.noise[i] + 0.05f;
        writeMap((dir / (std::string("noise") + suffix)).string(), noise, width, height,
                 "noise + 0.05");
      }
    } catch (const std::exception& e) {
      return fail(e.what());
    }
    nlohmann::json stats = statsToJson(result->stats);
    stats["scene"] = a.scene.source;
    stats["width"] = width;
    stats["height"] = height;
    stats["image"] = out;
    stats["view"] = v;
    stats["compositing"] = toString(method->compositing);
    stats["capture"] = a.capture;
    if (budget && budget->isRelative()) stats["budget_label"] = budget->label;
    allStats.push_back(stats);
    if (!a.scene.quiet && !a.scene.json) {
      const RenderStats& s = result->stats;
      progress.clear();
      std::fprintf(stderr,
                   "%s: %s  %llu fragments, %llu captured (%.2f%% lost), k %u-%u, %s, "
                   "%.1f ms\n",
                   method->name.c_str(), out.c_str(),
                   static_cast<unsigned long long>(s.fragmentsGenerated),
                   static_cast<unsigned long long>(s.captured), s.lostPercent(), s.kMin, s.kMax,
                   formatBytes(s.bytesUsed).c_str(), s.totalMs());
    }
  }
  const nlohmann::json statsOut = views == 1 ? allStats[0] : allStats;
  if (!a.statsJson.empty()) {  // written atomically: never a truncated JSON file
    auto written = writeFileAtomically(a.statsJson, statsOut.dump(2) + "\n");
    if (!written) return fail(written.error().message);
  }
  if (a.scene.json) std::printf("%s\n", statsOut.dump(2).c_str());
  return 0;
}

}  // namespace

Runner addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a scene with one method");
  args->scene.add(*cmd, true, true);
  cmd->add_option("--out,-o", args->out, "Output PNG (sRGB)");
  cmd->add_option("--depth-complexity", args->depthComplexity,
                  "Write the fragments-per-pixel map (colour-mapped PNG with legend)");
  cmd->add_option("--k-map", args->kMap, "Write the per-pixel k as a colour-mapped PNG");
  cmd->add_option("--stats-json", args->statsJson, "Write the run's statistics as JSON");
  cmd->add_option("--method,-m", args->method, presetHelp());
  cmd->add_option(
      "--budget,-M", args->budget,
      "Memory budget, e.g. 20MB (MB = 2^20 bytes), or 30% (the method's per-pixel words + "
      "30% of the exact A-buffer's node bytes for the frame)");
  cmd->add_option("--k", args->k,
                  "Explicit k (otherwise derived from the budget)" + appliesTo(MethodOption::K));
  cmd->add_option("--composite", args->composite,
                  "kbuffer or hybrid (default: the preset's own rule, hybrid for dkb* and "
                  "optimal*, else kbuffer)" +
                      appliesTo(MethodOption::Composite));
  cmd->add_option("--occupancy-d", args->occupancyD,
                  "Occupancy map: 32*d buckets (default 1)" + appliesTo(MethodOption::OccupancyD));
  cmd->add_option("--capture", args->capture,
                  "tile (tile-owned, lock-free) or parallel (fragment-parallel, spin-locks)");
  cmd->add_option(
      "--importance-map", args->importanceMap,
      "Write the importance map I(p) (colour-mapped PNG)" + appliesTo(MethodOption::ImportanceMap));
  cmd->add_option("--importance-factors", args->importanceFactors,
                  "Write each importance factor as a PNG into this folder" +
                      appliesTo(MethodOption::ImportanceParams));
  cmd->add_option("--model", args->model,
                  "Network model (.mfrnn from mfr train; default: the built-in model)" +
                      appliesTo(MethodOption::Model));
  cmd->add_option("--importance-alpha", args->importance.alpha, "vkb Eq. 3 alpha (default 0.375)");
  cmd->add_option("--n-limit", args->importance.nLimit, "vkb Eq. 3 N_limit (default 20)");
  cmd->add_option("--periphery-d", args->importance.peripheryExponent, "vkb Eq. 4 d (default 3)");
  cmd->add_option("--fovea", args->fovea,
                  "vkb Eq. 4 centre o in pixels X,Y (default: image centre)")
      ->delimiter(',')
      ->expected(2);
  cmd->add_option("--noise", args->importance.noise, "vkb Eq. 6 lambda (default 0.1)");
  cmd->add_flag("--no-depth-term", args->noDepthTerm, "vkb: switch off I_d");
  cmd->add_flag("--no-periphery-term", args->noPeripheryTerm, "vkb: switch off I_per");
  cmd->add_flag("--no-fresnel-term", args->noFresnelTerm, "vkb: switch off I_f");
  cmd->add_flag("--no-noise", args->noNoise, "vkb: switch off the noise of Eq. 6");
  args->command = cmd;
  return [args] { return run(*args); };
}

}  // namespace mfr::cli
