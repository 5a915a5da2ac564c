// Python arguments -> library values (see scene_options.hpp).
#include "scene_options.hpp"

#include <cmath>
#include <cstring>

#include "mfr/core/quote.hpp"
#include "mfr/core/samples.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/scene/camera_spec.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::python {
namespace {

/// A sequence of finite numbers (castArgument<double> names the item: "background[1]").
std::vector<double> numbers(const py::object& value, const char* what) {
  std::vector<double> v;
  for (const py::object& item : listArgument(value, what, "a sequence of numbers"))
    v.push_back(
        castArgument<double>(item, std::string(what) + "[" + std::to_string(v.size()) + "]"));
  return v;
}

}  // namespace

std::optional<float> alphaArgument(const py::object& alpha, const char* name) {
  if (alpha.is_none()) return std::nullopt;
  const double a = castArgument<double>(alpha, name);
  if (!(a >= 0.0 && a <= 1.0)) throw LibraryError(std::string(name) + ": must be in [0, 1]");
  return static_cast<float>(a);
}

glm::vec3 backgroundArgument(const py::object& background) {
  const std::vector<double> v = numbers(background, "background");
  if (v.size() != 3) throw LibraryError("background: expected three numbers R, G, B");
  for (double b : v)
    if (b < 0.0 || b > 1.0) throw LibraryError("background: components must be in [0, 1]");
  return glm::vec3(v[0], v[1], v[2]);
}

std::shared_ptr<Scene> loadSceneArgument(const std::string& source, uint64_t seed,
                                         double transmissionFloor, const py::object& alpha,
                                         const py::object& background,
                                         std::optional<uint64_t> memoryLimit,
                                         bool allowOutsideReferences, const py::object& gltfScene) {
  if (!(transmissionFloor >= 0.0 && transmissionFloor <= 1.0))
    throw LibraryError("transmission_floor: must be in [0, 1]");
  const std::optional<float> alphaOverride = alphaArgument(alpha);
  std::optional<glm::vec3> backgroundColor;
  if (!background.is_none()) backgroundColor = backgroundArgument(background);
  LoadOptions load;
  load.seed = seed;
  load.transmissionAlphaFloor = static_cast<float>(transmissionFloor);
  load.memoryLimitBytes = memoryLimit;
  load.allowOutsideReferences = allowOutsideReferences;
  if (!gltfScene.is_none()) {
    const long long n = castArgument<long long>(gltfScene, "gltf_scene");
    if (n < 0 || n > INT32_MAX) throw LibraryError("gltf_scene: must be a scene index (0-based)");
    load.sceneIndex = static_cast<int>(n);
  }
  auto scene = std::make_shared<Scene>();
  {
    py::gil_scoped_release release;
    *scene = unwrap(loadScene(source, load));
  }
  if (alphaOverride) scene->alphaOverride = alphaOverride;
  if (backgroundColor) scene->background = *backgroundColor;
  return scene;
}

SceneArgument sceneArgument(const py::object& scene, uint64_t seed, const SceneRequest& request,
                            std::optional<uint64_t> memoryLimit, bool allowOutsideReferences) {
  if (!py::isinstance<Scene>(scene)) {
    if (!isPath(scene))
      throw py::type_error(
          "scene: expected an mfr.Scene or a source (str, bytes or "
          "os.PathLike), got " +
          typeName(scene));
    const std::string source = pathText(scene, "scene");
    LoadOptions load;
    load.seed = seed;
    load.transmissionAlphaFloor = static_cast<float>(request.transmissionFloor);
    load.memoryLimitBytes = memoryLimit;
    load.allowOutsideReferences = allowOutsideReferences;
    load.sceneIndex = request.gltfScene;
    auto loaded = std::make_shared<Scene>();
    {
      py::gil_scoped_release release;
      *loaded = unwrap(loadScene(source, load));
      unwrap(applyToScene(request, *loaded, Spelling::Python));
    }
    return {loaded, source};
  }
  // a loaded scene's files are read: its loading options cannot change it now
  if (request.transmissionFloor != SceneRequest{}.transmissionFloor)
    throw LibraryError("transmission_floor: applies when the scene is loaded (mfr.load_scene)");
  if (allowOutsideReferences)
    throw LibraryError(
        "allow_outside_references: applies when the scene is loaded (mfr.load_scene)");
  if (request.gltfScene)
    throw LibraryError("gltf_scene: applies when the scene is loaded (mfr.load_scene)");
  auto loaded = scene.cast<std::shared_ptr<Scene>>();
  if (!request.changesScene()) return {loaded, loaded->name};
  auto changed = std::make_shared<Scene>(*loaded);  // the caller's scene stays as it is
  unwrap(applyToScene(request, *changed, Spelling::Python));
  return {changed, loaded->name};
}

