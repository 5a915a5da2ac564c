// procedural:hairball — thousands of thin curved tubes tangled inside the unit sphere, after the
// "Hairball" model of the occupancy-map / multi-fragment papers: very high depth complexity (well
// over 100 layers in the centre at 1024x1024 with the default camera) made of many small, thin
// fragments.
//
// Each strand is a smooth random curve: a random walk with momentum of 8 control points (step
// 0.45, bouncing off a shell of radius 0.92 so the strand density stays nearly uniform over the
// ball) interpolated by a Catmull-Rom spline sampled at `segments` steps, then swept into an open
// tube of `sides` sides and constant `radius` with analytic per-vertex normals
// (parallel-transported frames). Strands get one of 24 saturated hues.
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {
namespace {

constexpr int kControlPoints = 8;
constexpr float kStep = 0.45f;   // distance between control points
constexpr float kTurn = 0.9f;    // weight of the random turn added to the direction per step
constexpr float kShell = 0.92f;  // control points stay within this radius
constexpr float kClamp = 0.96f;  // spline samples are pulled back within this radius
constexpr uint32_t kPalette = 24;

std::array<glm::vec3, kControlPoints> randomWalk(Rng& rng) {
  std::array<glm::vec3, kControlPoints> points;
  glm::vec3 p = rng.inUnitBall() * kShell;
  glm::vec3 dir = rng.unitVector();
  points[0] = p;
  for (int i = 1; i < kControlPoints; ++i) {
    dir = glm::normalize(dir + kTurn * rng.unitVector());
    p += kStep * dir;
    const float len = glm::length(p);
    if (len > kShell) {
      // Bounce off the shell: mirror the overshoot back inside and reflect the direction, which
      // keeps the strand density close to uniform over the ball.
      const glm::vec3 outward = p / len;
      p = outward * std::max(2.0f * kShell - len, 0.0f);
      dir = glm::normalize(dir - 2.0f * std::max(0.0f, glm::dot(dir, outward)) * outward);
    }
    points[static_cast<size_t>(i)] = p;
  }
  return points;
}

}  // namespace

Result<Scene> buildHairball(ParamReader& params, uint64_t seed) {
  const int64_t strands = params.integer("strands", 3000, 1, 1'000'000);
  const int64_t segments = params.integer("segments", 16, 1, 4096);
  const int64_t sides = params.integer("sides", 6, 3, 64);
  const float radius = params.real("radius", 0.01, 0.0, 0.25, /*lowOpen=*/true);
  const float alpha = params.real("alpha", 0.3, 0.0, 1.0);
  if (params.error()) return *params.error();
  const double perStrand =
      tubeTriangles(static_cast<double>(segments) + 1.0, static_cast<double>(sides));
  MFR_TRY(checkTriangleBudget(params, perStrand * static_cast<double>(strands)));

  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  const size_t samples = static_cast<size_t>(segments) + 1;
  mesh.reserve(static_cast<size_t>(strands) * samples * static_cast<size_t>(sides),
               static_cast<size_t>(strands) * static_cast<size_t>(perStrand));
  const float hueOffset = rng.uniform();
  for (uint32_t i = 0; i < kPalette; ++i)
    mesh.material("hair_" + std::to_string(i), hsv(goldenHue(i, hueOffset), 0.85f, 0.95f), alpha);

  std::vector<glm::vec3> centerline(samples), tangents(samples);
  for (int64_t strand = 0; strand < strands; ++strand) {
    const std::array<glm::vec3, kControlPoints> c = randomWalk(rng);
    const uint32_t material = rng.below(kPalette);
    // Control point i, with mirrored phantom points before the first and after the last.
    const auto control = [&](int i) {
      if (i < 0) return 2.0f * c[0] - c[1];
      if (i >= kControlPoints) return 2.0f * c[kControlPoints - 1] - c[kControlPoints - 2];
      return c[static_cast<size_t>(i)];
    };
    for (size_t j = 0; j < samples; ++j) {
      const double s = static_cast<double>(kControlPoints - 1) * static_cast<double>(j) /
                       static_cast<double>(segments);
      const int span = std::min(static_cast<int>(s), kControlPoints - 2);
      const float u = static_cast<float>(s - span);
      const glm::vec3 p0 = control(span - 1), p1 = control(span), p2 = control(span + 1),
                      p3 = control(span + 2);
      // Uniform Catmull-Rom: P(u) = 0.5 (a + b u + c u^2 + d u^3).
      const glm::vec3 b = p2 - p0;
      const glm::vec3 cc = 2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3;
      const glm::vec3 d = -p0 + 3.0f * p1 - 3.0f * p2 + p3;
      glm::vec3 point = 0.5f * (2.0f * p1 + u * (b + u * (cc + u * d)));
      const glm::vec3 derivative = 0.5f * (b + u * (2.0f * cc + u * 3.0f * d));
      const float len = glm::length(point);
      if (len > kClamp) point *= kClamp / len;
      centerline[j] = point;
      const float dlen = glm::length(derivative);
      tangents[j] =
          dlen > 1e-6f ? derivative / dlen : (j > 0 ? tangents[j - 1] : glm::vec3(1, 0, 0));
    }
    appendTube(mesh, centerline, tangents, radius, static_cast<int>(sides), material);
  }

  scene.defaultCamera = fitClipPlanes(cameraForSphere(glm::vec3(0.0f), 1.0f), sceneBounds(scene));
  return scene;
}

}  // namespace mfr::procedural
