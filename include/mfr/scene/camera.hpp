// Pinhole camera (OpenGL conventions: right-handed view space looking down -z, clip z in [-w, w],
// window depth in [0, 1]).
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace mfr {

struct Bounds;

struct Camera {
  glm::vec3 eye{0.0f, 0.0f, 5.0f};
  glm::vec3 target{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fovYDegrees = 45.0f;
  /// Clip planes; 0 means "fit to the scene bounds" (see fitClipPlanes).
  float zNear = 0.0f;
  float zFar = 0.0f;
};

/// A camera that frames the bounds from the +z side, slightly above, the whole sphere in view.
Camera frameBounds(const Bounds& bounds, float fovYDegrees = 45.0f);

/// Near/far planes that enclose the bounds sphere as tightly as possible (near never below
/// 1e-3 of the radius), keeping explicit non-zero values.
Camera fitClipPlanes(const Camera& camera, const Bounds& bounds);

/// N cameras on a circle around the target (about the camera's up axis), starting at the given
/// camera's position: view i is rotated by 360 * i / N degrees.
std::vector<Camera> orbit(const Camera& camera, int views);

/// View and projection matrices for a width x height viewport.
glm::mat4 viewMatrix(const Camera& camera);
glm::mat4 projectionMatrix(const Camera& camera, int width, int height);

/// World-space ray through the centre of pixel (x, y) (row 0 at the top): origin and unit
/// direction.
struct Ray {
  glm::vec3 origin;
  glm::vec3 direction;
};
Ray pixelRay(const Camera& camera, int width, int height, int x, int y);

}  // namespace mfr
