// The scene options every front end shares (the command line's render, compare and view, the
// Python module's render and compare): the image size, which camera and how many views, and the
// overrides applied to a loaded scene. The checks and the camera choice live here once; errors
// name the option as the caller spells it (mfr/core/option_name.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/option_name.hpp"
#include "mfr/core/result.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

struct SceneRequest {
  int width = 1024, height = 1024;    // --width, --height: [1, kMaxImageSize]
  std::string camera;                 // --camera "EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ[,FOV]]"
  std::vector<double> cameraNumbers;  // or those numbers (Python's camera=(...))
  int view = -1;                      // --view: the scene file's camera, by index
  int orbit = 0;                      // --orbit N: N views on a circle around the camera's target
  int orbitView = -1;                 // --orbit-view I: only view I of the N
  double zoom = 1.0;                  // --zoom: distance to the target divided by this
  std::optional<uint64_t> shuffleDrawOrder;  // --shuffle-draw-order SEED
  std::optional<double> alpha;               // --alpha: every material's alpha
  std::vector<double> background;            // --background R,G,B (linear; empty: the scene's)
  double transmissionFloor = 0.1;            // --transmission-floor (glTF transmission glass)
  std::optional<int> gltfScene;              // --scene N: which of a glTF file's scenes
  std::string cull;  // --cull auto|none|back (Scene::cull); empty: the scene's as it is
  /// --blend MODE or MATERIAL=MODE, repeatable, applied in order (scene/blend_mode.hpp)
  std::vector<std::string> blend;

  bool hasCamera() const { return !camera.empty() || !cameraNumbers.empty(); }
  /// True when applyToScene changes a loaded scene.
  bool changesScene() const {
    return shuffleDrawOrder || alpha || !background.empty() || !cull.empty() || !blend.empty();
  }
};

/// The checks that need no scene: sizes, ranges, one camera source, --orbit-view within --orbit.
Result<void> checkSceneRequest(const SceneRequest& request, Spelling spelling = Spelling::Cli);

/// The draw order, alpha, background, cull and blend overrides, applied to a loaded scene (a
/// request that passed checkSceneRequest). The one error: a --blend MATERIAL=MODE naming no
/// material of the scene.
Result<void> applyToScene(const SceneRequest& request, Scene& scene,
                          Spelling spelling = Spelling::Cli);

/// The views to render and, with --orbit-view I > 0, view I - 1 of the orbit (the frame before
/// the rendered one: its nearest |n.v| feeds the variable k-buffer's Fresnel term).
struct SceneViews {
  std::vector<Camera> cameras;
  std::optional<Camera> previousCamera;
};

/// The scene file's camera `index` as --view names it: Scene::cameras[index], the file's
/// index-th camera as `mfr info` lists it. One line naming `source` and the option otherwise: a
/// negative index, one beyond the file's cameras, or a camera the scene cannot render
/// (Scene::cameraProblems: a glTF orthographic camera, one no node places), never another camera.
Result<Camera> fileCamera(const Scene& scene, const std::string& source, int index,
                          Spelling spelling = Spelling::Cli);

/// The camera as every front end picks it: --camera, else the file's camera --view, else the
/// scene's own camera or one framing its bounds; moved --zoom times closer to its target; then
/// --orbit views around it. `source` names the scene in errors.
Result<SceneViews> sceneViews(const Scene& scene, const std::string& source,
                              const SceneRequest& request, Spelling spelling = Spelling::Cli);

}  // namespace mfr
