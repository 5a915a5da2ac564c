// Everything the panel, the mouse and a script change. A render is keyed by the parts it depends
// on, so the viewer re-renders only when one of them changed.
#pragma once

#include <cstdint>
#include <string>

#include "mfr/method/importance.hpp"
#include "orbit_camera.hpp"
#include "view_mode.hpp"

namespace mfr::view {

struct ViewSettings {
  std::string method = "abuffer";  // a preset name (presetNames(), optionally +occupancy)
  std::string composite;           // empty: the preset's own rule; else kbuffer or hybrid
  uint64_t budgetBytes = 0;        // 0: no budget
  uint32_t k = 0;                  // 0: derived from the budget
  int occupancyD = 0;              // +occupancy presets: bucket words d (0: the preset's)
  int maxPeels = 0;                // peel, dual-peel: at most this many passes (0: unbounded)
  ImportanceParams importance;     // vkb*: Eq. 3-6 parameters and factor switches
  std::string model;               // dkb*: a .mfrnn network (empty: the built-in one)
  ViewMode mode = ViewMode::Image;
  float wiper = 0.5f;   // split position of the wiper view, share of the width
  bool compare = true;  // render the exact A-buffer for mean FLIP and PSNR (always for its views)
  OrbitCamera camera;

  explicit ViewSettings(const Camera& start) : camera(start) {}
  /// The key of the method's render (method, rule, budget, k, method parameters, camera).
  std::string methodKey() const;
  /// The key of what the image area shows (the render plus the view mode and wiper).
  std::string displayKey() const;
};

}  // namespace mfr::view
