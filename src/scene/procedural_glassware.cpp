// procedural:glassware — the training corpus's glass objects (issue 14 sec. 2; the deep k-buffer
// paper's glass scenes, DHOIT sec. 4): surfaces of revolution with random profiles, nested shells
// (a thick wall is two shells, a double-walled glass three or four) and a liquid inside.
//
// `count` objects on a grid of ceil(sqrt(count)) columns (spacing 1). Each object's outer radius
// is a random smooth profile r(t) = R (0.7 + sum_i a_i sin(i pi t + phi_i)), i = 1..3, clamped to
// [0.35 R, R], R in [0.22, 0.4], height in [0.8, 1.4]. Shell j (0 .. shells-1) is the closed
// surface of revolution of r(t) - j w (w = 0.06 R), inset by j w at the bottom and the top, so the
// shells nest without touching; the liquid is a closed volume of radius r(t) - shells w - w / 2
// filled to between 55% and 85% of the innermost shell. Every surface is closed: a ray crosses
// each one an even number of times, and a ray through the liquid crosses every shell.
// Each closed piece has max(8, segments / 2) profile samples between its two axis points.
// Materials: one tinted glass per shell and a saturated liquid per object, alphas
// jitteredAlpha(alpha, spread).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {
namespace {

struct Profile {
  float radius = 0.3f;
  float height = 1.0f;
  float amplitude[3] = {};
  float phase[3] = {};

  float at(float t) const {
    float r = 0.7f;
    for (int i = 0; i < 3; ++i)
      r += amplitude[i] * std::sin(static_cast<float>(i + 1) * glm::pi<float>() * t + phase[i]);
    return radius * std::clamp(r, 0.35f, 1.0f);
  }
};

/// Closed surface of revolution from the axis at y0 up the radius `r(y)` to the axis at y1.
template <class RadiusAt>
void closedPiece(MeshBuilder& mesh, RadiusAt r, float y0, float y1, int samples, int segments,
                 const glm::vec3& base, uint32_t material) {
  std::vector<ProfilePoint> profile;
  profile.push_back({0.0f, y0});
  for (int j = 0; j < samples; ++j) {
    const float y = y0 + (y1 - y0) * static_cast<float>(j) / static_cast<float>(samples - 1);
    profile.push_back({r(y), y});
  }
  profile.push_back({0.0f, y1});
  computeProfileNormals(profile);
  appendLathe(mesh, profile, segments, base, material);
}

}  // namespace

Result<Scene> buildGlassware(ParamReader& params, uint64_t seed) {
  const int64_t count = params.integer("count", 4, 1, 10'000);
  const int64_t segments = params.integer("segments", 48, 3, 4096);
  const int64_t shells = params.integer("shells", 2, 1, 4);
  const float alpha = params.real("alpha", 0.3, 0.0, 1.0);
  const float spread = params.real("spread", 0.5, 0.0, 1.0);
  if (params.error()) return *params.error();
  const int samples = std::max(8, static_cast<int>(segments) / 2);
  // a closed piece: two fans and samples - 1 bands
  const double perPiece = static_cast<double>(segments) * 2.0 * static_cast<double>(samples);
  MFR_TRY(checkTriangleBudget(params, perPiece * static_cast<double>((shells + 1) * count)));

  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count))));
  const int rows = static_cast<int>((count + columns - 1) / columns);
  const float hueOffset = rng.uniform();
  const int seg = static_cast<int>(segments);
  for (int i = 0; i < static_cast<int>(count); ++i) {
    Profile p;
    p.radius = rng.uniform(0.22f, 0.4f);
    p.height = rng.uniform(0.8f, 1.4f);
    for (int k = 0; k < 3; ++k) {
      p.amplitude[k] = rng.uniform(-0.25f, 0.25f) / static_cast<float>(k + 1);
      p.phase[k] = rng.uniform(0.0f, glm::two_pi<float>());
    }
    const float fill = rng.uniform(0.55f, 0.85f);
    const float w = 0.06f * p.radius;
    const int column = i % columns, row = i / columns;
    const glm::vec3 base(static_cast<float>(column) - 0.5f * static_cast<float>(columns - 1), 0.0f,
                         0.5f * static_cast<float>(rows - 1) - static_cast<float>(row));
    const float h = p.height;
    for (int j = 0; j < static_cast<int>(shells); ++j) {
      const float a = jitteredAlpha(rng, alpha, spread);
      const uint32_t glass = mesh.material(
          "glass_" + std::to_string(i) + "_" + std::to_string(j),
          hsv(goldenHue(static_cast<uint32_t>(i * 5 + j), hueOffset), 0.25f, 1.0f), a);
      const float inset = static_cast<float>(j) * w;
      closedPiece(
          mesh, [&](float y) { return p.at(y / h) - inset; }, inset, h - inset, samples, seg, base,
          glass);
    }
    const float a = jitteredAlpha(rng, alpha, spread);
    const uint32_t liquid =
        mesh.material("liquid_" + std::to_string(i),
                      hsv(goldenHue(static_cast<uint32_t>(i * 5 + 4), hueOffset), 0.9f, 0.85f), a);
    const float inset = (static_cast<float>(shells) + 0.5f) * w;
    const float bottom = inset, level = bottom + fill * (h - 2.0f * inset);
    closedPiece(
        mesh, [&](float y) { return p.at(y / h) - inset; }, bottom, level, std::max(4, samples / 2),
        seg, base, liquid);
  }
  scene.defaultCamera = frameVertices(scene);
  return scene;
}

}  // namespace mfr::procedural
