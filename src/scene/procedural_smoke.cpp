// procedural:smoke — a rising plume of camera-facing particle billboards, the particle-system test
// case of the multi-fragment / OIT papers: many large, overlapping, low-alpha, grey fragments.
//
// `count` particles rise uniformly from a source at the origin to a height of 3, spreading
// (standard deviation 0.12 + 0.15 * height) and drifting sideways as they rise. Each is a square of
// half-size size * [0.5, 1.5] * (0.6 + 0.8 * height / 3) in the plane of the default camera's
// right/up vectors (so it faces that camera exactly; normal towards the camera), submitted in
// random depth order. Greys from 16 materials (darker near the source, alternately slightly warm
// or cool), all with the given alpha.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {
namespace {

constexpr float kHeight = 3.0f;
constexpr uint32_t kGreys = 16;

}  // namespace

Result<Scene> buildSmoke(ParamReader& params, uint64_t seed) {
  const int64_t count = params.integer("count", 20000, 1, 10'000'000);
  const float size = params.real("size", 0.08, 0.0, 10.0, /*lowOpen=*/true);
  const float alpha = params.real("alpha", 0.1, 0.0, 1.0);
  if (params.error()) return *params.error();
  MFR_TRY(checkTriangleBudget(params, 2.0 * static_cast<double>(count)));

  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  mesh.reserve(4 * static_cast<size_t>(count), 2 * static_cast<size_t>(count));
  for (uint32_t i = 0; i < kGreys; ++i) {
    const float level = 0.2f + 0.45f * static_cast<float>(i) / static_cast<float>(kGreys - 1);
    const float tint = (i % 2 == 0 ? 1.0f : -1.0f) * 0.04f;  // alternately warm and cool
    mesh.material("smoke_" + std::to_string(i),
                  glm::clamp(glm::vec3(level + tint, level, level - tint), 0.0f, 1.0f), alpha);
  }

  // Billboards lie in the view plane of the default camera, whose direction is fixed (only its
  // distance depends on the particles, see frameVertices).
  const Camera direction = cameraForSphere(glm::vec3(0.0f), 1.0f);
  const glm::vec3 forward = glm::normalize(direction.target - direction.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, direction.up));
  const glm::vec3 up = glm::cross(right, forward);
  const glm::vec3 normal = -forward;

  const float phaseX = rng.uniform(0.0f, glm::two_pi<float>());
  const float phaseZ = rng.uniform(0.0f, glm::two_pi<float>());
  for (int64_t i = 0; i < count; ++i) {
    const float rise = rng.uniform();
    const float h = kHeight * rise;
    const float spread = 0.12f + 0.15f * h;
    const glm::vec3 drift(0.4f * rise * std::sin(1.3f * h + phaseX), h,
                          0.3f * rise * std::sin(1.9f * h + phaseZ));
    glm::vec3 center = drift;
    center.x += spread * rng.normal();
    center.y += 0.1f * rng.normal();
    center.z += spread * rng.normal();
    const float halfSize = size * rng.uniform(0.5f, 1.5f) * (0.6f + 0.8f * rise);
    const float level = std::clamp(0.25f + 0.6f * rise + 0.15f * rng.normal(), 0.0f, 0.999f);
    const uint32_t material = static_cast<uint32_t>(level * static_cast<float>(kGreys));
    const glm::vec3 r = right * halfSize, v = up * halfSize;
    const uint32_t a = mesh.vertex(center - r - v, normal);
    const uint32_t b = mesh.vertex(center + r - v, normal);
    const uint32_t c = mesh.vertex(center + r + v, normal);
    const uint32_t d = mesh.vertex(center - r + v, normal);
    mesh.quad(a, b, c, d, material);
  }

  scene.defaultCamera = frameVertices(scene);
  return scene;
}

}  // namespace mfr::procedural
