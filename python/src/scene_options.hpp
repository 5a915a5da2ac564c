// Arguments of the Python functions turned into library values, with the checks and one-line
// messages of the command line's options (apps/mfr/common.cpp, cmd_render.cpp) under the Python
// argument names. Failures raise mfr.Error (LibraryError); wrong array shapes raise ValueError.
#pragma once

#include <memory>
#include <string>

#include "common.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/scene/scene.hpp"
#include "mfr/scene/scene_request.hpp"

namespace mfr::python {

struct SceneArgument {
  std::shared_ptr<const Scene> scene;
  std::string source;  // as given (the "scene" of the statistics)
};

/// load_scene's work: loads with the GIL released, then applies alpha / background.
std::shared_ptr<Scene> loadSceneArgument(const std::string& source, uint64_t seed,
                                         double transmissionFloor, const py::object& alpha,
                                         const py::object& background,
                                         std::optional<uint64_t> memoryLimit,
                                         bool allowOutsideReferences = false,
                                         const py::object& gltfScene = py::none());

/// An mfr.Scene (copied only when the request changes it: draw order, alpha, background) or a
/// source string (loaded with `seed`, the request's transmission floor and overrides applied).
SceneArgument sceneArgument(const py::object& scene, uint64_t seed, const SceneRequest& request,
                            std::optional<uint64_t> memoryLimit,
                            bool allowOutsideReferences = false);

/// The scene options as the library checks them (checkSceneRequest, Python spelling): camera as
/// 6, 9 or 10 numbers or the command line's text, the file's camera `view`, an orbit of N views
/// (or view `orbit_view` of it), zoom, alpha, background, transmission floor, draw order.
SceneRequest sceneRequestArgument(int width, int height, const py::object& camera,
                                  const py::object& view, int orbit, const py::object& orbitView,
                                  double zoom, const py::object& alpha,
                                  const py::object& background, double transmissionFloor,
                                  const py::object& shuffleDrawOrder, const py::object& gltfScene,
                                  const py::object& cull, const py::object& blend);

/// A budget: bytes as an int, a size ("20MB") or a share of the A-buffer ("25%").
BudgetSpec budgetSpecArgument(const py::object& budget, const std::string& name = "budget");

/// None, or alpha in [0, 1].
std::optional<float> alphaArgument(const py::object& alpha, const char* name = "alpha");
/// Three finite numbers in [0, 1].
glm::vec3 backgroundArgument(const py::object& background);
/// Bytes as an int, or a size string ("20MB", parseByteSize).
uint64_t budgetArgument(const py::object& budget, const std::string& name = "budget");
/// None (the library's default, defaultMemoryLimit()), bytes as an int, or a size string.
std::optional<uint64_t> memoryLimitArgument(const py::object& limit);
/// `samples`: 1, 2, 4 or 8 as an int or the command line's text.
int samplesArgument(const py::object& samples);
/// `sample_counts`: None (none), a list of ints or the command line's text ("1,4,8").
std::vector<int> sampleCountsArgument(const py::object& counts);
/// "tile" or "parallel".
CaptureMode captureArgument(const std::string& capture);
/// vkb's importance parameters from a dict (alpha, n_limit, periphery_d, fovea, noise,
/// depth_term, periphery_term, fresnel_term, noise_term): their types here, their ranges in
/// makeMethod.
ImportanceOverrides importanceArgument(const py::dict& params);
/// An image array: uint8 (h, w, 3|4) sRGB (alpha set to 255 for 3 channels), or floating-point
/// (h, w, 3) linear RGB, sRGB-encoded with encodeSrgb. `what` names it in errors.
Image8 image8Argument(const py::object& image, const char* what);

}  // namespace mfr::python
