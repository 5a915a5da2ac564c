// mfr.metrics (MSE, PSNR, FLIP with its map) and mfr.compare (the folder of `mfr compare`).
#include <cmath>

#include "common.hpp"
#include "mfr/compare/compare.hpp"
#include "mfr/compare/compare_output.hpp"
#include "mfr/compare/compare_request.hpp"
#include "mfr/compare/temporal_run.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/engine/engine.hpp"
#include "mfr/engine/render_views.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/metrics/image_metrics.hpp"
#include "scene_options.hpp"

namespace mfr::python {
namespace {

/// A path (str or os.PathLike) read as PNG, or an image array (image8Argument).
Image8 imageOrPath(const py::object& image, const char* what) {
  if (isPath(image)) {
    const std::string path = pathText(image, what);
    py::gil_scoped_release release;
    return unwrap(readPng(path));
  }
  if (!py::isinstance<py::array>(image) && !py::isinstance<py::sequence>(image))
    throw py::type_error(std::string(what) + ": expected a PNG path or an image array, got " +
                         typeName(image));
  return image8Argument(image, what);
}

double pixelsPerDegree(double ppd) {
  unwrap(checkFlipPixelsPerDegree(ppd, Spelling::Python));
  return ppd;
}

py::dict metrics(const py::object& referenceArg, const py::object& testArg,
                 const py::object& ppdArg) {
  const double ppd = pixelsPerDegree(castArgument<double>(ppdArg, "ppd"));
  const Image8 reference = imageOrPath(referenceArg, "reference");
  const Image8 test = imageOrPath(testArg, "test");
  if (reference.width != test.width || reference.height != test.height)
    throw LibraryError("reference is " + std::to_string(reference.width) + "x" +
                       std::to_string(reference.height) + " but test is " +
                       std::to_string(test.width) + "x" + std::to_string(test.height) +
                       ": images must have the same size");
  ImageErrorStats stats;
  FlipResult flip;
  double median = 0, p95 = 0, p99 = 0, maxFlip = 0;
  {
    py::gil_scoped_release release;
    stats = unwrap(compareImages(reference, test));
    flip = unwrap(computeFlip(reference, test, ppd));
    median = flipPercentile(flip, 0.5);
    p95 = flipPercentile(flip, 0.95);
    p99 = flipPercentile(flip, 0.99);
    maxFlip = flipPercentile(flip, 1.0);
  }
  py::dict d;
  d["width"] = stats.width;
  d["height"] = stats.height;
  d["mse_linear"] = stats.mseLinear;
  d["mse_srgb"] = stats.mseSrgb;
  d["psnr_linear"] = stats.psnrLinear;  // inf for identical images
  d["psnr_srgb"] = stats.psnrSrgb;
  d["mse"] = stats.mseLinear;
  d["psnr"] = stats.psnrLinear;
  d["flip_mean"] = flip.mean;
  d["flip_median"] = median;
  d["flip_p95"] = p95;
  d["flip_p99"] = p99;
  d["flip_max"] = maxFlip;
  d["pixels_per_degree"] = ppd;
  const py::ssize_t h = flip.height, w = flip.width;
  d["flip_map"] = ownedArray<float>(std::move(flip.errorMap), {h, w});
  return d;
}

py::object compare(const py::object& sceneArg, const py::object& outArg, const py::object& budgets,
                   const py::object& methods, const py::object& widthArg,
                   const py::object& heightArg, const py::object& camera, const py::object& view,
                   const py::object& orbitArg, const py::object& orbitView,
                   const py::object& orbitStepArg, const py::object& zoomArg,
                   const py::object& composite, const py::object& captureArg,
                   const py::object& threadsArg, const py::object& seedArg, const py::object& model,
                   const py::object& ppdArg, const py::object& alpha, const py::object& background,
                   const py::object& transmissionFloorArg, const py::object& shuffleDrawOrder,
                   const py::object& gltfScene, const py::object& cull, const py::object& blend,
                   const py::object& engineArg, const py::object& glSyncArg,
                   const py::object& glRasterArg, const py::object& memoryLimitArg,
                   const py::object& allowOutsideReferencesArg, const py::object& samplesArg,
                   const py::object& sampleStorageArg, const py::object& sampleCountsArg,
                   const py::object& maxPeelsArg, const py::object& repeatArg,
                   const py::object& warmupArg, const py::object& truthEngineArg,
                   const py::object& commandLineArg) {
  // every argument converted (and its type checked) before any work
  const std::string out = pathText(outArg, "out");
  const int width = castArgument<int>(widthArg, "width");
  const int height = castArgument<int>(heightArg, "height");
  const int orbit = castArgument<int>(orbitArg, "orbit");
  const double orbitStep = castArgument<double>(orbitStepArg, "orbit_step");
  const double zoom = castArgument<double>(zoomArg, "zoom");
  const auto capture = castArgument<std::string>(captureArg, "capture");
  const int threads = castArgument<int>(threadsArg, "threads");
  const auto seed = castArgument<uint64_t>(seedArg, "seed");
  const double ppd = castArgument<double>(ppdArg, "ppd");
  const double transmissionFloor = castArgument<double>(transmissionFloorArg, "transmission_floor");
  const auto engineName = castArgument<std::string>(engineArg, "engine");
  const auto glSync = castArgument<std::string>(glSyncArg, "gl_sync");
  const auto glRaster = castArgument<std::string>(glRasterArg, "gl_raster");
  const bool allowOutsideReferences =
      castArgument<bool>(allowOutsideReferencesArg, "allow_outside_references");
  const auto sampleStorage = castArgument<std::string>(sampleStorageArg, "sample_storage");
  const auto commandLine = castArgument<std::string>(commandLineArg, "command_line");
  const auto repeat = castArgument<int64_t>(repeatArg, "repeat");
  const auto warmup = castArgument<int64_t>(warmupArg, "warmup");
  const auto truthEngine = castArgument<std::string>(truthEngineArg, "truth_engine");
  std::optional<int64_t> maxPeels;
  if (!maxPeelsArg.is_none()) maxPeels = castArgument<int64_t>(maxPeelsArg, "max_peels");
  std::vector<std::string> rules;  // composite: a rule, "kbuffer,hybrid" or a list of rules
  if (!composite.is_none()) {
    if (PyUnicode_Check(composite.ptr()))
      rules = splitCommaList(castArgument<std::string>(composite, "composite"));
    else
      for (const py::object& item : listArgument(composite, "composite", "a str or list of str"))
        rules.push_back(
            castArgument<std::string>(item, "composite[" + std::to_string(rules.size()) + "]"));
  }
  if (!py::isinstance<Scene>(sceneArg) && !isPath(sceneArg))
    throw py::type_error(
        "scene: expected an mfr.Scene or a source (str, bytes or os.PathLike), "
        "got " +
        typeName(sceneArg));
  if (!model.is_none() && !py::isinstance<learn::Model>(model) && !isPath(model))
    throw py::type_error(
        "model: expected an mfr.Model or a .mfrnn path (str, bytes or "
        "os.PathLike), got " +
        typeName(model));
  std::vector<py::object> budgetList;
  if (PyUnicode_Check(budgets.ptr()) || PyIndex_Check(budgets.ptr()))
    budgetList.push_back(budgets);  // one budget
  else
    budgetList = listArgument(budgets, "budgets", "a budget or a list of budgets");
  std::vector<std::string> methodNames;
  for (const py::object& item : listArgument(methods, "methods", "a list of str"))
    methodNames.push_back(
        castArgument<std::string>(item, "methods[" + std::to_string(methodNames.size()) + "]"));
  if (out.empty()) throw LibraryError("out: an output folder is required");
  const int samples = samplesArgument(samplesArg);
  const std::vector<int> sampleCounts = sampleCountsArgument(sampleCountsArg);
  const bool temporal = orbit != 0 && orbitView.is_none();  // every view of the orbit
  if (temporal && orbit < 2)
    throw LibraryError("orbit " + std::to_string(orbit) +
                       ": a temporal comparison needs at least 2 frames (or give orbit_view)");
  if (!(orbitStep >= 0.0 && orbitStep <= 360.0))
    throw LibraryError("orbit_step: must be in (0, 360] degrees");
  if (orbitStep > 0.0 && !temporal)
    throw LibraryError("orbit_step: needs orbit N (and no orbit_view)");
  if (!sampleCounts.empty() && temporal)
    throw LibraryError("sample_counts: not with a temporal comparison (orbit N)");
  CompareRequest compareRequest;
  compareRequest.methods = methodNames;
  for (const py::object& budget : budgetList) {
    // a size ("20MB", bytes), a share of the A-buffer's node bytes ("25%") or "auto"
    const std::string name = "budgets[" + std::to_string(compareRequest.budgets.size()) + "]";
    compareRequest.budgets.push_back(PyUnicode_Check(budget.ptr())
                                         ? castArgument<std::string>(budget, name)
                                         : std::to_string(budgetArgument(budget, name)));
  }
  compareRequest.rules = rules;
  compareRequest.maxPeels = maxPeels;
  if (py::isinstance<learn::Model>(model)) {
    compareRequest.model = model.cast<std::shared_ptr<learn::Model>>();
    compareRequest.modelName = "(mfr.Model)";
  } else if (!model.is_none()) {
    compareRequest.modelPath = pathText(model, "model");
  }
  compareRequest.capture = capture;
  compareRequest.pixelsPerDegree = ppd;
  compareRequest.seed = seed;
  compareRequest.sampleStorage = sampleStorage;
  compareRequest.repeat = repeat;
  compareRequest.warmup = warmup;
  CompareOptions options;
  {
    py::gil_scoped_release release;  // a model file is read here
    options = unwrap(checkCompareRequest(compareRequest, Spelling::Python));
  }
  const SceneRequest request =
      sceneRequestArgument(width, height, camera, view, orbit, orbitView, zoom, alpha, background,
                           transmissionFloor, shuffleDrawOrder, gltfScene, cull, blend);
  unwrap(checkThreads(threads, "threads"));
  // checked and staged before any work; put in place as `out` once complete (as mfr compare)
  OutputFolder folder = unwrap(OutputFolder::begin(out));

  options.memoryLimitBytes = memoryLimitArgument(memoryLimitArg);
  const SceneArgument scene =
      sceneArgument(sceneArg, seed, request, options.memoryLimitBytes, allowOutsideReferences);
  options.scene = scene.source;
  options.background = scene.scene->background;
  const SceneViews views =
      unwrap(sceneViews(*scene.scene, scene.source, request, Spelling::Python));
  std::string jsonText;
  {
    py::gil_scoped_release release;
    EngineOptions eo;
    eo.threads = threads;
    eo.glSync = glSync;
    eo.glRaster = glRaster;
    auto engine = unwrap(makeEngine(engineName, eo));
    EngineOptions truthOptions;
    truthOptions.threads = threads;
    const std::unique_ptr<Engine> truth =
        unwrap(makeTruthEngine(truthEngine, *engine, truthOptions, options, Spelling::Python));
    const auto named = [&](const Error& e) {
      return LibraryError(echoPath(scene.source) + ": " + e.message);
    };
    if (auto fits = checkComparisonFits(*engine, width, height, options); !fits)
      throw named(fits.error());
    ReportInfo info;
    info.mfrVersion = std::string("mfr ") + MFR_VERSION;
    info.commandLine = commandLine;
    info.generated = utcTimestamp();
    if (temporal) {
      TemporalRequest request;
      request.scene = &*scene.scene;
      request.source = scene.source;
      request.start = views.cameras.front();
      request.frames = orbit;
      request.stepDegrees = static_cast<float>(orbitStep);
      request.width = width;
      request.height = height;
      request.samples = samples;
      request.versionNumber = MFR_VERSION;
      request.info = info;
      jsonText =
          unwrap(runTemporalComparison(*engine, request, options, folder.staging())).jsonText;
    } else {
      auto view = prepareComparedView(
          *engine, View{&*scene.scene, views.cameras.front(), width, height, samples}, options);
      if (!view) throw named(view.error());
      // orbit_view I: view I - 1 precedes it (vkb's Fresnel term)
      options.previousNearestCosine = unwrap(
          previousViewCosine(*engine, *scene.scene, scene.source, views, width, height, samples));
      auto result = runComparison(*engine, *view->view, options, view->truth.get());
      if (!result) throw named(result.error());
      if (auto counted = addSampleCounts(
              *engine, View{&*scene.scene, views.cameras.front(), width, height, samples}, options,
              sampleCounts, result.value());
          !counted)
        throw named(counted.error());
      jsonText = unwrap(writeComparison(result.value(), folder.staging(), MFR_VERSION, info));
      unwrap(folder.commit());
      // the folder holds the refusals; a comparison where nothing ran is still an error
      if (auto ran = checkSomeRunRan(result.value()); !ran)
        throw LibraryError(echoPath(scene.source) + ": " + ran.error().message +
                           "; the refusals are in " + echoPath(out));
    }
    if (temporal) unwrap(folder.commit());
  }
  return py::module_::import("json").attr("loads")(jsonText);
}

}  // namespace

void addMetricsAndCompare(py::module_& m) {
  m.attr("FLIP_DEFAULT_PPD") = kFlipDefaultPixelsPerDegree;
  m.attr("DEFAULT_COMPARE_METHODS") = kDefaultCompareMethods;
  m.def("metrics", namedArguments("metrics(): ", &metrics), py::arg("reference"), py::arg("test"),
        py::arg("ppd") = kFlipDefaultPixelsPerDegree,
        R"(Error of `test` against `reference`, as `mfr metrics --json` computes it: each a PNG path
or an array (uint8 (h, w, 3|4) sRGB, or float (h, w, 3) linear, sRGB-encoded first). Returns a
dict: width, height, mse_linear, mse_srgb, psnr_linear, psnr_srgb (inf when identical), mse and psnr
(the linear ones), flip_mean, flip_median, flip_p95, flip_p99, flip_max, pixels_per_degree, and
flip_map (LDR-FLIP per pixel, float32 (h, w) in [0, 1]).)");
  m.def("_compare", namedArguments("compare(): ", &compare), py::arg("scene"), py::arg("out"),
        py::kw_only(), py::arg("budgets"), py::arg("methods"), py::arg("width"), py::arg("height"),
        py::arg("camera"), py::arg("view"), py::arg("orbit"), py::arg("orbit_view"),
        py::arg("orbit_step"), py::arg("zoom"), py::arg("composite"), py::arg("capture"),
        py::arg("threads"), py::arg("seed"), py::arg("model"), py::arg("ppd"), py::arg("alpha"),
        py::arg("background"), py::arg("transmission_floor"), py::arg("shuffle_draw_order"),
        py::arg("gltf_scene"), py::arg("cull"), py::arg("blend"), py::arg("engine"),
        py::arg("gl_sync"), py::arg("gl_raster"), py::arg("memory_limit"),
        py::arg("allow_outside_references"), py::arg("samples"), py::arg("sample_storage"),
        py::arg("sample_counts"), py::arg("max_peels"), py::arg("repeat"), py::arg("warmup"),
        py::arg("truth_engine"), py::arg("command_line"),
        "mfr.compare's work (see python/mfr/__init__.py).");
}

}  // namespace mfr::python
