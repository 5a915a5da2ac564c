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
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/engine/render_views.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/method/make_method.hpp"
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
  std::string overflowMap;
  std::string statsJson;
  std::string method = "abuffer";
  std::string budget;
  std::string capture = "tile";
  std::string importanceMap;
  std::string importanceFactors;
  MethodOverrides overrides;  // --k, --composite, --occupancy-d, --model, the vkb parameters
  std::vector<double> fovea;
  bool noDepthTerm = false, noPeripheryTerm = false, noFresnelTerm = false, noNoise = false;
  const CLI::App* command = nullptr;  // which options were given
  bool given(const char* flag) const { return command->count(flag) > 0; }
};

// The method through the library's makeMethod; the output options that only some methods have
// are refused for the others, not silently ignored.
Result<MethodDesc> buildMethod(const RenderArgs& a) {
  MethodOverrides o = a.overrides;
  if (a.given("--fovea")) o.importance.fovea = a.fovea;
  if (a.given("--no-depth-term")) o.importance.depthTerm = false;
  if (a.given("--no-periphery-term")) o.importance.peripheryTerm = false;
  if (a.given("--no-fresnel-term")) o.importance.fresnelTerm = false;
  if (a.given("--no-noise")) o.importance.noiseTerm = false;
  o.seed = a.scene.seed;
  // an empty value is not "not given": --composite "" is no rule, --model "" no file
  if (a.given("--composite") && o.composite.empty())
    return makeError("--composite: " + parseCompositing("").error().message);
  if (a.given("--model") && o.modelPath.empty()) return makeError("--model: empty path");
  auto m = makeMethod(a.method, o);
  if (!m) return m.error();
  if (a.given("--importance-map"))
    MFR_TRY(checkMethodOption(MethodOption::ImportanceMap, *m, "--importance-map"));
  if (a.given("--importance-factors"))
    MFR_TRY(checkMethodOption(MethodOption::ImportanceParams, *m, "--importance-factors"));
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

/// The format of --out (.png or .pfm), the maps' extensions checked (.png): the name of every
/// image output says its format, checked before any work.
Result<OutputImageFormat> checkImageOutputs(const RenderArgs& a) {
  const std::pair<const char*, const std::string*> maps[] = {
      {"--depth-complexity", &a.depthComplexity},
      {"--k-map", &a.kMap},
      {"--overflow-map", &a.overflowMap},
      {"--importance-map", &a.importanceMap}};
  for (const auto& [option, path] : maps)
    if (!path->empty()) MFR_TRY(imageOutputFormat(option, *path, {OutputImageFormat::Png}));
  if (a.out.empty()) return OutputImageFormat::Png;  // refused later as an empty path
  return imageOutputFormat("--out", a.out, {OutputImageFormat::Png, OutputImageFormat::Pfm});
}

/// The images and maps --out, --depth-complexity, --k-map, --importance-map and
/// --importance-factors ask for, of view `v` of `views`.
Result<void> writeViewImages(const RenderArgs& a, OutputImageFormat format, Engine& engine,
                             const RenderedView& r, int views) {
  const int v = r.index, width = a.scene.width, height = a.scene.height;
  const RenderOutput& result = r.output;
  if (format == OutputImageFormat::Pfm)
    MFR_TRY(writePfm(viewPath(a.out, v, views), result.image));
  else
    MFR_TRY(writePng(viewPath(a.out, v, views), encodeSrgb(result.image)));
  try {
    if (!a.depthComplexity.empty()) {
      std::vector<uint32_t> n = result.depthComplexity;
      if (n.empty()) {
        auto counted = engine.countFragments(r.view);
        if (!counted) return makeError(echoPath(a.scene.source) + ": " + counted.error().message);
        n = std::move(counted.value());
      }
      writeMap(viewPath(a.depthComplexity, v, views), n, width, height, "fragments per pixel");
    }
    if (!a.kMap.empty()) writeMap(viewPath(a.kMap, v, views), result.kMap, width, height, "k(p)");
    if (!a.overflowMap.empty())
      writeMap(viewPath(a.overflowMap, v, views), result.lostPerPixel, width, height,
               "fragments without a node");
    const ImportanceMaps& imp = result.importance;
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
    return makeError(e.what());
  }
  return {};
}

/// Every file the options ask for (the importance factors: each file in their folder, and the
/// folder itself), for checkDistinctOutputs.
std::vector<OutputFile> outputFiles(const RenderArgs& a) {
  std::vector<OutputFile> files{{"--out", a.out},
                                {"--depth-complexity", a.depthComplexity},
                                {"--k-map", a.kMap},
                                {"--overflow-map", a.overflowMap},
                                {"--stats-json", a.statsJson},
                                {"--importance-map", a.importanceMap}};
  if (!a.importanceFactors.empty()) {
    files.push_back({"--importance-factors", a.importanceFactors});
    for (const char* name : {"importance", "depth", "periphery", "fresnel", "noise"})
      files.push_back(
          {"--importance-factors",
           (std::filesystem::path(a.importanceFactors) / (std::string(name) + ".png")).string()});
  }
  return files;
}

int run(const RenderArgs& a) {
  // two outputs at one path: refused before any work (with --orbit every name gets the same
  // view suffix, so distinct names stay distinct)
  if (auto distinct = checkDistinctOutputs(
          outputFiles(a), {{"scene", a.scene.source}, {"--model", a.overrides.modelPath}});
      !distinct)
    return fail(distinct.error().message);
  const auto outFormat = checkImageOutputs(a);
  if (!outFormat) return fail(outFormat.error().message);
  auto method = buildMethod(a);
  if (!method) return fail(method.error().message);
  RenderOptions options;
  std::optional<BudgetSpec> budget;  // a relative one is resolved per view (its count pass)
  if (!a.budget.empty()) {
    auto parsed = parseBudgetSpec(a.budget);
    if (!parsed) return fail("--budget: " + parsed.error().message);
    budget = parsed.value();
  }
  auto capture = parseCaptureOption(a.capture);
  if (!capture) return fail(capture.error().message);
  options.capture = capture.value();
  options.sampleStorage = a.scene.storage();
  if (a.out.empty()) return fail("--out: empty path");
  if (!a.overflowMap.empty() && a.scene.sampleCount() == 1)
    return fail("--overflow-map: needs --samples 2, 4 or 8");

  auto memoryLimit = a.scene.memoryLimitBytes();
  if (!memoryLimit) return fail(memoryLimit.error().message);
  options.memoryLimitBytes = memoryLimit.value();
  if (budget) options.budgetBytes = budget->bytes;
  auto engine = makeSceneEngine(a.scene);
  if (!engine) return fail(engine.error().message);
  // what the image size alone decides, before the scene is loaded and set up
  if (auto fits = (*engine)->preflight(a.scene.width, a.scene.height, *method, options); !fits)
    return fail(echoPath(a.scene.source) + ": " + fits.error().message);

  Progress progress(!a.scene.quiet);
  progress.set("loading " + a.scene.source);
  auto prepared = prepareScene(a.scene);
  if (!prepared) return fail(prepared.error().message);
  options.background = prepared->scene.background;
  const int views = static_cast<int>(prepared->cameras.size());
  nlohmann::json allStats = nlohmann::json::array();
  const SceneViews sceneViews{prepared->cameras, prepared->previousCamera};
  progress.set("rendering " + method->name, 0, views);
  auto rendered = renderViews(
      **engine, prepared->scene, a.scene.source, sceneViews, a.scene.width, a.scene.height,
      a.scene.sampleCount(), *method, options, budget, [&](const RenderedView& r) -> Result<void> {
        MFR_TRY(writeViewImages(a, *outFormat, **engine, r, views));
        nlohmann::json stats = statsToJson(r.output.stats);
        stats["scene"] = a.scene.source;
        stats["width"] = a.scene.width;
        stats["height"] = a.scene.height;
        stats["image"] = viewPath(a.out, r.index, views);
        stats["view"] = r.index;
        stats["compositing"] = toString(method->compositing);
        stats["capture"] = a.capture;
        if (budget && budget->isRelative()) stats["budget_label"] = budget->label;
        allStats.push_back(stats);
        if (!a.scene.quiet && !a.scene.json) {
          const RenderStats& s = r.output.stats;
          progress.clear();
          const std::string skipped =
              s.primitivesSkipped
                  ? ", " + std::to_string(s.primitivesSkipped) + " point/line primitives skipped"
                  : "";
          std::fprintf(stderr,
                       "%s: %s  %llu fragments, %llu captured (%.2f%% lost), k %u-%u, %s, "
                       "%.1f ms%s\n",
                       method->name.c_str(), echoPath(viewPath(a.out, r.index, views)).c_str(),
                       static_cast<unsigned long long>(s.fragmentsGenerated),
                       static_cast<unsigned long long>(s.captured), s.lostPercent(), s.kMin, s.kMax,
                       formatBytes(s.bytesUsed).c_str(), s.totalMs(), skipped.c_str());
        }
        progress.set("rendering " + method->name, r.index + 1, views);
        return {};
      });
  if (!rendered) return fail(rendered.error().message);
  const nlohmann::json statsOut = views == 1 ? allStats[0] : allStats;
  if (!a.statsJson.empty()) {  // written atomically: never a truncated JSON file
    auto written = writeFileAtomically(a.statsJson, jsonText(statsOut) + "\n");
    if (!written) return fail(written.error().message);
  }
  if (a.scene.json) std::printf("%s\n", jsonText(statsOut).c_str());
  return 0;
}

}  // namespace

