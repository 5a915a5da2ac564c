// Brute-force depth complexity for the procedural-scene tests: how many triangles a line crosses.
#pragma once

#include <cmath>
#include <cstddef>

#include <glm/glm.hpp>

#include "mfr/scene/scene.hpp"

namespace mfr::test {

/// Triangles (from `firstTriangle` on) the line origin + t d crosses for t > 0 (Moller-Trumbore,
/// double precision).
inline int countHits(const Scene& scene, const glm::dvec3& o, const glm::dvec3& d,
                     size_t firstTriangle = 0) {
  int hits = 0;
  for (size_t t = 3 * firstTriangle; t + 2 < scene.indices.size(); t += 3) {
    const glm::dvec3 v0(scene.positions[scene.indices[t]]);
    const glm::dvec3 e1 = glm::dvec3(scene.positions[scene.indices[t + 1]]) - v0;
    const glm::dvec3 e2 = glm::dvec3(scene.positions[scene.indices[t + 2]]) - v0;
    const glm::dvec3 p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-18) continue;
    const double inv = 1.0 / det;
    const glm::dvec3 s = o - v0;
    const double u = glm::dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    if (glm::dot(e2, q) * inv > 1e-9) ++hits;
  }
  return hits;
}

}  // namespace mfr::test
