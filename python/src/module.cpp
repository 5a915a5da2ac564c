// The Python module mfr (_mfr, wrapped by python/mfr/__init__.py): scenes, rendering, images,
// metrics, comparisons (this file and metrics_compare.cpp) and the deep k-buffer's models and
// datasets (learn.cpp). Library errors raise mfr.Error with the library's one-line message; the
// GIL is released while the library works; arrays are returned over moved buffers, not copies.
#include <cmath>
#include <cstring>
#include <optional>
#include <type_traits>

#include "common.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/json_limits.hpp"
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
  // a scene or model path need not be UTF-8: such bytes become U+FFFD here (the "scene" of the
  // statistics is set from the path's bytes again, as os.fsdecode gives it)
  return py::module_::import("json").attr("loads")(mfr::jsonText(value, -1));
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
    else if (!isPath(model))
      throw py::type_error(
          "model: expected an mfr.Model or a .mfrnn path (str, bytes or "
          "os.PathLike), got " +
          typeName(model));
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
    const py::object& sceneArg, const py::object& methodArg, const py::object& budget,
    const py::object& k, const py::object& widthArg, const py::object& heightArg,
    const py::object& camera, const py::object& view, const py::object& orbitArg,
    const py::object& orbitView, const py::object& zoomArg, const py::object& composite,
    const py::object& captureArg, const py::object& threadsArg, const py::object& seedArg,
    const py::object& model, const py::object& occupancyD, const py::object& importance,
    const py::object& alpha, const py::object& background, const py::object& transmissionFloorArg,
    const py::object& shuffleDrawOrder, const py::object& gltfScene, const py::object& cull,
    const py::object& blend, const py::object& engineArg, const py::object& glSyncArg,
    const py::object& glRasterArg, const py::object& memoryLimitArg,
    const py::object& allowOutsideReferencesArg, const py::object& wantDepthComplexityArg,
    const py::object& maxPeels, const py::object& samplesArg, const py::object& sampleStorageArg) {
  // every argument converted (and its type checked) before any work
  const auto method = castArgument<std::string>(methodArg, "method");
  const int width = castArgument<int>(widthArg, "width");
  const int height = castArgument<int>(heightArg, "height");
  const int orbit = castArgument<int>(orbitArg, "orbit");
  const double zoom = castArgument<double>(zoomArg, "zoom");
  const auto capture = castArgument<std::string>(captureArg, "capture");
  const int threads = castArgument<int>(threadsArg, "threads");
  const auto seed = castArgument<uint64_t>(seedArg, "seed");
  const double transmissionFloor = castArgument<double>(transmissionFloorArg, "transmission_floor");
  const auto engineName = castArgument<std::string>(engineArg, "engine");
  const auto glSync = castArgument<std::string>(glSyncArg, "gl_sync");
  const auto glRaster = castArgument<std::string>(glRasterArg, "gl_raster");
  const bool allowOutsideReferences =
      castArgument<bool>(allowOutsideReferencesArg, "allow_outside_references");
  const bool wantDepthComplexity = castArgument<bool>(wantDepthComplexityArg, "depth_complexity");
  const auto sampleStorage = castArgument<std::string>(sampleStorageArg, "sample_storage");
  if (!py::isinstance<Scene>(sceneArg) && !isPath(sceneArg))
    throw py::type_error(
        "scene: expected an mfr.Scene or a source (str, bytes or os.PathLike), "
        "got " +
        typeName(sceneArg));
  const int samples = samplesArgument(samplesArg);
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
  const auto result = [&](Rendered& r) {
    PyRenderResult out = renderResult(std::move(r.output), std::move(r.stats), width, height);
    out.stats["scene"] = pathString(scene.source);
    return py::cast(std::move(out));
  };
  if (rendered.size() == 1 && (orbit == 0 || !orbitView.is_none())) return result(rendered[0]);
  py::list results;
  for (Rendered& r : rendered) results.append(result(r));
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

/// ValueError unless `path` ends in `format`'s extension (as the command line's --out): a PNG
/// is never written under another name.
void checkImagePath(const std::string& path, OutputImageFormat format) {
  if (auto checked = imageOutputFormat("path", path, {format}); !checked)
    throw py::value_error(checked.error().message);
}

void writePngArray(const py::object& pathArg, const py::object& image) {
  const std::string path = pathText(pathArg);
  checkImagePath(path, OutputImageFormat::Png);
  const Image8 encoded = image8Argument(image, "image");
  py::gil_scoped_release release;
  unwrap(writePng(path, encoded));
}

void writePfmArray(const py::object& pathArg, const py::object& imageArg) {
  const std::string path = pathText(pathArg);
  checkImagePath(path, OutputImageFormat::Pfm);
  const py::array image =
      arrayArgument(imageArg, "image", "a linear float image array (height, width, 3)");
  if (image.dtype().kind() != 'f')
    throw py::value_error("image: expected floating-point linear values, got dtype " +
                          std::string(py::str(static_cast<py::handle>(image.dtype()))) +
                          " (an sRGB uint8 image: decode_srgb first)");
  if (image.ndim() != 3 || image.shape(0) < 1 || image.shape(1) < 1 || image.shape(2) != 3)
    throw py::value_error("image: expected an array (height, width, 3)");
  if (image.shape(0) > kMaxImageSize || image.shape(1) > kMaxImageSize)
    throw py::value_error("image: larger than " + std::to_string(kMaxImageSize) + " pixels");
  const auto pixels = py::array_t<float, py::array::c_style | py::array::forcecast>(image);
  ImageRGB linear(static_cast<int>(image.shape(1)), static_cast<int>(image.shape(0)));
  std::memcpy(linear.pixels.data(), pixels.data(), sizeof(float) * 3 * linear.pixels.size());
  unwrap(checkFinite(linear, "image"));
  py::gil_scoped_release release;
  unwrap(writePfm(path, linear));
}

py::array encodeSrgbArray(const py::object& linear) {
  Image8 encoded = image8Argument(linear, "image");
  const py::ssize_t h = encoded.height, w = encoded.width;
  return ownedArray<uint8_t>(std::move(encoded.rgba), {h, w, 4});
}

py::array decodeSrgbArray(const py::object& srgb) {
  ImageRGB linear = decodeSrgb(image8Argument(srgb, "image"));
  const py::ssize_t h = linear.height, w = linear.width;
  return ownedArray<float>(std::move(linear.pixels), {h, w, 3});
}

}  // namespace

