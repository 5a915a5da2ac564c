// procedural:bottles — glass bottles, vases and flasks holding coloured liquid, the nested
// transparent surfaces of the papers' glass / "bottles" test cases: each vessel is a closed glass
// solid (outer wall, lip, inner wall: two nested surfaces of revolution) containing a closed liquid
// volume, so a ray through a filled vessel crosses 6 surfaces, and vessels standing behind one
// another in a grid add up.
//
// `count` vessels on a grid of ceil(sqrt(count)) columns (`spacing`, default 1, apart; small random
// jitter; below about 0.76 neighbours interpenetrate), each of
// a random kind (wine bottle, vase, flask), height 0.9-1.5 and body radius 0.25-0.38. Surfaces of
// revolution have `segments` steps around the axis and max(8, segments / 2) profile samples;
// normals come from the profile curve (creases at the rims, bottoms and liquid surface are kept
// sharp by building those parts as separate pieces). Glass is a light tint, liquid a saturated
// colour, both with the given alpha.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {
namespace {

constexpr float kWall = 0.02f;  // glass thickness
constexpr float kGap = 0.01f;   // liquid surface inset from the inner wall (avoids coplanar layers)

float smoothstep(float edge0, float edge1, float x) {
  const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

/// Outer radius of a vessel as a function of the height fraction t in [0, 1].
struct Vessel {
  int kind = 0;  // 0 wine bottle, 1 vase, 2 flask
  float height = 1.0f;
  float body = 0.3f;
  float neck = 0.1f;

  float radius(float t) const {
    switch (kind) {
      case 0:  // cylindrical body, rounded shoulder, straight neck
        return body + (neck - body) * smoothstep(0.55f, 0.75f, t);
      case 1: {  // bulging vase with a flared mouth
        const float bulge = 0.62f + 0.38f * std::sin(glm::pi<float>() * (0.1f + 0.95f * t));
        return body * (bulge + 0.25f * smoothstep(0.8f, 1.0f, t));
      }
      default: {  // spherical bulb (flattened base) blended smoothly into the neck
        const float y = t * height, centre = 0.8f * body;
        const float bulb = std::sqrt(std::max(0.0f, body * body - (y - centre) * (y - centre)));
        const float d = bulb - neck;
        return 0.5f * (bulb + neck + std::sqrt(d * d + 0.0025f));  // smooth max
      }
    }
  }
};

/// Appends one lathe piece after computing its normals from the polyline.
void piece(MeshBuilder& mesh, std::vector<ProfilePoint> profile, int segments,
           const glm::vec3& base, uint32_t material) {
  computeProfileNormals(profile);
  appendLathe(mesh, profile, segments, base, material);
}

}  // namespace

Result<Scene> buildBottles(ParamReader& params, uint64_t seed) {
  const int64_t count = params.integer("count", 6, 1, 10'000);
  const int64_t segments = params.integer("segments", 64, 3, 4096);
  const float alpha = params.real("alpha", 0.3, 0.0, 1.0);
  const float spacing = params.real("spacing", 1.0, 0.0, 100.0, /*lowOpen=*/true);
  if (params.error()) return *params.error();
  const int samples = std::max(8, static_cast<int>(segments) / 2);  // wall profile samples
  const int liquidSamples = std::max(4, samples / 2);
  const double perVessel =
      static_cast<double>(segments) * (6.0 + 4.0 * (samples - 1) + 2.0 * (liquidSamples - 1));
  MFR_TRY(checkTriangleBudget(params, perVessel * static_cast<double>(count)));

  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  const size_t seg = static_cast<size_t>(segments);
  mesh.reserve(static_cast<size_t>(count) * seg * (2 * samples + liquidSamples + 8),
               static_cast<size_t>(count) * static_cast<size_t>(perVessel));
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count))));
  const int rows = static_cast<int>((count + columns - 1) / columns);
  const float hueOffset = rng.uniform();
  const int seg32 = static_cast<int>(segments);

  for (int i = 0; i < static_cast<int>(count); ++i) {
    Vessel v;
    v.kind = static_cast<int>(rng.below(3));
    v.height = rng.uniform(0.9f, 1.5f);
    v.body = rng.uniform(0.25f, 0.38f);
    v.neck = rng.uniform(0.07f, 0.12f);
    const float fill = rng.uniform(0.3f, 0.75f);
    const int column = i % columns, row = i / columns;
    const float jitterX = rng.uniform(-0.05f, 0.05f);
    const float jitterZ = rng.uniform(-0.05f, 0.05f);
    const glm::vec3 base(
        spacing * (static_cast<float>(column) - 0.5f * static_cast<float>(columns - 1)) + jitterX,
        0.0f, spacing * (0.5f * static_cast<float>(rows - 1) - static_cast<float>(row)) + jitterZ);
    const uint32_t glass =
        mesh.material("glass_" + std::to_string(i),
                      hsv(goldenHue(2 * static_cast<uint32_t>(i), hueOffset), 0.35f, 1.0f), alpha);
    const uint32_t liquid = mesh.material(
        "liquid_" + std::to_string(i),
        hsv(goldenHue(2 * static_cast<uint32_t>(i) + 1, hueOffset), 0.9f, 0.85f), alpha);

    const float h = v.height;
    const float top = v.radius(1.0f);
    const auto outer = [&](float y) { return v.radius(y / h); };
    const auto inner = [&](float y) { return outer(y) - kWall; };
    const auto wet = [&](float y) { return std::max(inner(y) - kGap, 0.005f); };
    const auto at = [&](int j, int n) { return static_cast<float>(j) / static_cast<float>(n - 1); };

    // Glass: outer bottom, outer wall, lip, inner wall (downwards), inner floor.
    piece(mesh, {{0.0f, 0.0f}, {outer(0.0f), 0.0f}}, seg32, base, glass);
    std::vector<ProfilePoint> wall;
    for (int j = 0; j < samples; ++j)
      wall.push_back({outer(at(j, samples) * h), at(j, samples) * h});
    piece(mesh, wall, seg32, base, glass);
    piece(mesh, {{top, h}, {top - kWall, h}}, seg32, base, glass);
    wall.clear();
    for (int j = samples - 1; j >= 0; --j) {
      const float y = kWall + (h - kWall) * at(j, samples);
      wall.push_back({inner(y), y});
    }
    piece(mesh, wall, seg32, base, glass);
    piece(mesh, {{inner(kWall), kWall}, {0.0f, kWall}}, seg32, base, glass);

    // Liquid: a closed volume inside the cavity up to the fill level.
    const float bottom = kWall + kGap;
    const float level = bottom + fill * (h - bottom) * 0.8f;
    piece(mesh, {{0.0f, bottom}, {wet(bottom), bottom}}, seg32, base, liquid);
    wall.clear();
    for (int j = 0; j < liquidSamples; ++j) {
      const float y = bottom + (level - bottom) * at(j, liquidSamples);
      wall.push_back({wet(y), y});
    }
    piece(mesh, wall, seg32, base, liquid);
    piece(mesh, {{wet(level), level}, {0.0f, level}}, seg32, base, liquid);
  }

  scene.defaultCamera = frameVertices(scene);
  return scene;
}

}  // namespace mfr::procedural
