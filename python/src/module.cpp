// The Python module mfr (_mfr, wrapped by python/mfr/__init__.py): scenes, rendering, images,
// metrics, comparisons (this file and metrics_compare.cpp) and the deep k-buffer's models and
// datasets (learn.cpp). Library errors raise mfr.Error with the library's one-line message; the
// GIL is released while the library works; arrays are returned over moved buffers, not copies.
#include <cmath>
#include <optional>
#include <type_traits>

#include "common.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/memory_limit.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/engine/render_views.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/method/stats_json.hpp"
#include "mfr/scene/load.hpp"
#include "scene_options.hpp"
#ifdef MFR_HAS_GL
#include "mfr/gl/gl_render_engine.hpp"
#endif

namespace mfr::python {

py::object toPython(const nlohmann::json& value) {
  return py::module_::import("json").attr("loads")(value.dump());
}

namespace {

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be three packed floats");

py::tuple vec3Tuple(const glm::vec3& v) {
  return py::make_tuple(v.x, v.y, v.z);
}

py::dict cameraDict(const Camera& c) {
  py::dict d;
  d["eye"] = vec3Tuple(c.eye);
  d["target"] = vec3Tuple(c.target);
  d["up"] = vec3Tuple(c.up);
  d["fov"] = c.fovYDegrees;
  return d;
}

/// A read-only array over memory owned by `owner` (a Python object kept alive by the array).
template <class Scalar>
py::array viewOf(const Scalar* data, std::vector<py::ssize_t> shape, py::handle owner) {
  py::array a = py::array_t<Scalar>(shape, data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

/// The method as `mfr render` builds it from the same options: the library's makeMethod.
MethodDesc buildMethod(const std::string& name, const py::object& k, const py::object& composite,
                       const py::object& model, const py::object& occupancyD,
                       const py::object& importance, uint64_t seed,
                       const py::object& maxPeels = py::none()) {
  MethodOverrides o;
  if (!maxPeels.is_none()) o.maxPeels = castArgument<long long>(maxPeels, "max_peels");
  if (!k.is_none()) o.k = castArgument<long long>(k, "k");
  if (!composite.is_none()) {
    o.composite = castArgument<std::string>(composite, "composite");
    if (o.composite.empty())
      throw LibraryError("composite: " + parseCompositing("").error().message);
  }
  if (!occupancyD.is_none()) o.occupancyD = castArgument<long long>(occupancyD, "occupancy_d");
  if (!model.is_none()) {
    if (py::isinstance<learn::Model>(model))
      o.model = model.cast<std::shared_ptr<learn::Model>>();
    else if ((o.modelPath = pathText(model, "model")).empty())
      throw LibraryError("model: empty path");
  }
  if (!importance.is_none())
    o.importance = importanceArgument(castArgument<py::dict>(importance, "importance"));
  o.seed = seed;
  py::gil_scoped_release release;  // a model file may be read
  return unwrap(makeMethod(name, o, Spelling::Python));
}

struct PyRenderResult {
  py::object image, srgb, kMap, depthComplexity, importance, stats;
};

/// One view's output as Python values; the statistics exactly as `mfr render --stats-json`
/// writes them (less "image": no file).
PyRenderResult renderResult(RenderOutput&& out, nlohmann::json stats, int width, int height) {
  const py::ssize_t h = height, w = width;
  const size_t pixels = static_cast<size_t>(h) * static_cast<size_t>(w);
  // a per-pixel map, or None when the method has none (e.g. no fragment slots, no importance)
  const auto map = [&](auto&& values) -> py::object {
    using T = typename std::decay_t<decltype(values)>::value_type;
    if (values.size() != pixels) return py::none();
    return ownedArray<T>(std::move(values), {h, w});
  };
  MFR_CHECK(out.image.pixels.size() == pixels);
  PyRenderResult r;
  r.srgb = ownedArray<uint8_t>(std::move(encodeSrgb(out.image).rgba), {h, w, 4});
  r.image = ownedArray<float>(std::move(out.image.pixels), {h, w, 3});
  r.kMap = map(std::move(out.kMap));
  r.depthComplexity = map(std::move(out.depthComplexity));
  r.importance = map(std::move(out.importance.importance));
  r.stats = toPython(stats);
  return r;
}

py::object renderScene(
    const py::object& sceneArg, const std::string& method, const py::object& budget,
    const py::object& k, int width, int height, const py::object& camera, const py::object& view,
    int orbit, const py::object& orbitView, double zoom, const py::object& composite,
    const std::string& capture, int threads, uint64_t seed, const py::object& model,
    const py::object& occupancyD, const py::object& importance, const py::object& alpha,
    const py::object& background, double transmissionFloor, const py::object& shuffleDrawOrder,
    const py::object& gltfScene, const py::object& cull, const py::object& blend,
    const std::string& engineName, const std::string& glSync, const std::string& glRaster,
    const py::object& memoryLimitArg, bool allowOutsideReferences, bool wantDepthComplexity,
    const py::object& maxPeels, const std::string& samplesArg, const std::string& sampleStorage) {
  const int samples = unwrap(parseSamples(samplesArg, "samples"));
  const std::optional<uint64_t> memoryLimit = memoryLimitArgument(memoryLimitArg);
  const SceneRequest request =
      sceneRequestArgument(width, height, camera, view, orbit, orbitView, zoom, alpha, background,
                           transmissionFloor, shuffleDrawOrder, gltfScene, cull, blend);
  unwrap(checkThreads(threads, "threads"));
  const MethodDesc m =
      buildMethod(method, k, composite, model, occupancyD, importance, seed, maxPeels);
  RenderOptions options;
  std::optional<BudgetSpec> spec;
  if (!budget.is_none()) spec = budgetSpecArgument(budget);
  options.capture = captureArgument(capture);
  options.sampleStorage = unwrap(parseSampleStorage(sampleStorage, "sample_storage"));
  options.memoryLimitBytes = memoryLimit;
  const SceneArgument scene =
      sceneArgument(sceneArg, seed, request, memoryLimit, allowOutsideReferences);
  options.background = scene.scene->background;
  const SceneViews views =
      unwrap(sceneViews(*scene.scene, scene.source, request, Spelling::Python));
  // an orbit's arrays are returned together (the CLI writes each view and drops it): image,
  // sRGB, k(p), n(p) and importance, 28 bytes per pixel and view
  if (views.cameras.size() > 1) {
    const uint64_t outputBytes = saturatingMul(
        saturatingMul(views.cameras.size(), static_cast<uint64_t>(width) * height), 28);
    unwrap(checkMemory(outputBytes, memoryLimit.value_or(defaultMemoryLimit()),
                       echoPath(scene.source) + ": the arrays of " +
                           std::to_string(views.cameras.size()) + " views"));
  }

  struct Rendered {
    RenderOutput output;
    nlohmann::json stats;
  };
  std::vector<Rendered> rendered;
  {
    py::gil_scoped_release release;
    EngineOptions eo;
    eo.threads = threads;
    eo.glSync = glSync;
    eo.glRaster = glRaster;
    auto engine = unwrap(makeEngine(engineName, eo));
    if (spec) options.budgetBytes = spec->bytes;
    if (auto fits = engine->preflight(width, height, m, options); !fits)
      throw LibraryError(echoPath(scene.source) + ": " + fits.error().message);
    unwrap(renderViews(*engine, *scene.scene, scene.source, views, width, height, samples, m,
                       options, spec, [&](const RenderedView& r) -> Result<void> {
                         RenderOutput out = std::move(r.output);
                         if (wantDepthComplexity && out.depthComplexity.empty()) {
                           auto counted = engine->countFragments(r.view);
                           if (!counted) return counted.error();
                           out.depthComplexity = std::move(counted.value());
                         }
                         nlohmann::json stats = statsToJson(out.stats);
                         stats["scene"] = scene.source;
                         stats["width"] = width;
                         stats["height"] = height;
                         stats["view"] = r.index;
                         stats["compositing"] = toString(m.compositing);
                         stats["capture"] = capture;
                         if (spec && spec->isRelative()) stats["budget_label"] = spec->label;
                         rendered.push_back({std::move(out), std::move(stats)});
                         return {};
                       }));
  }
  // one view: its result; an orbit of N views: a list of N results
  if (rendered.size() == 1 && (orbit == 0 || !orbitView.is_none()))
    return py::cast(
        renderResult(std::move(rendered[0].output), std::move(rendered[0].stats), width, height));
  py::list results;
  for (Rendered& r : rendered)
    results.append(py::cast(renderResult(std::move(r.output), std::move(r.stats), width, height)));
  return results;
}

// --- images -----------------------------------------------------------------------------------

py::array readPngArray(const py::object& pathArg) {
  const std::string path = pathText(pathArg);
  Image8 image;
  {
    py::gil_scoped_release release;
    image = unwrap(readPng(path));
  }
  const py::ssize_t h = image.height, w = image.width;
  return ownedArray<uint8_t>(std::move(image.rgba), {h, w, 4});
}

void writePngArray(const py::object& pathArg, const py::array& image) {
  const std::string path = pathText(pathArg);
  const Image8 encoded = image8Argument(image, "image");
  py::gil_scoped_release release;
  unwrap(writePng(path, encoded));
}

py::array encodeSrgbArray(const py::array& linear) {
  Image8 encoded = image8Argument(linear, "image");
  const py::ssize_t h = encoded.height, w = encoded.width;
  return ownedArray<uint8_t>(std::move(encoded.rgba), {h, w, 4});
}

py::array decodeSrgbArray(const py::array& srgb) {
  ImageRGB linear = decodeSrgb(image8Argument(srgb, "image"));
  const py::ssize_t h = linear.height, w = linear.width;
  return ownedArray<float>(std::move(linear.pixels), {h, w, 3});
}

}  // namespace

void addSceneAndRender(py::module_& m) {
  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene",
                                            "A loaded scene (mfr.load_scene): one flat triangle "
                                            "soup in world space with materials and cameras.")
      .def_readonly("name", &Scene::name, "The file path or procedural spec it was loaded from.")
      .def_readonly("primitives_skipped", &Scene::primitivesSkipped,
                    "The file's primitives that are not surfaces (glTF points, lines): not "
                    "rendered.")
      .def_property_readonly("triangle_count", &Scene::triangleCount)
      .def_property_readonly("vertex_count", &Scene::vertexCount)
      .def_property_readonly("material_count", [](const Scene& s) { return s.materials.size(); })
      .def_property_readonly("texture_count", [](const Scene& s) { return s.textures.size(); })
      .def_property_readonly(
          "cameras",
          [](const Scene& s) {
            py::list l;
            for (const Camera& c : s.cameras) l.append(cameraDict(c));
            return l;
          },
          "The file's cameras as dicts (eye, target, up, fov in degrees); render(view=i).")
      .def_property_readonly(
          "default_camera",
          [](const Scene& s) -> py::object {
            if (!s.defaultCamera) return py::none();
            return cameraDict(*s.defaultCamera);
          },
          "The camera a procedural scene frames itself with (None for files).")
      .def_property_readonly("bounds",
                             [](const Scene& s) {
                               const Bounds b = sceneBounds(s);
                               return py::make_tuple(vec3Tuple(b.min), vec3Tuple(b.max));
                             })
      .def_property(
          "background", [](const Scene& s) { return vec3Tuple(s.background); },
          [](Scene& s, const py::object& v) { s.background = backgroundArgument(v); },
          "Linear RGB behind everything, components in [0, 1].")
      .def_property(
          "alpha_override", [](const Scene& s) { return s.alphaOverride; },
          [](Scene& s, const py::object& v) { s.alphaOverride = alphaArgument(v); },
          "When set (0..1), every material is blended with this alpha; None: the file's.")
      .def_property(
          "cull", [](const Scene& s) { return std::string(toString(s.cull)); },
          [](Scene& s, const std::string& v) { s.cull = unwrap(parseCullMode(v, "cull")); },
          "Back faces culled: 'auto' (as the file says: glTF materials with doubleSided false), "
          "'none' or 'back' (every back face), as `mfr --cull`.")
      .def_property_readonly(
          "positions",
          [](py::object self) {
            const Scene& s = self.cast<const Scene&>();
            return viewOf<float>(reinterpret_cast<const float*>(s.positions.data()),
                                 {static_cast<py::ssize_t>(s.positions.size()), 3}, self);
          },
          "World-space vertex positions, float32 (V, 3), read-only view.")
      .def_property_readonly(
          "indices",
          [](py::object self) {
            const Scene& s = self.cast<const Scene&>();
            return viewOf<uint32_t>(s.indices.data(),
                                    {static_cast<py::ssize_t>(s.triangleCount()), 3}, self);
          },
          "Vertex indices of the triangles, uint32 (T, 3), read-only view.")
      .def("__repr__", [](const Scene& s) {
        return "<mfr.Scene '" + s.name + "': " + std::to_string(s.triangleCount()) +
               " triangles, " + std::to_string(s.materials.size()) + " materials, " +
               std::to_string(s.cameras.size()) + " cameras>";
      });

  m.def(
      "load_scene",
      [](const py::object& source, uint64_t seed, double transmissionFloor, const py::object& alpha,
         const py::object& background, const py::object& memoryLimit, bool allowOutsideReferences,
         const py::object& gltfScene) {
        return loadSceneArgument(pathText(source, "source"), seed, transmissionFloor, alpha,
                                 background, memoryLimitArgument(memoryLimit),
                                 allowOutsideReferences, gltfScene);
      },
      py::arg("source"), py::kw_only(), py::arg("seed") = 1, py::arg("transmission_floor") = 0.1,
      py::arg("alpha") = py::none(), py::arg("background") = py::none(),
      py::arg("memory_limit") = py::none(), py::arg("allow_outside_references") = false,
      py::arg("gltf_scene") = py::none(),
      R"(Loads a scene: a .gltf/.glb, .obj, .ply or JSON scene file, or "procedural:NAME[?k=v&...]".
seed: procedural scenes' seed; transmission_floor: glass alpha floor; alpha: override every
material's alpha (0..1); background: linear RGB; memory_limit: refuse scenes needing more (bytes
or "8GB"; default 75% of the physical memory); allow_outside_references: let a scene file name
files outside its folder (`mfr --allow-outside-references`). Raises mfr.Error naming the input.
gltf_scene: which of a glTF file's scenes (`mfr --scene N`; default the file's own). Points and
lines are not rendered: Scene.primitives_skipped counts them.)");