Runner addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a scene with one method");
  args->scene.add(*cmd, true, true);
  cmd->add_option("--out,-o", args->out,
                  "Output image: NAME.png (sRGB, 8 bits) or NAME.pfm (Portable Float Map: linear "
                  "RGB floats) (default mfr.png)");
  cmd->add_option("--depth-complexity", args->depthComplexity,
                  "Write the fragments-per-pixel map (colour-mapped PNG with legend)");
  cmd->add_option("--k-map", args->kMap, "Write the per-pixel k as a colour-mapped PNG");
  cmd->add_option("--overflow-map", args->overflowMap,
                  "With --samples > 1: write, per pixel, the fragments that got no node (lost "
                  "or sent to the hybrid tail) as a colour-mapped PNG");
  cmd->add_option("--stats-json", args->statsJson, "Write the run's statistics as JSON");
  cmd->add_option("--method,-m", args->method, presetHelp());
  cmd->add_option(
      "--budget,-M", args->budget,
      "Memory budget, e.g. 20MB (MB = 2^20 bytes), or 30% (the method's per-pixel words + "
      "30% of the exact A-buffer's node bytes for the frame)");
  cmd->add_option("--k", args->overrides.k,
                  "Explicit k (otherwise derived from the budget)" + appliesTo(MethodOption::K));
  cmd->add_option("--composite", args->overrides.composite,
                  "kbuffer or hybrid (default: the preset's own rule, hybrid for dkb* and "
                  "optimal*, else kbuffer)" +
                      appliesTo(MethodOption::Composite));
  cmd->add_option("--occupancy-d", args->overrides.occupancyD,
                  "Occupancy map: 32*d buckets (default 1)" + appliesTo(MethodOption::OccupancyD));
  cmd->add_option("--capture", args->capture,
                  "tile (tile-owned, lock-free) or parallel (fragment-parallel, spin-locks)");
  cmd->add_option("--max-peels", args->overrides.maxPeels,
                  "Depth peeling: at most P geometry passes (dual-peel: 2P layers); the rest is "
                  "dropped, or with --composite hybrid blended into a tail (default: until no "
                  "fragment remains)" +
                      appliesTo(MethodOption::MaxPeels));
  cmd->add_option(
      "--importance-map", args->importanceMap,
      "Write the importance map I(p) (colour-mapped PNG)" + appliesTo(MethodOption::ImportanceMap));
  cmd->add_option("--importance-factors", args->importanceFactors,
                  "Write each importance factor as a PNG into this folder" +
                      appliesTo(MethodOption::ImportanceParams));
  cmd->add_option("--model", args->overrides.modelPath,
                  "Network model (.mfrnn from mfr train; default: the built-in model)" +
                      appliesTo(MethodOption::Model));
  cmd->add_option("--importance-alpha", args->overrides.importance.alpha,
                  "vkb Eq. 3 alpha (default 0.375)");
  cmd->add_option("--n-limit", args->overrides.importance.nLimit, "vkb Eq. 3 N_limit (default 20)");
  cmd->add_option("--periphery-d", args->overrides.importance.peripheryD,
                  "vkb Eq. 4 d (default 3)");
  cmd->add_option("--fovea", args->fovea,
                  "vkb Eq. 4 centre o in pixels X,Y (default: image centre)")
      ->delimiter(',')
      ->expected(2);
  cmd->add_option("--noise", args->overrides.importance.noise, "vkb Eq. 6 lambda (default 0.1)");
  cmd->add_flag("--no-depth-term", args->noDepthTerm, "vkb: switch off I_d");
  cmd->add_flag("--no-periphery-term", args->noPeripheryTerm, "vkb: switch off I_per");
  cmd->add_flag("--no-fresnel-term", args->noFresnelTerm, "vkb: switch off I_f");
  cmd->add_flag("--no-noise", args->noNoise, "vkb: switch off the noise of Eq. 6");
  args->command = cmd;
  return [args] { return run(*args); };
}

}  // namespace mfr::cli