void addSceneAndRender(py::module_& m) {
  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene",
                                            "A loaded scene (mfr.load_scene): one flat triangle "
                                            "soup in world space with materials and cameras.")
      .def_property_readonly(
          "name", [](const Scene& s) { return pathString(s.name); },
          "The file path or procedural spec it was loaded from (os.fsdecode of its bytes).")
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
            for (size_t i = 0; i < s.cameras.size(); ++i) {
              if (i < s.cameraProblems.size() && !s.cameraProblems[i].empty()) {
                py::dict refused;
                refused["refused"] = s.cameraProblems[i];
                l.append(refused);
              } else {
                l.append(cameraDict(s.cameras[i]));
              }
            }
            return l;
          },
          "The file's cameras in the file's order, as dicts (eye, target, up, fov in degrees), "
          "or {'refused': why} for one mfr cannot render (orthographic, placed by no node); "
          "render(view=i) renders cameras[i], as `mfr info` lists them.")
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
          namedArguments(
              "Scene.",
              +[](Scene& s, const py::object& v) { s.background = backgroundArgument(v); }),
          "Linear RGB behind everything, components in [0, 1].")
      .def_property(
          "alpha_override", [](const Scene& s) { return s.alphaOverride; },
          namedArguments(
              "Scene.",
              +[](Scene& s, const py::object& v) {
                s.alphaOverride = alphaArgument(v, "alpha_override");
              }),
          "When set (0..1), every material is blended with this alpha; None: the file's.")
      .def_property(
          "cull", [](const Scene& s) { return std::string(toString(s.cull)); },
          namedArguments(
              "Scene.",
              +[](Scene& s, const py::object& v) {
                s.cull = unwrap(parseCullMode(castArgument<std::string>(v, "cull"), "cull"));
              }),
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
        return py::str("<mfr.Scene {!r}: {} triangles, {} materials, {} cameras>")
            .format(pathString(s.name), s.triangleCount(), s.materials.size(), s.cameras.size());
      });

  m.def(
      "load_scene",
      namedArguments(
          "load_scene(): ",
          +[](const py::object& source, const py::object& seed, const py::object& transmissionFloor,
              const py::object& alpha, const py::object& background, const py::object& memoryLimit,
              const py::object& allowOutsideReferences, const py::object& gltfScene) {
            const std::string path = pathText(source, "source");
            return loadSceneArgument(
                path, castArgument<uint64_t>(seed, "seed"),
                castArgument<double>(transmissionFloor, "transmission_floor"), alpha, background,
                memoryLimitArgument(memoryLimit),
                castArgument<bool>(allowOutsideReferences, "allow_outside_references"), gltfScene);
          }),
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

  m.def("render", namedArguments("render(): ", &renderScene), py::arg("scene"), py::kw_only(),
        py::arg("method") = "abuffer", py::arg("budget") = py::none(), py::arg("k") = py::none(),
        py::arg("width") = 1024, py::arg("height") = 1024, py::arg("camera") = py::none(),
        py::arg("view") = py::none(), py::arg("orbit") = 0, py::arg("orbit_view") = py::none(),
        py::arg("zoom") = 1.0, py::arg("composite") = py::none(), py::arg("capture") = "tile",
        py::arg("threads") = 0, py::arg("seed") = 1, py::arg("model") = py::none(),
        py::arg("occupancy_d") = py::none(), py::arg("importance") = py::none(),
        py::arg("alpha") = py::none(), py::arg("background") = py::none(),
        py::arg("transmission_floor") = 0.1, py::arg("shuffle_draw_order") = py::none(),
        py::arg("gltf_scene") = py::none(), py::arg("cull") = py::none(),
        py::arg("blend") = py::none(), py::arg("engine") = "cpu", py::arg("gl_sync") = "auto",
        py::arg("gl_raster") = "native", py::arg("memory_limit") = py::none(),
        py::arg("allow_outside_references") = false, py::arg("depth_complexity") = true,
        py::arg("max_peels") = py::none(), py::arg("samples") = 1,
        py::arg("sample_storage") = "pixel",
        R"(Renders a scene (an mfr.Scene, or a source string loaded with `seed`) with one method, as
`mfr render` does with the same options, and returns an mfr.RenderResult (a list of them for an
orbit of several views). See mfr.render's Python documentation (python/mfr/__init__.py) for the
arguments.)");

  m.def("engine_names", &engineNames, "The engines render and compare accept (\"cpu\", \"gl\").");
  m.def("preset_names", &presetNames,
        "The method presets (each bounded one also as NAME+occupancy).");
  m.def("parse_bytes",
        namedArguments(
            "parse_bytes(): ",
            +[](const py::object& text) {
              return unwrap(parseByteSize(castArgument<std::string>(text, "text")));
            }),
        py::arg("text"), "\"20MB\" -> 20971520 (binary units, as the command line's --budget).");

  m.def("read_png", namedArguments("read_png(): ", &readPngArray), py::arg("path"),
        "Reads a PNG as uint8 (height, width, 4) RGBA (sRGB colour).");
  m.def("write_png", namedArguments("write_png(): ", &writePngArray), py::arg("path"),
        py::arg("image"),
        "Writes uint8 (h, w, 3|4) sRGB, or float (h, w, 3) linear RGB (sRGB-encoded as mfr "
        "render does), as a PNG; the path must end in .png.");
  m.def("write_pfm", namedArguments("write_pfm(): ", &writePfmArray), py::arg("path"),
        py::arg("image"),
        "Writes float (h, w, 3) linear RGB as a Portable Float Map (as mfr render -o NAME.pfm: "
        "float32, rows bottom to top, little-endian); the path must end in .pfm.");
  m.def("encode_srgb", namedArguments("encode_srgb(): ", &encodeSrgbArray), py::arg("image"),
        "Linear float (h, w, 3) -> sRGB uint8 (h, w, 4), exactly as images are written.");
  m.def("decode_srgb", namedArguments("decode_srgb(): ", &decodeSrgbArray), py::arg("image"),
        "sRGB uint8 (h, w, 3|4) -> linear float32 (h, w, 3).");
}

}  // namespace mfr::python

PYBIND11_MODULE(_mfr, m) {
  namespace py = pybind11;
  using namespace mfr::python;
  m.doc() = "mfr: bounded-memory multi-fragment rendering (the C++ library's Python binding)";
  m.attr("__version__") = MFR_VERSION;
  // mfr.Error: the library's message, which may echo a path's bytes that are not UTF-8 (shown as
  // \xNN escapes rather than failing to make the message)
  static py::exception<LibraryError> error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const LibraryError& e) {
      const std::string_view text = e.what();
      const auto message = py::reinterpret_steal<py::object>(PyUnicode_DecodeUTF8(
          text.data(), static_cast<Py_ssize_t>(text.size()), "backslashreplace"));
      PyErr_SetObject(error.ptr(), message.ptr());
    }
  });
#ifdef MFR_HAS_GL
  mfr::gl::registerGlEngine();  // engine="gl"
#endif
  addSceneAndRender(m);
  addMetricsAndCompare(m);
  addLearn(m);
}
