// procedural:foliage — plants made of leaf cards, the alpha-tested foliage of games and
// architectural scenes (issue 14 sec. 2): many small, flat, randomly oriented, overlapping
// surfaces around a stem.
//
// `plants` plants on a grid of ceil(sqrt(plants)) columns (spacing 1.2). Each has a stem (an open
// 6-sided tube of radius 0.015 from the ground to the crown centre at height 1.2-1.6) and `leaves`
// leaves whose centres are uniform in the crown ball of radius 0.45. A leaf is the cut-out shape of
// an alpha-tested card modelled as geometry: a flat fan of 8 triangles around its centre with the
// outline of an ellipse of half-axes 0.09 x 0.04 (area 4 sin(pi/4) a b, about 0.0102), in a random
// plane. A line crosses each leaf at most once, so n(p) <= plants * leaves + 2 * plants; along a
// line through the crown centre the expected count is rho * 2 R * A / 2 = 3 N A / (4 pi R^2)
// (N leaves of area A, density rho = N / (4/3 pi R^3), mean projected area A / 2).
// Materials: 12 greens per plant, alphas jitteredAlpha(alpha, spread), and a brown stem.
#include <cmath>
#include <string>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {

Result<Scene> buildFoliage(ParamReader& params, uint64_t seed) {
  const int64_t plants = params.integer("plants", 4, 1, 10'000);
  const int64_t leaves = params.integer("leaves", 300, 1, 1'000'000);
  const float alpha = params.real("alpha", 0.5, 0.0, 1.0);
  const float spread = params.real("spread", 0.5, 0.0, 1.0);
  if (params.error()) return *params.error();
  constexpr int kFan = 8, kStemSides = 6, kStemPoints = 4;
  constexpr float kCrown = 0.45f, kLeafA = 0.09f, kLeafB = 0.04f, kStem = 0.015f;
  MFR_TRY(checkTriangleBudget(
      params, static_cast<double>(plants) *
                  (static_cast<double>(leaves) * kFan + tubeTriangles(kStemPoints, kStemSides))));

  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(plants))));
  const int rows = static_cast<int>((plants + columns - 1) / columns);
  for (int i = 0; i < static_cast<int>(plants); ++i) {
    const int column = i % columns, row = i / columns;
    const float height = rng.uniform(1.2f, 1.6f);
    const glm::vec3 root(
        1.2f * (static_cast<float>(column) - 0.5f * static_cast<float>(columns - 1)), 0.0f,
        1.2f * (0.5f * static_cast<float>(rows - 1) - static_cast<float>(row)));
    const glm::vec3 crown = root + glm::vec3(0.0f, height, 0.0f);
    const uint32_t stem = mesh.material("stem_" + std::to_string(i), {0.35f, 0.22f, 0.1f},
                                        jitteredAlpha(rng, alpha, spread));
    std::vector<glm::vec3> line, tangents;
    for (int j = 0; j < kStemPoints; ++j) {
      line.push_back(root +
                     glm::vec3(0.0f, height * static_cast<float>(j) / (kStemPoints - 1), 0.0f));
      tangents.emplace_back(0.0f, 1.0f, 0.0f);
    }
    appendTube(mesh, line, tangents, kStem, kStemSides, stem);
    uint32_t greens[12];
    for (uint32_t g = 0; g < 12; ++g)
      greens[g] = mesh.material(
          "leaf_" + std::to_string(i) + "_" + std::to_string(g),
          hsv(0.22f + 0.012f * static_cast<float>(g), 0.75f, 0.45f + 0.04f * static_cast<float>(g)),
          jitteredAlpha(rng, alpha, spread));
    for (int64_t l = 0; l < leaves; ++l) {
      const glm::vec3 centre = crown + kCrown * rng.inUnitBall();
      const glm::vec3 normal = rng.unitVector();
      const glm::vec3 helper = std::abs(normal.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
      const glm::vec3 u = glm::normalize(glm::cross(helper, normal));
      const glm::vec3 v = glm::cross(normal, u);
      const uint32_t material = greens[rng.below(12)];
      const uint32_t hub = mesh.vertex(centre, normal);
      uint32_t rim[kFan];
      for (int k = 0; k < kFan; ++k) {
        const float angle = glm::two_pi<float>() * static_cast<float>(k) / kFan;
        rim[k] = mesh.vertex(centre + kLeafA * std::cos(angle) * u + kLeafB * std::sin(angle) * v,
                             normal);
      }
      for (int k = 0; k < kFan; ++k) mesh.triangle(hub, rim[k], rim[(k + 1) % kFan], material);
    }
  }
  scene.defaultCamera = frameVertices(scene);
  return scene;
}

}  // namespace mfr::procedural