SceneRequest sceneRequestArgument(int width, int height, const py::object& camera,
                                  const py::object& view, int orbit, const py::object& orbitView,
                                  double zoom, const py::object& alpha,
                                  const py::object& background, double transmissionFloor,
                                  const py::object& shuffleDrawOrder, const py::object& gltfScene,
                                  const py::object& cull, const py::object& blend) {
  SceneRequest r;
  r.width = width;
  r.height = height;
  if (!camera.is_none()) {
    if (py::isinstance<py::str>(camera)) {  // the command line's text, "EX,EY,EZ,TX,TY,TZ,..."
      r.camera = castArgument<std::string>(camera, "camera");
      if (r.camera.empty()) throw LibraryError("camera: empty");
    } else {
      for (const py::object& item : listArgument(camera, "camera", "6, 9 or 10 numbers or a str"))
        r.cameraNumbers.push_back(
            castArgument<double>(item, "camera[" + std::to_string(r.cameraNumbers.size()) + "]"));
      if (r.cameraNumbers.empty()) throw LibraryError("camera: expected 6, 9 or 10 numbers");
    }
  }
  if (!view.is_none()) {
    const long long v = castArgument<long long>(view, "view");
    r.view = v < 0 ? -2 : static_cast<int>(std::min<long long>(v, 1 << 30));
  }
  r.orbit = orbit;
  if (!orbitView.is_none()) {
    const long long v = castArgument<long long>(orbitView, "orbit_view");
    r.orbitView = v < 0 ? -2 : static_cast<int>(std::min<long long>(v, 1 << 30));
  }
  r.zoom = zoom;
  if (!alpha.is_none()) r.alpha = castArgument<double>(alpha, "alpha");
  if (!background.is_none()) r.background = numbers(background, "background");
  r.transmissionFloor = transmissionFloor;
  if (!gltfScene.is_none()) {
    const long long n = castArgument<long long>(gltfScene, "gltf_scene");
    r.gltfScene = n < 0 ? -1 : static_cast<int>(std::min<long long>(n, INT32_MAX));
  }
  if (!shuffleDrawOrder.is_none())
    r.shuffleDrawOrder = castArgument<uint64_t>(shuffleDrawOrder, "shuffle_draw_order");
  if (!cull.is_none()) r.cull = castArgument<std::string>(cull, "cull");
  if (py::isinstance<py::str>(blend)) {  // "MODE" or "MATERIAL=MODE", or a list of them
    r.blend.push_back(castArgument<std::string>(blend, "blend"));
  } else if (!blend.is_none()) {
    for (const py::object& item : listArgument(blend, "blend", "a str or a list of str"))
      r.blend.push_back(
          castArgument<std::string>(item, "blend[" + std::to_string(r.blend.size()) + "]"));
  }
  unwrap(checkSceneRequest(r, Spelling::Python));
  return r;
}

BudgetSpec budgetSpecArgument(const py::object& budget, const std::string& name) {
  if (PyUnicode_Check(budget.ptr())) {
    auto spec = parseBudgetSpec(castArgument<std::string>(budget, name));
    if (!spec) throw LibraryError(name + ": " + spec.error().message);
    return spec.value();
  }
  return BudgetSpec(budgetArgument(budget, name));
}

namespace {

/// A positive number of bytes as an int: TypeError for another type (`expected` says what the
/// parameter takes), mfr.Error for 0 or less (as the command line), OverflowError past 2^64 - 1.
uint64_t positiveBytes(const py::object& value, const std::string& name, const char* expected) {
  if (isBool(value) || !PyIndex_Check(value.ptr()))
    throw py::type_error(name + ": expected " + expected + ", got " + typeName(value));
  if (value <= py::int_(0)) throw LibraryError(name + ": must be a positive number of bytes");
  return castArgument<uint64_t>(value, name);
}

}  // namespace

uint64_t budgetArgument(const py::object& budget, const std::string& name) {
  if (PyUnicode_Check(budget.ptr()))
    return unwrap(parseByteSize(castArgument<std::string>(budget, name)));
  return positiveBytes(budget, name, "bytes (an int) or a size such as \"20MB\"");
}

std::optional<uint64_t> memoryLimitArgument(const py::object& limit) {
  if (limit.is_none()) return std::nullopt;
  if (PyUnicode_Check(limit.ptr()))
    return unwrap(
        parseMemoryLimitOption(castArgument<std::string>(limit, "memory_limit"), Spelling::Python));
  return positiveBytes(limit, "memory_limit", "bytes (an int) or a size such as \"8GB\"");
}

