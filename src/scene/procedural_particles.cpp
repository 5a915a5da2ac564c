// procedural:particles — several clouds of camera-facing particle billboards (issue 14 sec. 2):
// the particle effects of games (dust, steam, sparks), with clouds of different densities and
// alphas, unlike procedural:smoke's single plume.
//
// `clouds` clouds with centres uniform in the box [-1.5, 1.5] x [0, 1.5] x [-1.5, 1.5] (the first
// at the origin) and radii R in [0.3, 0.7]; each holds `count` particles uniform in its ball.
// A particle is a square of half-size size * [0.5, 1.5] in the view plane of the default camera's
// direction (as procedural:smoke's), so along that direction a line through a cloud's centre
// crosses in expectation rho * 2 R * E[(2 s)^2] = 3 N E[s^2] / (pi R^2) particles of that cloud,
// E[s^2] = 13/12 size^2. Each cloud has its own hue and alpha (jitteredAlpha(alpha, spread)).
#include <string>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {

Result<Scene> buildParticles(ParamReader& params, uint64_t seed) {
  const int64_t clouds = params.integer("clouds", 5, 1, 10'000);
  const int64_t count = params.integer("count", 2000, 1, 10'000'000);
  const float size = params.real("size", 0.05, 0.0, 10.0, /*lowOpen=*/true);
  const float alpha = params.real("alpha", 0.2, 0.0, 1.0);
  const float spread = params.real("spread", 0.5, 0.0, 1.0);
  if (params.error()) return *params.error();
  MFR_TRY(checkTriangleBudget(params, 2.0 * static_cast<double>(count * clouds)));

  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  const Camera direction = cameraForSphere(glm::vec3(0.0f), 1.0f);
  const glm::vec3 forward = glm::normalize(direction.target - direction.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, direction.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float hueOffset = rng.uniform();
  for (int64_t c = 0; c < clouds; ++c) {
    glm::vec3 centre(0.0f);
    if (c > 0) {
      centre.x = rng.uniform(-1.5f, 1.5f);
      centre.y = rng.uniform(0.0f, 1.5f);
      centre.z = rng.uniform(-1.5f, 1.5f);
    }
    const float radius = rng.uniform(0.3f, 0.7f);
    const uint32_t material = mesh.material(
        "cloud_" + std::to_string(c),
        hsv(goldenHue(static_cast<uint32_t>(c), hueOffset), rng.uniform(0.1f, 0.6f), 0.9f),
        jitteredAlpha(rng, alpha, spread));
    for (int64_t i = 0; i < count; ++i) {
      const glm::vec3 p = centre + radius * rng.inUnitBall();
      const float half = size * rng.uniform(0.5f, 1.5f);
      const glm::vec3 r = right * half, v = up * half;
      const uint32_t a = mesh.vertex(p - r - v, -forward);
      const uint32_t b = mesh.vertex(p + r - v, -forward);
      const uint32_t d = mesh.vertex(p + r + v, -forward);
      const uint32_t e = mesh.vertex(p - r + v, -forward);
      mesh.quad(a, b, d, e, material);
    }
  }
  scene.defaultCamera = frameVertices(scene);
  return scene;
}

}  // namespace mfr::procedural
