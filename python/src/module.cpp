// The Python module mfr (_mfr, wrapped by python/mfr/__init__.py): scenes, rendering, images,
// metrics, comparisons (this file and metrics_compare.cpp) and the deep k-buffer's models and
// datasets (learn.cpp). Library errors raise mfr.Error with the library's one-line message; the
// GIL is released while the library works; arrays are returned over moved buffers, not copies.
#include <cmath>
#include <optional>
#include <type_traits>

#include "common.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/method/stats_json.hpp"
#include "mfr/scene/load.hpp"
#include "scene_options.hpp"

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

Result<uint32_t> parseK(const py::object& k) {
  const long long v = castArgument<long long>(k, "k");
  if (v < 1 || v > (1 << 20)) return makeError("k: must be in [1, 1048576]");
  return static_cast<uint32_t>(v);
}

/// The method as `mfr render` builds it from the same options (apps/mfr/cmd_render.cpp).
MethodDesc buildMethod(const std::string& name, const py::object& k, const py::object& composite,
                       const py::object& model, const py::object& occupancyD,
                       const py::object& importance, uint64_t seed) {
  MethodDesc m = unwrap(methodPreset(name));
  const auto applicable = [&](MethodOption option, const char* argument) {
    unwrap(checkMethodOption(option, m, argument));
  };
  if (!k.is_none()) {
    applicable(MethodOption::K, "k");
    const uint32_t value = unwrap(parseK(k));
    if (m.name.rfind("zbuffer", 0) == 0 && value != 1) throw LibraryError("k: zbuffer has k = 1");
    m.k = value;
  }
  if (!composite.is_none()) {
    applicable(MethodOption::Composite, "composite");
    m.compositing = unwrap(parseCompositing(castArgument<std::string>(composite, "composite")));
  }
  if (!model.is_none()) {
    applicable(MethodOption::Model, "model");
    m.model = modelArgument(model);
  }
  if (!importance.is_none()) applicable(MethodOption::ImportanceParams, "importance");
  if (m.allocation == AllocationPolicy::Importance) {
    ImportanceParams ip;
    if (!importance.is_none())
      ip = importanceArgument(castArgument<py::dict>(importance, "importance"));
    ip.seed = seed;
    m.importance = ip;
  }
  if (!occupancyD.is_none()) {
    applicable(MethodOption::OccupancyD, "occupancy_d");
    const long long d = castArgument<long long>(occupancyD, "occupancy_d");
    if (d < 1 || d > 64) throw LibraryError("occupancy_d: must be in [1, 64]");
    m.occupancyWords = static_cast<int>(d);
  }
  return m;
}

struct PyRenderResult {
  py::object image, srgb, kMap, depthComplexity, importance, stats;
};

PyRenderResult renderScene(const py::object& sceneArg, const std::string& method,
                           const py::object& budget, const py::object& k, int width, int height,
                           const py::object& camera, const py::object& view, double zoom,
                           const py::object& composite, const std::string& capture, int threads,
                           uint64_t seed, const py::object& model, const py::object& occupancyD,
                           const py::object& importance, const py::object& alpha,
                           const py::object& background, const py::object& memoryLimitArg,
                           bool wantDepthComplexity) {
  const std::optional<uint64_t> memoryLimit = memoryLimitArgument(memoryLimitArg);
  SceneArgument scene = sceneArgument(sceneArg, seed, alpha, background, memoryLimit);
  const MethodDesc m = buildMethod(method, k, composite, model, occupancyD, importance, seed);
  RenderOptions options;
  if (!budget.is_none()) options.budgetBytes = budgetArgument(budget);
  options.capture = captureArgument(capture);
  options.background = scene.scene->background;
  options.memoryLimitBytes = memoryLimit;
  RasterOptions ro = rasterArgument(width, height, threads);
  const Camera cam = cameraArgument(*scene.scene, camera, view, zoom);

  RenderOutput out;
  {
    py::gil_scoped_release release;
    CpuEngine engine(EngineOptions{ro.threads, ro.tileSize});
    if (auto fits = engine.preflight(ro.width, ro.height, m, options); !fits)
      throw LibraryError(echoPath(scene.source) + ": " + fits.error().message);
    auto view = engine.prepare(View{&*scene.scene, cam, ro.width, ro.height});
    if (!view) throw LibraryError(echoPath(scene.source) + ": " + view.error().message);
    auto rendered = engine.render(**view, m, options);
    if (!rendered) throw LibraryError(echoPath(scene.source) + ": " + rendered.error().message);
    out = std::move(rendered.value());
    if (wantDepthComplexity && out.depthComplexity.empty())
      out.depthComplexity = unwrap(engine.countFragments(**view));
  }

  // the statistics exactly as `mfr render --stats-json` writes them (less "image": no file)
  nlohmann::json stats = statsToJson(out.stats);
  stats["scene"] = scene.source;
  stats["width"] = ro.width;
  stats["height"] = ro.height;
  stats["view"] = 0;
  stats["compositing"] = toString(m.compositing);
  stats["capture"] = capture;

  const py::ssize_t h = ro.height, w = ro.width;
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
         const py::object& background, const py::object& memoryLimit, bool allowOutsideReferences) {
        return loadSceneArgument(pathText(source, "source"), seed, transmissionFloor, alpha,
                                 background, memoryLimitArgument(memoryLimit),
                                 allowOutsideReferences);
      },
      py::arg("source"), py::kw_only(), py::arg("seed") = 1, py::arg("transmission_floor") = 0.1,
      py::arg("alpha") = py::none(), py::arg("background") = py::none(),
      py::arg("memory_limit") = py::none(), py::arg("allow_outside_references") = false,
      R"(Loads a scene: a .gltf/.glb, .obj, .ply or JSON scene file, or "procedural:NAME[?k=v&...]".
seed: procedural scenes' seed; transmission_floor: glass alpha floor; alpha: override every
material's alpha (0..1); background: linear RGB; memory_limit: refuse scenes needing more (bytes
or "8GB"; default 75% of the physical memory); allow_outside_references: let a scene file name
files outside its folder (`mfr --allow-outside-references`). Raises mfr.Error naming the input.)");

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
        py::arg("zoom") = 1.0, py::arg("composite") = py::none(), py::arg("capture") = "tile",
        py::arg("threads") = 0, py::arg("seed") = 1, py::arg("model") = py::none(),
        py::arg("occupancy_d") = py::none(), py::arg("importance") = py::none(),
        py::arg("alpha") = py::none(), py::arg("background") = py::none(),
        py::arg("memory_limit") = py::none(), py::arg("depth_complexity") = true,
        R"(Renders a scene (an mfr.Scene, or a source string loaded with `seed`) with one method, as
`mfr render` does with the same options, and returns an mfr.RenderResult. See mfr.render's
Python documentation (python/mfr/__init__.py) for the arguments.)");

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
  addSceneAndRender(m);
  addMetricsAndCompare(m);
  addLearn(m);
}
