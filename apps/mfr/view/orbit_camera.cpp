#include "orbit_camera.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/gtc/matrix_transform.hpp>

namespace mfr::view {

void OrbitCamera::orbit(float yawDegrees, float pitchDegrees) {
  const glm::vec3 up = glm::normalize(camera_.up);
  glm::vec3 offset = camera_.eye - camera_.target;
  const glm::mat4 yaw = glm::rotate(glm::mat4(1.0f), glm::radians(yawDegrees), up);
  offset = glm::vec3(yaw * glm::vec4(offset, 0.0f));
  const float distance = glm::length(offset);
  // pitch: keep at least 2 degrees away from the up axis
  const float current =
      glm::degrees(std::acos(std::clamp(glm::dot(offset / distance, up), -1.0f, 1.0f)));
  const float wanted = std::clamp(current - pitchDegrees, 2.0f, 178.0f);
  const glm::vec3 right = glm::normalize(glm::cross(up, offset));
  const glm::mat4 pitch = glm::rotate(glm::mat4(1.0f), glm::radians(current - wanted), right);
  offset = glm::vec3(pitch * glm::vec4(offset, 0.0f));
  camera_.eye = camera_.target + offset;
}

void OrbitCamera::pan(float dx, float dy) {
  const glm::vec3 forward = glm::normalize(camera_.target - camera_.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera_.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float distance = glm::length(camera_.target - camera_.eye);
  const float extent = 2.0f * distance * std::tan(glm::radians(camera_.fovYDegrees) * 0.5f);
  const glm::vec3 move = (-dx * right + dy * up) * extent;
  camera_.eye += move;
  camera_.target += move;
}

void OrbitCamera::fly(float right, float up, float forward) {
  const glm::vec3 view = camera_.target - camera_.eye;
  const float distance = glm::length(view);
  const glm::vec3 f = view / distance;
  const glm::vec3 r = glm::normalize(glm::cross(f, camera_.up));
  const glm::vec3 u = glm::cross(r, f);
  const glm::vec3 move = (right * r + up * u + forward * f) * distance;
  camera_.eye += move;
  camera_.target += move;
}

void OrbitCamera::zoom(float factor) {
  if (!(factor > 0.0f)) return;
  const glm::vec3 offset = (camera_.eye - camera_.target) / factor;
  if (glm::length(offset) > 1e-4f) camera_.eye = camera_.target + offset;
}

void OrbitCamera::setFov(float degrees) {
  camera_.fovYDegrees = std::clamp(degrees, 5.0f, 150.0f);
}

std::string OrbitCamera::spec() const {
  const Camera& c = camera_;
  char text[512];
  std::snprintf(text, sizeof text, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", c.eye.x,
                c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z,
                c.fovYDegrees);
  return text;
}

}  // namespace mfr::view
