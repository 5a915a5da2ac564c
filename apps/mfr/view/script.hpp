// --script FILE.json: a session as a list of UI actions, applied one per frame, for tests and for
// reproducing what a person did. The file is a JSON array of objects; each object is one frame's
// actions, applied in this order:
//   {"method": "fkb"}  {"composite": "hybrid"}  {"budget_mb": 2.5}  {"budget": "3MB"}  {"k": 4}
//   {"mode": "flip"}  (image depth kmap importance truth flip wiper)  {"wiper": 0.3}
//   {"orbit": 30}  {"pitch": 10}  {"pan": [0.1, 0]}  {"zoom": 1.5}  {"fov": 50}  {"reset": true}
//   {"compare": false}  (no A-buffer, FLIP or PSNR unless the view needs them)
//   {"fly": [right, up, forward]}  (WASD/QE, in units of the distance to the target)
//   {"file_camera": N}  (the scene file's camera N, as `mfr render --view N`)
//   {"next_camera": 1}  (+1 next, -1 previous file camera)  {"open": "scene.gltf"}  (as a drop)
//   {"occupancy_d": 2}  (+occupancy presets)  {"model": "net.mfrnn"}  (dkb*; "" the built-in)
//   {"importance": {"alpha": 0.4, "n_limit": 20, "periphery_d": 3, "noise": 0.1,
//                   "depth": true, "periphery": true, "fresnel": true, "noise_term": true,
//                   "fovea": [x, y]}}  (vkb*; fovea in pixels, null: the image centre)
//   {"budget_share": 0.5}  (the budget as a share of the exact A-buffer's bytes)
//   {"screenshot": "a.png"}  {"screenshot_ui": "b.png"}  {"copy_command": true}
//   {"screenshot_maps": "shot"}  (shot-image.png, shot-depth.png, shot-kmap.png, ... : the image
//                                 and every map the method has, each as its view mode shows it)
// Screenshots are taken after the frame's settings have been rendered.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/core/result.hpp"
#include "view_settings.hpp"

namespace mfr::view {

struct FrameActions {
  std::vector<std::string> screenshots;     // image area
  std::vector<std::string> screenshotsUi;   // whole window with the panel
  std::vector<std::string> screenshotMaps;  // prefixes: the image and every map
  bool copyCommand = false;
  std::optional<int> fileCamera;      // an index into the scene's cameras
  int nextCamera = 0;                 // +1 / -1: the next / previous file camera
  std::string open;                   // a scene to open (as a file dropped on the window)
  std::optional<double> budgetShare;  // of the exact A-buffer's bytes
};

/// Reads and checks a script (unknown keys and wrong types are one-line errors naming the step).
Result<std::vector<nlohmann::json>> loadScript(const std::string& path);

/// Applies one step to the settings; what is not a setting goes into `actions`.
Result<void> applyStep(const nlohmann::json& step, ViewSettings& settings, FrameActions& actions);

}  // namespace mfr::view