  py::class_<PyRenderResult>(m, "RenderResult",
                             "What mfr.render returns: images, per-pixel maps and statistics.")
      .def_readonly("image", &PyRenderResult::image,
                    "Linear RGB composited over the background, float32 (height, width, 3).")
      .def_readonly("srgb", &PyRenderResult::srgb,
                    "The image as written to PNG: sRGB-encoded RGBA, uint8 (height, width, 4), "
                    "alpha 255.")
      .def_readonly("k_map", &PyRenderResult::kMap,
                    "Fragment slots per pixel k(p), uint32 (height, width) (None for a method "
                    "without fragment slots).")
      .def_readonly("depth_complexity", &PyRenderResult::depthComplexity,
                    "Fragments per pixel n(p), uint32 (height, width) (None when not asked for "
                    "and the method ran no count pass).")
      .def_readonly("importance", &PyRenderResult::importance,
                    "Importance I(p), float32 (height, width), for vkb*/dkb*; else None.")
      .def_readonly("stats", &PyRenderResult::stats,
                    "The statistics as a dict, the keys of `mfr render --stats-json` (no "
                    "'image').")
      .def("__repr__", [](const PyRenderResult& r) {
        return "<mfr.RenderResult " + py::str(r.stats["method"]).cast<std::string>() + " " +
               py::str(r.image.attr("shape")).cast<std::string>() + ">";
      });

