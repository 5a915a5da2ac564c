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
#include "mfr/method/importance.hpp"
#include "mfr/scene/scene.hpp"

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
                                         bool allowOutsideReferences = false);

/// An mfr.Scene (copied only when alpha or background must change it) or a source string
/// (loaded with `seed`).
SceneArgument sceneArgument(const py::object& scene, uint64_t seed, const py::object& alpha,
                            const py::object& background, std::optional<uint64_t> memoryLimit);

/// None, or alpha in [0, 1].
std::optional<float> alphaArgument(const py::object& alpha);
/// Three finite numbers in [0, 1].
glm::vec3 backgroundArgument(const py::object& background);
/// Bytes as an int, or a size string ("20MB", parseByteSize).
uint64_t budgetArgument(const py::object& budget);
/// None (the library's default, defaultMemoryLimit()), bytes as an int, or a size string.
std::optional<uint64_t> memoryLimitArgument(const py::object& limit);
/// "tile" or "parallel".
CaptureMode captureArgument(const std::string& capture);
/// width, height in [1, kMaxImageSize], threads in [0, 1024] (0 = all cores).
RasterOptions rasterArgument(int width, int height, int threads);
/// The camera as `mfr render` picks it: `camera` (6, 9 or 10 numbers: eye, target, [up, [fov]], or
/// that text, checked by cameraFromNumbers / parseCameraSpec),
/// or the scene's camera `view`, or the scene's default camera / one framing its bounds; then
/// moved `zoom` times closer to its target.
Camera cameraArgument(const Scene& scene, const py::object& camera, const py::object& view,
                      double zoom);
/// An mfr.Model or a .mfrnn path; checked to fit the deep k-buffer (checkDkbModel).
std::shared_ptr<const learn::Model> modelArgument(const py::object& model);
/// vkb's importance parameters from a dict (alpha, n_limit, periphery_d, fovea, noise,
/// depth_term, periphery_term, fresnel_term, noise_term), defaults for keys not given.
ImportanceParams importanceArgument(const py::dict& params);
/// An image array: uint8 (h, w, 3|4) sRGB (alpha set to 255 for 3 channels), or floating-point
/// (h, w, 3) linear RGB, sRGB-encoded with encodeSrgb. `what` names it in errors.
Image8 image8Argument(const py::array& image, const char* what);

}  // namespace mfr::python
