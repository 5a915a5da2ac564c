// procedural:city — a city block of translucent buildings (issue 14 sec. 2; the "translucent city
// block" among the real test scenes): a grid of towers of random heights, some with a core inside
// a glass curtain wall.
//
// `rows` x `columns` unit cells centred on the origin; each holds a closed axis-aligned box of
// footprint [0.5, 0.85] per side (placed randomly inside its cell) and height [0.4, 3], and with
// probability 1/2 a core: a closed box inset by 30% of the footprint and 10% of the height. A line
// in the ground plane's projection passes through at most rows + columns - 1 cells, and each cell
// holds at most two closed boxes, so n(p) is even and n(p) <= 4 (rows + columns - 1).
// Materials: one per building and per core, alphas jitteredAlpha(alpha, spread).
#include <string>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {

Result<Scene> buildCity(ParamReader& params, uint64_t seed) {
  const int64_t rows = params.integer("rows", 6, 1, 1000);
  const int64_t columns = params.integer("columns", 6, 1, 1000);
  const float alpha = params.real("alpha", 0.3, 0.0, 1.0);
  const float spread = params.real("spread", 0.5, 0.0, 1.0);
  if (params.error()) return *params.error();
  MFR_TRY(checkTriangleBudget(params, 2.0 * kBoxTriangles * static_cast<double>(rows * columns)));
  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  const float hueOffset = rng.uniform();
  for (int64_t r = 0; r < rows; ++r) {
    for (int64_t c = 0; c < columns; ++c) {
      const float x0 = static_cast<float>(c) - 0.5f * static_cast<float>(columns);
      const float z0 = static_cast<float>(r) - 0.5f * static_cast<float>(rows);
      const float w = rng.uniform(0.5f, 0.85f), d = rng.uniform(0.5f, 0.85f);
      const float height = rng.uniform(0.4f, 3.0f);
      const float ox = rng.uniform(0.0f, 1.0f - w), oz = rng.uniform(0.0f, 1.0f - d);
      const glm::vec3 lo(x0 + ox, 0.0f, z0 + oz), hi(lo.x + w, height, lo.z + d);
      const uint32_t id = static_cast<uint32_t>(r * columns + c);
      appendBox(
          mesh, lo, hi,
          mesh.material("building_" + std::to_string(id), hsv(goldenHue(id, hueOffset), 0.3f, 0.9f),
                        jitteredAlpha(rng, alpha, spread)));
      if (rng.below(2) == 0) {
        const glm::vec3 inset(0.3f * w, 0.1f * height, 0.3f * d);
        appendBox(mesh, lo + inset, hi - inset,
                  mesh.material("core_" + std::to_string(id), {0.5f, 0.5f, 0.55f},
                                jitteredAlpha(rng, alpha, spread)));
      }
    }
  }
  scene.defaultCamera = frameVertices(scene);
  return scene;
}

}  // namespace mfr::procedural