  m.def("render", &renderScene, py::arg("scene"), py::kw_only(), py::arg("method") = "abuffer",
        py::arg("budget") = py::none(), py::arg("k") = py::none(), py::arg("width") = 1024,
        py::arg("height") = 1024, py::arg("camera") = py::none(), py::arg("view") = py::none(),
        py::arg("orbit") = 0, py::arg("orbit_view") = py::none(), py::arg("zoom") = 1.0,
        py::arg("composite") = py::none(), py::arg("capture") = "tile", py::arg("threads") = 0,
        py::arg("seed") = 1, py::arg("model") = py::none(), py::arg("occupancy_d") = py::none(),
        py::arg("importance") = py::none(), py::arg("alpha") = py::none(),
        py::arg("background") = py::none(), py::arg("transmission_floor") = 0.1,
        py::arg("shuffle_draw_order") = py::none(), py::arg("gltf_scene") = py::none(),
        py::arg("cull") = py::none(), py::arg("blend") = py::none(), py::arg("engine") = "cpu",
        py::arg("gl_sync") = "auto", py::arg("gl_raster") = "native",
        py::arg("memory_limit") = py::none(), py::arg("allow_outside_references") = false,
        py::arg("depth_complexity") = true, py::arg("max_peels") = py::none(),
        py::arg("samples") = "1", py::arg("sample_storage") = "pixel",
        R"(Renders a scene (an mfr.Scene, or a source string loaded with `seed`) with one method, as
`mfr render` does with the same options, and returns an mfr.RenderResult (a list of them for an
orbit of several views). See mfr.render's Python documentation (python/mfr/__init__.py) for the
arguments.)");

