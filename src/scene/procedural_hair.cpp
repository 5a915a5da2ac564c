// procedural:hair — hanging hair strands on a head (issue 14 sec. 2): long, thin, nearly parallel
// tubes, the hair / fur case of the multi-fragment papers, combed rather than tangled like
// procedural:hairball.
//
// A head (closed UV sphere of radius 0.5 at the origin, 16 x 24) and `strands` strands rooted
// uniformly on its upper hemisphere. A strand leaves its root along the surface normal, then falls
// (gravity) with a small random sideways wave, length 1.0-1.6, sampled at `segments` + 1 points
// kept outside the head, swept into an open tube of radius 0.004 with `sides` sides. Away from
// its open ends a line crosses a tube twice (in and out) and the head twice, so the counts are
// even almost everywhere, and n(p) <= 2 strands + 2.
// Materials: 8 hair tones (dark to blond) and the skin, alphas jitteredAlpha(alpha, spread).
#include <algorithm>
#include <string>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {

Result<Scene> buildHair(ParamReader& params, uint64_t seed) {
  const int64_t strands = params.integer("strands", 1500, 1, 1'000'000);
  const int64_t segments = params.integer("segments", 12, 1, 1000);
  const int64_t sides = params.integer("sides", 4, 3, 64);
  const float alpha = params.real("alpha", 0.4, 0.0, 1.0);
  const float spread = params.real("spread", 0.5, 0.0, 1.0);
  if (params.error()) return *params.error();
  constexpr float kHead = 0.5f, kRadius = 0.004f;
  MFR_TRY(checkTriangleBudget(
      params, uvSphereTriangles(16, 24) +
                  static_cast<double>(strands) * tubeTriangles(static_cast<double>(segments + 1),
                                                               static_cast<double>(sides))));
  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  appendUvSphere(mesh, glm::vec3(0.0f), kHead, 16, 24,
                 mesh.material("skin", {0.9f, 0.7f, 0.6f}, jitteredAlpha(rng, alpha, spread)));
  const float hue = rng.uniform(0.05f, 0.12f);
  uint32_t tones[8];
  for (uint32_t t = 0; t < 8; ++t)
    tones[t] = mesh.material("hair_" + std::to_string(t),
                             hsv(hue, 0.6f, 0.15f + 0.1f * static_cast<float>(t)),
                             jitteredAlpha(rng, alpha, spread));
  const uint32_t tone = rng.below(8);
  std::vector<glm::vec3> line, tangents;
  for (int64_t s = 0; s < strands; ++s) {
    glm::vec3 n = rng.unitVector();
    n.y = std::abs(n.y);
    const float length = rng.uniform(1.0f, 1.6f);
    const float wave = rng.uniform(0.0f, 0.08f), phase = rng.uniform(0.0f, glm::two_pi<float>());
    const glm::vec3 side =
        glm::normalize(glm::cross(n, glm::vec3(0.0f, 1.0f, 0.0f)) + glm::vec3(1e-3f, 0.0f, 0.0f));
    line.clear();
    tangents.clear();
    const float step = length / static_cast<float>(segments);
    glm::vec3 p = (kHead + 2.0f * kRadius) * n, dir = n;
    for (int64_t j = 0; j <= segments; ++j) {
      line.push_back(p + wave * std::sin(6.0f * static_cast<float>(j) * step + phase) * side);
      // gravity bends the direction downwards; the strand slides over the head's surface
      dir = glm::normalize(dir + glm::vec3(0.0f, -0.6f * step / 0.1f, 0.0f) * 0.1f);
      p += step * dir;
      const float r = glm::length(p);
      if (r < kHead + 2.0f * kRadius) p *= (kHead + 2.0f * kRadius) / r;
    }
    for (size_t j = 0; j < line.size(); ++j) {
      const glm::vec3 d = line[std::min(j + 1, line.size() - 1)] - line[j == 0 ? 0 : j - 1];
      tangents.push_back(glm::length(d) > 0.0f ? glm::normalize(d) : glm::vec3(0, -1, 0));
    }
    appendTube(mesh, line, tangents, kRadius, static_cast<int>(sides),
               tones[(tone + rng.below(3)) % 8]);
  }
  scene.defaultCamera = frameVertices(scene);
  return scene;
}

}  // namespace mfr::procedural
