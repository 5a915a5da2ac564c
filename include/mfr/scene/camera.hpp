// Pinhole camera (OpenGL conventions: right-handed view space looking down -z, clip z in [-w, w],
// window depth in [0, 1]).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/result.hpp"

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

/// The narrowest vertical field of view mfr renders: 2^-9 radians (0.112 degrees). A pixel row of
/// the tallest image (16384 rows) then spans 2^-23 radians, single precision's relative step
/// (FLT_EPSILON): the view transform rounds a point's position by about that much of its
/// coordinates, so for a scene whose coordinates are about its distance from the eye a narrower
/// view rounds by more than a pixel (a quad framed to cover 1024 of 64 x 64 pixels, coordinates
/// 1, distance 5: 1444 pixels at 1e-5 degrees, none at 1e-10); at 1e-37 degrees the focal scale
/// 1 / tan(fov / 2) is no longer a float at all.
inline constexpr double kMinFovYRadians = 0x1p-9;
inline constexpr double kMinFovYDegrees = kMinFovYRadians * 57.295779513082320876798;

/// Whether a vertical field of view in degrees is one mfr renders: in [kMinFovYDegrees, 180).
bool validFovYDegrees(double degrees);

/// Near planes beyond this (an explicit one, or the one fitClipPlanes fits) are refused by the
/// engines: the perspective projection multiplies 2 far near in single precision, which overflows
/// FLT_MAX (3.4e38) for far > near > 9.2e18. Scene coordinates stop at kMaxCoordinate (1e18) too.
inline constexpr float kMaxNearPlane = 1e18f;

/// The farthest far plane the projection takes with near plane `zNear`: FLT_MAX / 4 / max(near, 1)
/// (at least 8.5e19). glm::perspective computes 2 far, 2 far near and far + near, and the surface
/// point (method_math.h) 2 near far / (far + near - ...), all in single precision: with this bound
/// each stays at or below FLT_MAX / 2. A farther plane (glTF zfar 1e300, a JSON scene's far 3e38)
/// overflowed to an infinite or NaN projection and an empty image; fitClipPlanes clamps it to this
/// bound instead. That cuts nothing a nearer plane would show (scene coordinates stop at
/// kMaxCoordinate, 1e18), and for a near plane below 1e15 the clamped projection is the
/// infinite-far one already: its (f + n) / (f - n) rounds to 1.
float maxFarPlane(float zNear);

/// kMinFovYDegrees as the messages that refuse a narrower view write it, and why.
inline constexpr const char* kMinFovText = "0.112 degrees (2^-9 = 0.00195 rad)";
inline constexpr const char* kNarrowFovReason =
    "a pixel of a 16384-row image would span less than single precision's step, 2^-23 rad";

/// What the engines check of a camera's projection beyond its orientation: the field of view
/// (validFovYDegrees), eye and target at most 1e19 apart (the view transform squares their
/// distance in single precision) and the near plane of `fitted` (fitClipPlanes of `camera`)
/// within kMaxNearPlane. Errors are one line starting "camera: ".
Result<void> checkProjection(const Camera& camera, const Camera& fitted);

/// A camera that frames the bounds from the +z side, slightly above, the whole sphere in view.
Camera frameBounds(const Bounds& bounds, float fovYDegrees = 45.0f);

/// Near/far planes that enclose the bounds sphere as tightly as possible (near never below
/// 1e-3 of the radius), keeping explicit non-zero values; a far plane beyond maxFarPlane(near) is
/// clamped to it.
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