  m.def("engine_names", &engineNames, "The engines render and compare accept (\"cpu\", \"gl\").");
  m.def("preset_names", &presetNames,
        "The method presets (each bounded one also as NAME+occupancy).");
  m.def(
      "parse_bytes", [](const std::string& text) { return unwrap(parseByteSize(text)); },
      py::arg("text"), "\"20MB\" -> 20971520 (binary units, as the command line's --budget).");

  m.def("read_png", &readPngArray, py::arg("path"),
        "Reads a PNG as uint8 (height, width, 4) RGBA (sRGB colour).");
  m.def("write_png", &writePngArray, py::arg("path"), py::arg("image"),
        "Writes uint8 (h, w, 3|4) sRGB, or float (h, w, 3) linear RGB (sRGB-encoded as mfr "
        "render does), as a PNG.");
  m.def("encode_srgb", &encodeSrgbArray, py::arg("image"),
        "Linear float (h, w, 3) -> sRGB uint8 (h, w, 4), exactly as images are written.");
  m.def("decode_srgb", &decodeSrgbArray, py::arg("image"),
        "sRGB uint8 (h, w, 3|4) -> linear float32 (h, w, 3).");
}

}  // namespace mfr::python

PYBIND11_MODULE(_mfr, m) {
  namespace py = pybind11;
  using namespace mfr::python;
  m.doc() = "mfr: bounded-memory multi-fragment rendering (the C++ library's Python binding)";
  m.attr("__version__") = MFR_VERSION;
  py::register_exception<LibraryError>(m, "Error", PyExc_RuntimeError);
#ifdef MFR_HAS_GL
  mfr::gl::registerGlEngine();  // engine="gl"
#endif
  addSceneAndRender(m);
  addMetricsAndCompare(m);
  addLearn(m);
}
