// The ImGui panel on the right of the image: method, compositing, budget, k, view mode, camera,
// live statistics and the screenshot / copy-command buttons. It edits the settings in place.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "frame_renderer.hpp"
#include "view_settings.hpp"

namespace mfr::view {

struct PanelInfo {
  std::string scene;
  std::string engine;
  int width = 0, height = 0;
  const Frame* frame = nullptr;
  double frameMs = 0.0;    // last frame, wall time
  int fileCameras = 0;     // the scene file's cameras
  int fileCamera = -1;     // the one last chosen (-1: none)
  std::string notice;      // one line: a scene that did not open
  bool rendering = false;  // a render of newer settings is in flight (the image is the last one)
};

struct PanelRequests {
  bool screenshot = false;
  bool screenshotMaps = false;  // the image and every map of the current settings
  bool copyCommand = false;
  int nextCamera = 0;                 // +1 / -1: the next / previous file camera
  std::optional<double> budgetShare;  // of the exact A-buffer's bytes
};

/// Every preset the viewer offers: presetNames() and their +occupancy forms.
const std::vector<std::string>& viewerMethods();

/// Draws the panel at x, full height, `width` wide.
PanelRequests drawPanel(float x, float width, float height, ViewSettings& settings,
                        const PanelInfo& info);

}  // namespace mfr::view
