// Tests of the built-in procedural scenes (mfr/scene/procedural.hpp): spec parsing and parameter
// validation, determinism, and the geometric properties each scene promises, checked by
// brute-force ray casting (Moller-Trumbore against every triangle) through pixel centres.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mfr/scene/camera.hpp"
#include "mfr/scene/procedural.hpp"
#include "mfr/scene/procedural_geometry.hpp"
#include "mfr/scene/scene.hpp"
#include "ray_hits.hpp"
#include "scene/procedural_internal.hpp"

namespace mfr {
namespace {

Scene build(const std::string& spec, uint64_t seed = 1) {
  Result<Scene> result = makeProceduralScene(spec, seed);
  if (!result) {
    ADD_FAILURE() << spec << ": " << result.error().message;
    return Scene{};
  }
  return std::move(result).value();
}

/// Expects `spec` to fail with a one-line message containing every fragment.
void expectError(const std::string& spec, std::initializer_list<std::string> fragments) {
  Result<Scene> result = makeProceduralScene(spec, 1);
  ASSERT_FALSE(result.ok()) << spec << " unexpectedly succeeded";
  const std::string& message = result.error().message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  for (const std::string& fragment : fragments)
    EXPECT_NE(message.find(fragment), std::string::npos)
        << spec << ": message \"" << message << "\" lacks \"" << fragment << "\"";
}

/// Number of triangles the ray crosses in front of its origin.
int countHits(const Scene& scene, const Ray& ray) {
  return test::countHits(scene, glm::dvec3(ray.origin), glm::dvec3(ray.direction));
}

bool sameGeometry(const Scene& a, const Scene& b) {
  return a.positions == b.positions && a.normals == b.normals && a.indices == b.indices &&
         a.triangleMaterial == b.triangleMaterial;
}

bool sameColours(const Scene& a, const Scene& b) {
  if (a.materials.size() != b.materials.size()) return false;
  for (size_t i = 0; i < a.materials.size(); ++i)
    if (a.materials[i].baseColor != b.materials[i].baseColor) return false;
  return true;
}

/// NDC coordinate of the centre of pixel i of an n-pixel axis (left/top = -1 as in pixelRay).
double ndc(int i, int n) {
  return 2.0 * (i + 0.5) / n - 1.0;
}

// ------------------------------------------------------------------------------------------------
// All scenes

TEST(ProceduralScenes, NamesAreTheBuiltInScenes) {
  EXPECT_EQ(
      proceduralSceneNames(),
      (std::vector<std::string>{"layers", "hairball", "smoke", "bottles", "spheres", "glassware",
                                "foliage", "particles", "hair", "panels", "city"}));
}

TEST(ProceduralScenes, EveryDefaultSceneIsValidBlendedAndFramedByItsDefaultCamera) {
  for (const std::string& name : proceduralSceneNames()) {
    SCOPED_TRACE(name);
    const Scene scene = build(name);
    ASSERT_TRUE(validateScene(scene).ok());
    EXPECT_EQ(scene.name, "procedural:" + name);
    EXPECT_EQ(scene.background, glm::vec3(1.0f));
    EXPECT_TRUE(scene.uvs.empty() || scene.uvs.size() == scene.positions.size());
    for (const Material& m : scene.materials) {
      EXPECT_EQ(m.alphaMode, AlphaMode::Blend);
      EXPECT_GT(m.baseColor.a, 0.0f);
      EXPECT_LE(m.baseColor.a, 1.0f);
    }
    for (const glm::vec3& n : scene.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
    ASSERT_TRUE(scene.defaultCamera.has_value());
    const Camera& camera = *scene.defaultCamera;
    EXPECT_FLOAT_EQ(camera.fovYDegrees, 45.0f);
    ASSERT_GT(camera.zNear, 0.0f);
    ASSERT_GT(camera.zFar, camera.zNear);
    // Every vertex lies inside the view frustum of a square viewport.
    const glm::mat4 clip = projectionMatrix(camera, 256, 256) * viewMatrix(camera);
    for (const glm::vec3& p : scene.positions) {
      const glm::vec4 c = clip * glm::vec4(p, 1.0f);
      ASSERT_GT(c.w, 0.0f);
      ASSERT_LE(std::abs(c.x), c.w * 1.0001f);
      ASSERT_LE(std::abs(c.y), c.w * 1.0001f);
      ASSERT_LE(std::abs(c.z), c.w * 1.0001f);
    }
  }
}

TEST(ProceduralScenes, SameSeedGivesIdenticalScenes) {
  for (const std::string& name : proceduralSceneNames()) {
    SCOPED_TRACE(name);
    const Scene a = build(name, 7), b = build(name, 7);
    EXPECT_TRUE(sameGeometry(a, b));
    EXPECT_TRUE(sameColours(a, b));
  }
}

TEST(ProceduralScenes, DifferentSeedsGiveDifferentScenes) {
  for (const char* name : {"layers", "hairball", "smoke", "bottles"}) {
    SCOPED_TRACE(name);
    EXPECT_FALSE(sameGeometry(build(name, 7), build(name, 8)));
  }
  // The spheres are fixed by their parameters; the seed only changes their colours.
  const Scene a = build("spheres", 7), b = build("spheres", 8);
  EXPECT_TRUE(sameGeometry(a, b));
  EXPECT_FALSE(sameColours(a, b));
}

TEST(ProceduralScenes, SeedParameterOverridesTheSeedArgument) {
  const Scene fromParameter = build("hairball?strands=50&seed=42", 1);
  const Scene fromArgument = build("hairball?strands=50", 42);
  EXPECT_TRUE(sameGeometry(fromParameter, fromArgument));
  EXPECT_FALSE(sameGeometry(fromParameter, build("hairball?strands=50", 1)));
  EXPECT_EQ(fromParameter.name, "procedural:hairball?strands=50&seed=42");
}

TEST(ProceduralScenes, AcceptsTheProceduralPrefixAndAnEmptyQuery) {
  EXPECT_TRUE(sameGeometry(build("procedural:layers?k=2"), build("layers?k=2")));
  EXPECT_TRUE(sameGeometry(build("layers?"), build("layers")));
}

TEST(ProceduralRng, IsSplitMix64WithTheReferenceSequence) {
  procedural::Rng rng(0);
  EXPECT_EQ(rng.next(), 0xe220a8397b1dcdafull);
  EXPECT_EQ(rng.next(), 0x6e789e6aa1b965f4ull);
  EXPECT_EQ(rng.next(), 0x06c45d188009454full);
  procedural::Rng uniform(123);
  for (int i = 0; i < 10000; ++i) {
    const float u = uniform.uniform();
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    ASSERT_LT(uniform.below(7), 7u);
  }
}

// ------------------------------------------------------------------------------------------------
// Parameter validation

TEST(ProceduralParameters, UnknownParameterIsAnErrorListingTheKnownOnes) {
  expectError("layers?foo=1",
              {"procedural:layers: unknown parameter 'foo' (known: k, r, pd, alpha, seed, blend)"});
  expectError("hairball?k=1", {"'k'", "strands, segments, sides, radius, alpha, seed"});
  expectError("smoke?strands=1", {"'strands'", "count, size, alpha, seed"});
  expectError("bottles?detail=1", {"'detail'", "count, segments, alpha, spacing, seed"});
  expectError("spheres?sides=1", {"'sides'", "count, scale, detail, alpha, seed"});
}

TEST(ProceduralParameters, MalformedValueIsAnErrorNamingKeyAndValue) {
  expectError("layers?k=abc", {"procedural:layers", "'k'", "'abc'"});
  expectError("layers?k=8x", {"'k'", "'8x'"});
  expectError("layers?k=1.5", {"'k'", "'1.5'"});
  expectError("layers?k= 8", {"'k'", "' 8'"});
  expectError("layers?pd=", {"'pd'", "''"});
  expectError("layers?pd=0.5.1", {"'pd'", "'0.5.1'"});
  expectError("smoke?size=big", {"procedural:smoke", "'size'", "'big'"});
  expectError("spheres?seed=-1", {"'seed'", "'-1'"});
  expectError("spheres?seed=18446744073709551616", {"'seed'", "'18446744073709551616'"});
}

TEST(ProceduralParameters, OutOfRangeValueIsAnErrorNamingKeyAndValue) {
  expectError("layers?k=0", {"procedural:layers", "'k'", "'0'", "out of range"});
  expectError("layers?pd=0", {"'pd'", "'0'", "out of range (0, 1]"});
  expectError("layers?pd=1.5", {"'pd'", "'1.5'"});
  expectError("layers?alpha=nan", {"'alpha'", "'nan'"});
  expectError("layers?alpha=-0.1", {"'alpha'", "'-0.1'"});
  expectError("hairball?sides=2", {"procedural:hairball", "'sides'", "'2'"});
  expectError("hairball?radius=0", {"'radius'", "'0'"});
  expectError("bottles?segments=2", {"procedural:bottles", "'segments'", "'2'"});
  expectError("spheres?detail=2", {"procedural:spheres", "'detail'", "'2'"});
  expectError("spheres?scale=-1", {"'scale'", "'-1'"});
  expectError("smoke?count=0", {"'count'", "'0'"});
}

TEST(ProceduralParameters, UnknownSceneNameListsTheKnownNames) {
  expectError("teapot?k=1",
              {"unknown scene 'teapot'", "layers, hairball, smoke, bottles, spheres"});
  expectError("", {"unknown scene ''"});
}

TEST(ProceduralParameters, MalformedQueryIsAnError) {
  expectError("layers?k", {"procedural:layers", "'k'", "key=value"});
  expectError("layers?=3", {"'=3'"});
  expectError("layers?k=2&", {"''", "key=value"});
  expectError("layers?k=2&k=3", {"'k'", "twice"});
}

TEST(ProceduralParameters, SizesThatWouldAllocateAbsurdMemoryAreErrors) {
  expectError("hairball?strands=1000000&segments=4096", {"procedural:hairball", "triangles"});
  expectError("spheres?count=10000&detail=4096", {"procedural:spheres", "triangles"});
  expectError("bottles?count=10000&segments=4096", {"procedural:bottles", "triangles"});
  expectError("layers?k=1024&r=1024", {"procedural:layers", "r*k"});
}

// ------------------------------------------------------------------------------------------------
// layers

/// Depth of each quad in submission order (two triangles per quad, all four corners at one z).
std::vector<float> quadDepths(const Scene& scene) {
  std::vector<float> depths;
  for (size_t t = 0; t < scene.triangleCount(); t += 2)
    depths.push_back(-scene.positions[scene.indices[3 * t]].z);
  return depths;
}

TEST(ProceduralLayers, QuadCountIsRTimesK) {
  EXPECT_EQ(build("layers").triangleCount(), 2u * 16u * 8u);
  const Scene scene = build("layers?k=3&r=5");
  EXPECT_EQ(scene.triangleCount(), 2u * 15u);
  EXPECT_EQ(scene.materials.size(), 15u);  // every quad its own colour
}

TEST(ProceduralLayers, DepthsAreDistinctAndSubmissionOrderIsRandom) {
  const Scene scene = build("layers");
  const std::vector<float> depths = quadDepths(scene);
  ASSERT_EQ(depths.size(), 128u);
  for (size_t t = 0; t < scene.indices.size(); ++t)
    ASSERT_EQ(-scene.positions[scene.indices[t]].z, depths[t / 6]);
  std::vector<float> sorted = depths;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "repeated depth";
  EXPECT_GE(sorted.front(), 2.0f);
  EXPECT_LE(sorted.back(), 10.0f);
  EXPECT_NE(depths, sorted);
  // A random permutation has n(n-1)/4 = 4064 inversions on average (standard deviation ~240).
  int inversions = 0;
  for (size_t i = 0; i < depths.size(); ++i)
    for (size_t j = i + 1; j < depths.size(); ++j) inversions += depths[i] > depths[j];
  EXPECT_GT(inversions, 2000);
  EXPECT_LT(inversions, 6128);
}

TEST(ProceduralLayers, EveryQuadProjectsOntoTheSameCentredSquareOfAreaPd) {
  const Scene scene = build("layers?pd=0.3");
  const double halfTan = std::tan(glm::radians(22.5));
  for (size_t i = 0; i < scene.positions.size(); ++i) {
    const glm::vec3 p = scene.positions[i];
    EXPECT_NEAR(std::abs(p.x) / -p.z, halfTan * std::sqrt(0.3), 1e-6);
    EXPECT_NEAR(std::abs(p.y) / -p.z, halfTan * std::sqrt(0.3), 1e-6);
  }
  const Camera& camera = *scene.defaultCamera;
  EXPECT_EQ(camera.eye, glm::vec3(0.0f));
  EXPECT_EQ(camera.target, glm::vec3(0.0f, 0.0f, -1.0f));
  EXPECT_EQ(camera.up, glm::vec3(0.0f, 1.0f, 0.0f));
  EXPECT_FLOAT_EQ(camera.zNear, 1.0f);
  EXPECT_FLOAT_EQ(camera.zFar, 11.0f);
}

/// Casts a ray through every pixel of a size x size image: inside the pd square the count must be
/// exactly r*k, outside 0 (pixels within a hair of the square's border and the pixels whose centre
/// ray runs along the quads' shared diagonals, which brute force would count twice, are skipped).
void expectLayerCounts(const std::string& spec, int r, int k, double pd) {
  SCOPED_TRACE(spec);
  const Scene scene = build(spec);
  const int size = 64;
  const double edge = std::sqrt(pd);
  int covered = 0, checked = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double nx = std::abs(ndc(x, size)), ny = std::abs(ndc(y, size));
      const int hits = countHits(scene, pixelRay(*scene.defaultCamera, size, size, x, y));
      covered += hits > 0;
      if (std::abs(nx - edge) < 1e-3 || std::abs(ny - edge) < 1e-3) continue;
      if (x == y || x + y == size - 1) continue;
      const int expected = (nx < edge && ny < edge) ? r * k : 0;
      ASSERT_EQ(hits, expected) << "pixel " << x << "," << y;
      ++checked;
    }
  }
  EXPECT_GT(checked, size * size * 9 / 10);
  // Covered fraction of the square image is pd, up to the pixels along the square's border.
  const double border = 4.0 * edge * size / (size * size);
  EXPECT_NEAR(static_cast<double>(covered) / (size * size), pd, border);
}

TEST(ProceduralLayers, EveryCoveredPixelHasRTimesKFragmentsAndOthersNone) {
  expectLayerCounts("layers", 16, 8, 0.5);
  expectLayerCounts("layers?k=4&r=3&pd=0.25", 3, 4, 0.25);
  expectLayerCounts("layers?k=2&r=1&pd=1", 1, 2, 1.0);
}

// ------------------------------------------------------------------------------------------------
// hairball

TEST(ProceduralHairball, TriangleCountIsStrandsTimesSegmentsTimesSidesTimesTwo) {
  EXPECT_EQ(build("hairball").triangleCount(), 3000u * 16u * 6u * 2u);
  EXPECT_EQ(build("hairball?strands=10&segments=5&sides=3").triangleCount(), 10u * 5u * 3u * 2u);
}

TEST(ProceduralHairball, StrandsStayInsideTheUnitSphere) {
  const Scene scene = build("hairball");
  float maxRadius = 0.0f;
  for (const glm::vec3& p : scene.positions) maxRadius = std::max(maxRadius, glm::length(p));
  EXPECT_LT(maxRadius, 1.0f);
  EXPECT_GT(maxRadius, 0.9f);
}

TEST(ProceduralHairball, CentralPixelsExceedDepthComplexity100At1024x1024) {
  const Scene scene = build("hairball");
  const int size = 1024;
  int maxHits = 0;
  for (int y = size / 2 - 2; y <= size / 2 + 2; ++y)
    for (int x = size / 2 - 2; x <= size / 2 + 2; ++x)
      maxHits =
          std::max(maxHits, countHits(scene, pixelRay(*scene.defaultCamera, size, size, x, y)));
  RecordProperty("maxDepthComplexity", maxHits);
  EXPECT_GT(maxHits, 100);
}

// ------------------------------------------------------------------------------------------------
// smoke

TEST(ProceduralSmoke, EveryParticleIsASquareBillboardFacingTheDefaultCamera) {
  const Scene scene = build("smoke?count=2000");
  ASSERT_EQ(scene.triangleCount(), 4000u);
  const Camera& camera = *scene.defaultCamera;
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  for (size_t q = 0; q < 2000; ++q) {
    const uint32_t* t = &scene.indices[6 * q];  // triangles (a, b, c) and (a, c, d)
    const glm::vec3 a = scene.positions[t[0]], b = scene.positions[t[1]], c = scene.positions[t[2]],
                    d = scene.positions[t[5]];
    ASSERT_NEAR(glm::dot(b - a, forward), 0.0f, 1e-5f);
    ASSERT_NEAR(glm::dot(d - a, forward), 0.0f, 1e-5f);
    ASSERT_NEAR(glm::dot(b - a, d - a), 0.0f, 1e-5f);
    ASSERT_NEAR(glm::length(c - a), glm::length(d - b), 1e-5f);
    const float side = glm::length(b - a);
    ASSERT_NEAR(glm::length(d - a), side, 1e-5f);
    ASSERT_GE(side, 2.0f * 0.08f * 0.5f * 0.6f * 0.999f);
    ASSERT_LE(side, 2.0f * 0.08f * 1.5f * 1.4f * 1.001f);
    for (int i = 0; i < 6; ++i) ASSERT_NEAR(glm::dot(scene.normals[t[i]], -forward), 1.0f, 1e-5f);
  }
}

TEST(ProceduralSmoke, SizeParameterScalesTheParticles) {
  const Scene small = build("smoke?count=100&size=0.01"), large = build("smoke?count=100&size=0.1");
  const auto side = [](const Scene& s) {
    return glm::length(s.positions[s.indices[1]] - s.positions[s.indices[0]]);
  };
  EXPECT_NEAR(side(large) / side(small), 10.0f, 1e-3f);
}

// ------------------------------------------------------------------------------------------------
// bottles

TEST(ProceduralBottles, VesselsAreClosedAndNestLiquidInsideGlass) {
  const Scene scene = build("bottles?count=1");
  const int size = 48;
  int maxHits = 0, odd = 0;
  for (int y = 0; y < size; y += 2) {
    for (int x = 1; x < size; x += 2) {
      const int hits = countHits(scene, pixelRay(*scene.defaultCamera, size, size, x, y));
      maxHits = std::max(maxHits, hits);
      odd += hits % 2;
    }
  }
  EXPECT_EQ(odd, 0) << "a ray crossed an odd number of surfaces: some surface is not closed";
  EXPECT_GE(maxHits, 6) << "outer wall, inner wall and liquid: two crossings each";
}

TEST(ProceduralBottles, CountAndSegmentsDetermineTheTriangleCount) {
  // Per vessel: segments * (6 + 4 * (profile - 1) + 2 * (liquid profile - 1)), profile =
  // max(8, segments / 2), liquid profile = max(4, profile / 2).
  EXPECT_EQ(build("bottles").triangleCount(), 6u * 64u * (6u + 4u * 31u + 2u * 15u));
  EXPECT_EQ(build("bottles?count=2&segments=8").triangleCount(),
            2u * 8u * (6u + 4u * 7u + 2u * 3u));
  EXPECT_EQ(build("bottles?count=5").materials.size(), 10u);  // glass and liquid per vessel
}

TEST(ProceduralBottles, SpacingMovesEachVesselWithItsGridCell) {
  // 2 x 2 grid: vessel i sits at column i % 2, row i / 2; spacing s scales the cell offsets
  // (+-0.5 in x and z) and leaves the shapes, jitter and vertex order as they were
  const Scene one = build("bottles?count=4&segments=8");
  EXPECT_EQ(build("bottles?count=4&segments=8&spacing=1").positions, one.positions);
  const float s = 0.6f;
  const Scene close = build("bottles?count=4&segments=8&spacing=0.6");
  ASSERT_EQ(close.indices, one.indices);
  ASSERT_EQ(close.positions.size(), one.positions.size());
  for (size_t t = 0; t < one.indices.size(); ++t) {
    const uint32_t v = one.indices[t];
    const uint32_t vessel = one.triangleMaterial[t / 3] / 2;  // glass, liquid per vessel
    const glm::vec3 cell(static_cast<float>(vessel % 2) - 0.5f, 0.0f,
                         0.5f - static_cast<float>(vessel / 2));
    const glm::vec3 moved = close.positions[v] - one.positions[v];
    ASSERT_NEAR(moved.x, (s - 1.0f) * cell.x, 1e-5f) << t;
    ASSERT_NEAR(moved.y, 0.0f, 1e-6f) << t;
    ASSERT_NEAR(moved.z, (s - 1.0f) * cell.z, 1e-5f) << t;
  }
  expectError("bottles?spacing=0", {"procedural:bottles", "'spacing'"});
}

// ------------------------------------------------------------------------------------------------
// spheres

TEST(ProceduralSpheres, TriangleCountFollowsCountAndDetail) {
  EXPECT_EQ(build("spheres").triangleCount(), 8u * 2u * 128u * 63u);
  EXPECT_EQ(build("spheres?count=3&detail=10").triangleCount(), 3u * 2u * 20u * 9u);
}

TEST(ProceduralSpheres, VerticesLieOnTheSpheresOfRadiusScaleTimesIOverCount) {
  const Scene scene = build("spheres?count=4&scale=2&detail=8");
  ASSERT_EQ(scene.materials.size(), 4u);
  for (size_t t = 0; t < scene.indices.size(); ++t) {
    const uint32_t i = scene.indices[t];
    const float expected = 2.0f * static_cast<float>(scene.triangleMaterial[t / 3] + 1) / 4.0f;
    ASSERT_NEAR(glm::length(scene.positions[i]), expected, 1e-5f);
    ASSERT_NEAR(glm::dot(scene.normals[i], glm::normalize(scene.positions[i])), 1.0f, 1e-5f);
  }
}

TEST(ProceduralSpheres, AnalyticLayerCountMatchesBruteForceRayCasting) {
  const Scene scene = build("spheres");
  const Camera& camera = *scene.defaultCamera;
  const int size = 256;
  const float tolerance = sphereTessellationError(kSpheresDefaultScale, kSpheresDefaultDetail);
  int checked = 0, maxCount = 0;
  for (int y = 3; y < size; y += 12) {
    for (int x = 5; x < size; x += 12) {
      float margin = 0.0f;
      const int analytic = sphereLayersAnalytic(camera, size, size, x, y, kSpheresDefaultCount,
                                                kSpheresDefaultScale, &margin);
      if (margin <= tolerance + 1e-4f) continue;
      ASSERT_EQ(countHits(scene, pixelRay(camera, size, size, x, y)), analytic)
          << "pixel " << x << "," << y << " margin " << margin;
      maxCount = std::max(maxCount, analytic);
      ++checked;
    }
  }
  EXPECT_GT(checked, 300);
  EXPECT_EQ(maxCount, 2 * kSpheresDefaultCount);
}

TEST(ProceduralSpheres, AnalyticCountIsTwicePerSphereAtTheCentreAndZeroInTheCorner) {
  const Camera camera = *build("spheres?detail=4").defaultCamera;
  EXPECT_EQ(sphereLayersAnalytic(camera, 100, 100, 50, 50, 8, 1.0f), 16);
  EXPECT_EQ(sphereLayersAnalytic(camera, 100, 100, 0, 0, 8, 1.0f), 0);
}

TEST(ProceduralSpheres, AnalyticCountHonoursCameraInsideAndClipPlanes) {
  Camera inside;
  inside.eye = glm::vec3(0.0f);
  inside.target = glm::vec3(0.0f, 0.0f, -1.0f);
  EXPECT_EQ(sphereLayersAnalytic(inside, 64, 64, 20, 30, 5, 1.0f), 5);  // one exit per sphere
  Camera clipped;
  clipped.eye = glm::vec3(0.0f, 0.0f, 3.0f);
  // Radii 0.25, 0.5, 0.75, 1: crossings near depths 2, 2.25, 2.5, 2.75, 3.25, 3.5, 3.75, 4.
  clipped.zNear = 2.4f;  // cuts away the front crossings of the two outer spheres
  clipped.zFar = 3.7f;   // and their back crossings
  float margin = 0.0f;
  EXPECT_EQ(sphereLayersAnalytic(clipped, 64, 64, 32, 32, 4, 1.0f, &margin), 4);
  EXPECT_GT(margin, 0.0f);
  EXPECT_LT(margin, 0.06f);
}

}  // namespace
}  // namespace mfr
