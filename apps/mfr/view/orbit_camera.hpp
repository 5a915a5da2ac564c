// The viewer's camera: orbit around the target, pan, zoom, reset to the starting camera, and the
// `--camera` text that reproduces it in `mfr render`.
#pragma once

#include <string>

#include "mfr/scene/camera.hpp"

namespace mfr::view {

class OrbitCamera {
 public:
  explicit OrbitCamera(const Camera& start) : start_(start), camera_(start) {}
  const Camera& camera() const { return camera_; }
  /// Rotates the eye around the target: yaw about the up axis, pitch about the right axis
  /// (degrees; the pitch stops short of the up axis).
  void orbit(float yawDegrees, float pitchDegrees);
  /// Moves eye and target in the image plane by fractions of the view's height at the target.
  void pan(float dx, float dy);
  /// Distance to the target divided by `factor` (> 1 moves closer).
  void zoom(float factor);
  void setFov(float degrees);
  void reset() { camera_ = start_; }
  /// WASD fly: moves eye and target together, `right` sideways, `up` along the camera's up and
  /// `forward` along the view direction, each in units of the distance to the target.
  void fly(float right, float up, float forward);
  /// A new starting camera (a file camera, a newly opened scene): reset() returns to it.
  void restart(const Camera& start) { start_ = camera_ = start; }
  /// "EX,EY,EZ,TX,TY,TZ,UX,UY,UZ,FOV", exact enough to give the same image in `mfr render`.
  std::string spec() const;

 private:
  Camera start_;
  Camera camera_;
};

}  // namespace mfr::view