int samplesArgument(const py::object& samples) {
  const std::string text = PyUnicode_Check(samples.ptr())
                               ? castArgument<std::string>(samples, "samples")
                               : std::to_string(castArgument<long long>(samples, "samples"));
  return unwrap(parseSamples(text, "samples"));
}

std::vector<int> sampleCountsArgument(const py::object& counts) {
  if (counts.is_none()) return {};
  std::string text;
  if (PyUnicode_Check(counts.ptr())) {
    text = castArgument<std::string>(counts, "sample_counts");
  } else {
    const std::vector<py::object> items =
        listArgument(counts, "sample_counts", "a list of integers or a str");
    for (size_t i = 0; i < items.size(); ++i)
      text += (i ? "," : "") + std::to_string(castArgument<long long>(
                                   items[i], "sample_counts[" + std::to_string(i) + "]"));
  }
  if (text.empty()) return {};
  return unwrap(parseSampleCounts(text, "sample_counts"));
}

CaptureMode captureArgument(const std::string& capture) {
  return unwrap(parseCaptureOption(capture, Spelling::Python));
}

ImportanceOverrides importanceArgument(const py::dict& params) {
  ImportanceOverrides o;
  o.asGroup = true;
  for (const auto& [key, value] : params) {
    const std::string k = py::str(key);
    const std::string name = "importance[" + quoteInput(k) + "]";
    if (k == "alpha") {
      o.alpha = castArgument<double>(value, name);
    } else if (k == "n_limit") {
      o.nLimit = castArgument<double>(value, name);
    } else if (k == "periphery_d") {
      o.peripheryD = castArgument<double>(value, name);
    } else if (k == "noise") {
      o.noise = castArgument<double>(value, name);
    } else if (k == "fovea") {
      o.fovea = numbers(value.cast<py::object>(), "importance['fovea']");
    } else if (k == "depth_term") {
      o.depthTerm = castArgument<bool>(value, name);
    } else if (k == "periphery_term") {
      o.peripheryTerm = castArgument<bool>(value, name);
    } else if (k == "fresnel_term") {
      o.fresnelTerm = castArgument<bool>(value, name);
    } else if (k == "noise_term") {
      o.noiseTerm = castArgument<bool>(value, name);
    } else {
      throw LibraryError("importance: unknown parameter " + quoteInput(k) +
                         " (alpha, n_limit, periphery_d, fovea, noise, depth_term, "
                         "periphery_term, fresnel_term, noise_term)");
    }
  }
  return o;
}

Image8 image8Argument(const py::object& imageArg, const char* what) {
  const std::string name = what;
  // an array, or a nested list of numbers (converted as numpy.asarray does)
  const py::array image = arrayArgument(imageArg, name, "an image array (height, width, channels)");
  if (image.ndim() != 3 || image.shape(0) < 1 || image.shape(1) < 1)
    throw py::value_error(name + ": expected an array (height, width, channels), got " +
                          std::to_string(image.ndim()) + " dimensions");
  const py::ssize_t h = image.shape(0), w = image.shape(1), c = image.shape(2);
  if (h > kMaxImageSize || w > kMaxImageSize)
    throw py::value_error(name + ": larger than " + std::to_string(kMaxImageSize) + " pixels");
  const py::dtype dtype = image.dtype();
  if (dtype.is(py::dtype::of<uint8_t>())) {
    if (c != 3 && c != 4)
      throw py::value_error(name + ": a uint8 (sRGB) image needs 3 or 4 channels, got " +
                            std::to_string(c));
    const auto pixels = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>(image);
    Image8 out;
    out.width = static_cast<int>(w);
    out.height = static_cast<int>(h);
    out.rgba.resize(static_cast<size_t>(w * h * 4), 255);
    const uint8_t* src = pixels.data();
    for (size_t i = 0; i < static_cast<size_t>(w * h); ++i)
      std::memcpy(&out.rgba[4 * i], src + c * i, static_cast<size_t>(c));
    return out;
  }
  if (dtype.kind() == 'f') {
    if (c != 3)
      throw py::value_error(name + ": a floating-point (linear) image needs 3 channels, got " +
                            std::to_string(c));
    const auto pixels = py::array_t<float, py::array::c_style | py::array::forcecast>(image);
    ImageRGB linear(static_cast<int>(w), static_cast<int>(h));
    std::memcpy(linear.pixels.data(), pixels.data(), sizeof(float) * 3 * linear.pixels.size());
    unwrap(checkFinite(linear, name));
    return encodeSrgb(linear);
  }
  throw py::value_error(name + ": expected uint8 sRGB or floating-point linear values, got dtype " +
                        std::string(py::str(static_cast<py::handle>(dtype))));
}

}  // namespace mfr::python
