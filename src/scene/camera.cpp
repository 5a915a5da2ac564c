#include "mfr/scene/camera.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "mfr/scene/scene.hpp"

namespace mfr {
namespace {

/// Eye and target farther apart than this are refused by checkProjection: the view transform
/// (glm::lookAt) and fitClipPlanes normalise target - eye in single precision, squaring the
/// distance, which overflows beyond 1.8e19 (the view direction became zero and the image empty).
constexpr double kMaxEyeTargetDistance = 1e19;

}  // namespace

bool validFovYDegrees(double degrees) {
  return degrees >= kMinFovYDegrees && degrees < 180.0;
}

float maxFarPlane(float zNear) {
  return std::numeric_limits<float>::max() / 4.0f / std::max(zNear, 1.0f);
}

Result<void> checkProjection(const Camera& camera, const Camera& fitted) {
  char text[160];
  if (!validFovYDegrees(camera.fovYDegrees)) {
    std::snprintf(text, sizeof text, "camera: field of view %g degrees ", camera.fovYDegrees);
    if (!(camera.fovYDegrees > 0.0f && camera.fovYDegrees < 180.0f))
      return makeError(std::string(text) + "must be in (0, 180)");
    return makeError(std::string(text) + "is narrower than " + kMinFovText + " (" +
                     kNarrowFovReason + ")");
  }
  const double distance = glm::length(glm::dvec3(camera.target) - glm::dvec3(camera.eye));
  if (!(distance <= kMaxEyeTargetDistance)) {
    std::snprintf(text, sizeof text, "camera: eye and target %g apart, beyond 1e19", distance);
    return makeError(std::string(text) +
                     ": the view transform squares their distance in single precision");
  }
  if (!(fitted.zNear <= kMaxNearPlane)) {
    std::snprintf(text, sizeof text, "camera: near plane %g%s is beyond 1e18", fitted.zNear,
                  camera.zNear > 0.0f ? "" : " (fitted to the scene's distance from the eye)");
    return makeError(std::string(text) +
                     ": the projection's 2 far near would overflow single precision");
  }
  return {};
}

Camera frameBounds(const Bounds& bounds, float fovYDegrees) {
  Camera camera;
  const float radius = std::max(bounds.radius(), 1e-6f);
  const float distance = radius / std::sin(glm::radians(fovYDegrees) * 0.5f) * 1.05f;
  const glm::vec3 direction = glm::normalize(glm::vec3(0.0f, 0.35f, 1.0f));
  camera.target = bounds.center();
  camera.eye = bounds.center() + direction * distance;
  camera.up = {0.0f, 1.0f, 0.0f};
  camera.fovYDegrees = fovYDegrees;
  return camera;
}

Camera fitClipPlanes(const Camera& camera, const Bounds& bounds) {
  Camera fitted = camera;
  const float radius = std::max(bounds.radius(), 1e-6f);
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const float centerDepth = glm::dot(bounds.center() - camera.eye, forward);
  if (fitted.zNear <= 0.0f) fitted.zNear = std::max(centerDepth - radius * 1.01f, radius * 1e-3f);
  if (fitted.zFar <= 0.0f)
    fitted.zFar = std::max(centerDepth + radius * 1.01f, fitted.zNear * 2.0f);
  fitted.zFar = std::min(fitted.zFar, maxFarPlane(fitted.zNear));
  return fitted;
}

std::vector<Camera> orbit(const Camera& camera, int views) {
  std::vector<Camera> cameras;
  const glm::vec3 axis = glm::normalize(camera.up);
  for (int i = 0; i < views; ++i) {
    const float angle = glm::two_pi<float>() * static_cast<float>(i) / static_cast<float>(views);
    const glm::mat4 rotation = glm::rotate(glm::mat4(1.0f), angle, axis);
    Camera c = camera;
    c.eye = camera.target + glm::vec3(rotation * glm::vec4(camera.eye - camera.target, 0.0f));
    cameras.push_back(c);
  }
  return cameras;
}

glm::mat4 viewMatrix(const Camera& camera) {
  return glm::lookAt(camera.eye, camera.target, camera.up);
}

glm::mat4 projectionMatrix(const Camera& camera, int width, int height) {
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  return glm::perspective(glm::radians(camera.fovYDegrees), aspect, camera.zNear, camera.zFar);
}

Ray pixelRay(const Camera& camera, int width, int height, int x, int y) {
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5f);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const float ndcX = (2.0f * (static_cast<float>(x) + 0.5f) / static_cast<float>(width)) - 1.0f;
  const float ndcY = 1.0f - (2.0f * (static_cast<float>(y) + 0.5f) / static_cast<float>(height));
  const glm::vec3 direction = forward + right * (ndcX * tanHalf * aspect) + up * (ndcY * tanHalf);
  return {camera.eye, glm::normalize(direction)};
}

}  // namespace mfr
