// procedural:spheres — nested transparent concentric spheres, a scene whose number of layers per
// pixel is known analytically (2 per sphere the pixel's ray passes through), used to check that a
// rasterizer produces exactly the right fragment counts and that methods composite many ordered
// layers correctly (the nested-surface test case of the multi-fragment papers).
//
// `count` UV spheres centred at the origin, radii scale * i / count (i = 1..count), `detail`
// latitude bands and 2 * detail longitude steps each (poles on y, vertices exactly on the spheres,
// radial normals), each its own saturated colour (the seed only rotates the hues), alpha 0.2 by
// default. sphereLayersAnalytic (mfr/scene/procedural_geometry.hpp) gives the exact counts.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "mfr/scene/procedural_geometry.hpp"
#include "scene/procedural_internal.hpp"

namespace mfr {

int sphereLayersAnalytic(const Camera& camera, int width, int height, int x, int y, int count,
                         float scale, float* marginOut) {
  const Ray ray = pixelRay(camera, width, height, x, y);
  const glm::dvec3 o(ray.origin), d(glm::normalize(glm::dvec3(ray.direction)));
  const glm::dvec3 forward = glm::normalize(glm::dvec3(camera.target) - glm::dvec3(camera.eye));
  const double depthPerT = glm::dot(d, forward);  // view depth per unit of ray length
  const double b = glm::dot(o, d);
  const double o2 = glm::dot(o, o);
  const double eyeDistance = std::sqrt(o2);
  const double lineDistance = std::sqrt(std::max(0.0, o2 - b * b));
  double margin = std::numeric_limits<double>::infinity();
  int crossings = 0;
  for (int i = 1; i <= count; ++i) {
    const double r = static_cast<double>(scale) * i / count;
    margin = std::min({margin, std::abs(lineDistance - r), std::abs(eyeDistance - r)});
    const double disc = b * b - (o2 - r * r);
    if (disc <= 0.0) continue;
    const double root = std::sqrt(disc);
    for (const double t : {-b - root, -b + root}) {
      if (t <= 0.0) continue;
      const double depth = t * depthPerT;
      if (camera.zNear > 0.0f) {
        margin = std::min(margin, std::abs(depth - camera.zNear));
        if (depth < camera.zNear) continue;
      }
      if (camera.zFar > 0.0f) {
        margin = std::min(margin, std::abs(depth - camera.zFar));
        if (depth > camera.zFar) continue;
      }
      ++crossings;
    }
  }
  if (marginOut) *marginOut = static_cast<float>(margin);
  return crossings;
}

float sphereTessellationError(float radius, int detail) {
  // Every triangle's vertices lie within a spherical cap of angular radius dTheta + dPhi around
  // any one of them, so the flat triangle stays within radius * (1 - cos(dTheta + dPhi)) of the
  // sphere; the mesh never reaches outside it.
  const double step = glm::pi<double>() / std::max(detail, 1);  // dTheta = dPhi
  return static_cast<float>(radius * (1.0 - std::cos(2.0 * step)));
}

namespace procedural {

Result<Scene> buildSpheres(ParamReader& params, uint64_t seed) {
  const int64_t count = params.integer("count", kSpheresDefaultCount, 1, 10'000);
  const float scale = params.real("scale", kSpheresDefaultScale, 0.0, 1e6, /*lowOpen=*/true);
  const int64_t detail = params.integer("detail", kSpheresDefaultDetail, 3, 4096);
  const float alpha = params.real("alpha", 0.2, 0.0, 1.0);
  if (params.error()) return *params.error();
  const double rings = static_cast<double>(detail), sectors = 2.0 * rings;
  const double perSphere = uvSphereTriangles(rings, sectors);
  MFR_TRY(checkTriangleBudget(params, perSphere * static_cast<double>(count)));

  Rng rng(seed);
  const float hueOffset = rng.uniform();
  Scene scene;
  MeshBuilder mesh(scene);
  mesh.reserve(static_cast<size_t>(count) * static_cast<size_t>((rings + 1.0) * sectors),
               static_cast<size_t>(count) * static_cast<size_t>(perSphere));
  for (int64_t i = 1; i <= count; ++i) {
    const uint32_t material =
        mesh.material("sphere_" + std::to_string(i),
                      hsv(goldenHue(static_cast<uint32_t>(i), hueOffset), 0.9f, 1.0f), alpha);
    const float radius = static_cast<float>(static_cast<double>(scale) * static_cast<double>(i) /
                                            static_cast<double>(count));
    appendUvSphere(mesh, glm::vec3(0.0f), radius, static_cast<int>(detail),
                   static_cast<int>(2 * detail), material);
  }
  scene.defaultCamera = fitClipPlanes(cameraForSphere(glm::vec3(0.0f), scale), sceneBounds(scene));
  return scene;
}

}  // namespace procedural
}  // namespace mfr
