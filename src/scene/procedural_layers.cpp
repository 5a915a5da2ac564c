// procedural:layers — the synthetic benchmark of the k+-buffer paper (Vasilakis & Fudos, sec. 4.1:
// "artificially generated scenes that cover a percentage of screen size (pixel density pd) and
// produce n = r*k randomly arrived fragments per pixel").
//
// n = r*k screen-aligned quads for the default camera (eye at the origin looking down -z, up +y,
// fov 45, zNear 1, zFar 11). Quad i lies in the plane z = -d_i with distinct depths d_i spread
// evenly over [2, 10] and submitted in a random order (a seeded permutation), with half-extent
// d_i * tan(fov/2) * sqrt(pd), so every quad projects onto the same centred square spanning
// sqrt(pd) of the image in each direction: on a square viewport every pixel inside it receives
// exactly n fragments and the covered fraction of the image is exactly pd (on a non-square viewport
// the square keeps sqrt(pd) of the height and the covered fraction becomes pd / aspect).
// Each quad has its own saturated material (golden-ratio hues in depth order, so neighbouring
// layers differ strongly and ordering errors are visible), alpha 0.1 by default.
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {

Result<Scene> buildLayers(ParamReader& params, uint64_t seed) {
  const int64_t k = params.integer("k", 8, 1, 1024);
  const int64_t r = params.integer("r", 16, 1, 1024);
  const float pd = params.real("pd", 0.5, 0.0, 1.0, /*lowOpen=*/true);
  const float alpha = params.real("alpha", 0.1, 0.0, 1.0);
  if (params.error()) return *params.error();
  // Depths must stay distinct in float (spacing 8/n well above the float step near 10).
  constexpr int64_t kMaxQuads = 1'000'000;
  const int64_t n = r * k;
  if (n > kMaxQuads)
    return params.fail("r*k = " + std::to_string(n) + " quads exceeds the limit " +
                       std::to_string(kMaxQuads) + " (r=" + std::to_string(r) +
                       ", k=" + std::to_string(k) + ")");
  MFR_TRY(checkTriangleBudget(params, 2.0 * static_cast<double>(n)));

  Rng rng(seed);
  const uint32_t count = static_cast<uint32_t>(n);
  // order[i] = depth rank of the i-th submitted quad (0 = nearest): Fisher-Yates shuffle.
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  for (uint32_t i = count; i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);

  Scene scene;
  MeshBuilder mesh(scene);
  mesh.reserve(4 * static_cast<size_t>(count), 2 * static_cast<size_t>(count));
  scene.materials.reserve(count);
  const float hueOffset = rng.uniform();
  for (uint32_t rank = 0; rank < count; ++rank)
    mesh.material("layer_" + std::to_string(rank), hsv(goldenHue(rank, hueOffset), 0.9f, 1.0f),
                  alpha);

  constexpr double kNearDepth = 2.0, kFarDepth = 10.0, kFovY = 45.0;
  const double tanHalf = std::tan(kFovY * 0.5 * glm::pi<double>() / 180.0);
  const glm::vec3 normal(0.0f, 0.0f, 1.0f);
  for (uint32_t rank : order) {
    const double depth =
        kNearDepth + (kFarDepth - kNearDepth) * (static_cast<double>(rank) + 0.5) / count;
    const float h = static_cast<float>(depth * tanHalf * std::sqrt(static_cast<double>(pd)));
    const float z = static_cast<float>(-depth);
    const uint32_t a = mesh.vertex({-h, -h, z}, normal);
    const uint32_t b = mesh.vertex({h, -h, z}, normal);
    const uint32_t c = mesh.vertex({h, h, z}, normal);
    const uint32_t d = mesh.vertex({-h, h, z}, normal);
    mesh.quad(a, b, c, d, rank);
  }

  Camera camera;
  camera.eye = {0.0f, 0.0f, 0.0f};
  camera.target = {0.0f, 0.0f, -1.0f};
  camera.up = {0.0f, 1.0f, 0.0f};
  camera.fovYDegrees = static_cast<float>(kFovY);
  camera.zNear = 1.0f;
  camera.zFar = 11.0f;
  scene.defaultCamera = camera;
  return scene;
}

}  // namespace mfr::procedural
