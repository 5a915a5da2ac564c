// The shared scene options (scene_request.hpp).
#include "mfr/scene/scene_request.hpp"

#include <cmath>

#include "mfr/core/quote.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/scene/camera_spec.hpp"
#include "mfr/scene/draw_order.hpp"

namespace mfr {

Result<void> checkSceneRequest(const SceneRequest& r, Spelling spelling) {
  const auto flag = [&](const char* cli) { return spell(spelling, cli); };
  if (r.width < 1 || r.height < 1 || r.width > kMaxImageSize || r.height > kMaxImageSize)
    return makeError(flag("--width/--height") + " " + std::to_string(r.width) + "x" +
                     std::to_string(r.height) + ": must be in [1, " +
                     std::to_string(kMaxImageSize) + "]");
  if (r.orbit < 0 || r.orbit > 10000)
    return makeError(flag("--orbit") + " " + std::to_string(r.orbit) + ": must be in [1, 10000]");
  if (r.orbitView < -1) return makeError(flag("--orbit-view") + ": must be a view index (0-based)");
  if (r.orbitView >= 0 && r.orbitView >= r.orbit)
    return makeError(flag("--orbit-view") + " " + std::to_string(r.orbitView) + ": needs " +
                     flag("--orbit") + " N with N > " + std::to_string(r.orbitView));
  if (!(r.zoom >= 0.01 && r.zoom <= 100.0))
    return makeError(flag("--zoom") + ": must be in [0.01, 100]");
  if (r.alpha && !(*r.alpha >= 0.0 && *r.alpha <= 1.0))
    return makeError(flag("--alpha") + ": must be in [0, 1]");
  for (double b : r.background)
    if (!std::isfinite(b))
      return makeError(flag("--background") + ": values must be finite numbers");
  if (!r.background.empty() && r.background.size() != 3)
    return makeError(flag("--background") + ": expected three numbers R, G, B");
  for (double b : r.background)
    if (b < 0.0 || b > 1.0)
      return makeError(flag("--background") + ": components must be in [0, 1]");
  if (!(r.transmissionFloor >= 0.0 && r.transmissionFloor <= 1.0))
    return makeError(flag("--transmission-floor") + ": must be in [0, 1]");
  if (!r.cull.empty()) MFR_TRY(parseCullMode(r.cull, flag("--cull")));
  for (const std::string& b : r.blend) MFR_TRY(parseBlendOverride(b, flag("--blend")));
  if (r.view < -1) return makeError(flag("--view") + ": must be a camera index (0-based)");
  if (r.gltfScene && *r.gltfScene < 0)
    return makeError(spell(spelling, spelling == Spelling::Cli ? "--scene" : "gltf_scene") +
                     ": must be a scene index (0-based)");
  if (r.hasCamera() && r.view >= 0)
    return makeError(flag("--view") + " and " + flag("--camera") + ": give one camera, not both");
  if (!r.camera.empty()) MFR_TRY(parseCameraSpec(r.camera, flag("--camera")));
  if (!r.cameraNumbers.empty()) MFR_TRY(cameraFromNumbers(r.cameraNumbers, flag("--camera")));
  return {};
}

Result<void> applyToScene(const SceneRequest& r, Scene& scene, Spelling spelling) {
  if (r.shuffleDrawOrder) shuffleDrawOrder(scene, *r.shuffleDrawOrder);
  if (r.alpha) scene.alphaOverride = static_cast<float>(*r.alpha);
  if (r.background.size() == 3)
    scene.background = glm::vec3(r.background[0], r.background[1], r.background[2]);
  if (auto cull = parseCullMode(r.cull, "--cull"); cull && !r.cull.empty()) scene.cull = *cull;
  for (const std::string& text : r.blend) {
    const std::string name = spell(spelling, "--blend");
    auto o = parseBlendOverride(text, name);
    if (!o) return o.error();
    bool named = false;
    for (Material& m : scene.materials)
      if (o->material.empty() || m.name == o->material) {
        m.blend = o->mode;
        named = true;
      }
    if (!named) {
      std::string known;
      for (const Material& m : scene.materials)
        if (!m.name.empty() && known.size() < 200)
          known += (known.empty() ? "" : ", ") + quoteInput(m.name, 40);
      return makeError(name + " " + quoteInput(text) + ": the scene has no material named " +
                       quoteInput(o->material) +
                       (known.empty() ? "" : " (materials: " + known + ")"));
    }
  }
  return {};
}

Result<Camera> fileCamera(const Scene& scene, const std::string& source, int index,
                          Spelling spelling) {
  const std::string what =
      echoPath(source) + ": " + spell(spelling, "--view") + " " + std::to_string(index);
  if (index < 0) return makeError(what + ": must be a camera index (0-based)");
  const size_t i = static_cast<size_t>(index);
  if (i >= scene.cameras.size())
    return makeError(what + " but the scene has " + std::to_string(scene.cameras.size()) +
                     " camera(s)");
  if (i < scene.cameraProblems.size() && !scene.cameraProblems[i].empty())
    return makeError(what + ": camera " + std::to_string(index) + " " +
                     oneLine(scene.cameraProblems[i], 300));
  return scene.cameras[i];
}

Result<SceneViews> sceneViews(const Scene& scene, const std::string& source, const SceneRequest& r,
                              Spelling spelling) {
  Camera camera;
  if (!r.camera.empty()) {
    auto parsed = parseCameraSpec(r.camera, spell(spelling, "--camera"));
    if (!parsed) return parsed.error();
    camera = parsed.value();
  } else if (!r.cameraNumbers.empty()) {
    auto made = cameraFromNumbers(r.cameraNumbers, spell(spelling, "--camera"));
    if (!made) return made.error();
    camera = made.value();
  } else if (r.view >= 0) {
    auto chosen = fileCamera(scene, source, r.view, spelling);
    if (!chosen) return chosen.error();
    camera = chosen.value();
  } else if (scene.defaultCamera) {
    camera = *scene.defaultCamera;
  } else {
    camera = frameBounds(sceneBounds(scene));
  }
  camera.eye = camera.target + (camera.eye - camera.target) / static_cast<float>(r.zoom);
  SceneViews views;
  views.cameras = r.orbit > 0 ? orbit(camera, r.orbit) : std::vector<Camera>{camera};
  if (r.orbitView > 0) views.previousCamera = views.cameras[r.orbitView - 1];
  if (r.orbitView >= 0) views.cameras = {views.cameras[r.orbitView]};
  return views;
}

}  // namespace mfr
