// Tests of the training corpus's procedural families (issue 14 sec. 2: glassware, foliage,
// particles, hair, panels, city): determinism from the seed, the triangle counts their headers
// promise, and depth-complexity statistics derived from each family's geometry, counted by
// brute-force ray casting (Moller-Trumbore against every triangle).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mfr/scene/camera.hpp"
#include "mfr/scene/procedural.hpp"
#include "mfr/scene/scene.hpp"
#include "ray_hits.hpp"
#include "scene/procedural_internal.hpp"

namespace mfr {
namespace {

const std::vector<std::string> kFamilies = {"glassware", "foliage", "particles",
                                            "hair",      "panels",  "city"};

Scene build(const std::string& spec, uint64_t seed = 1) {
  Result<Scene> result = makeProceduralScene(spec, seed);
  if (!result) {
    ADD_FAILURE() << spec << ": " << result.error().message;
    return Scene{};
  }
  return std::move(result).value();
}

using test::countHits;

/// Depth complexity through the centres of a size x size image of the default camera.
std::vector<int> pixelCounts(const Scene& scene, int size) {
  std::vector<int> counts;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const Ray ray = pixelRay(*scene.defaultCamera, size, size, x, y);
      counts.push_back(countHits(scene, ray.origin, ray.direction));
    }
  return counts;
}

int countOdd(const std::vector<int>& counts) {
  return static_cast<int>(std::count_if(counts.begin(), counts.end(), [](int n) { return n % 2; }));
}

TEST(ProceduralCorpus, EveryFamilyIsRegistered) {
  const std::vector<std::string> names = proceduralSceneNames();
  for (const std::string& family : kFamilies)
    EXPECT_NE(std::find(names.begin(), names.end(), family), names.end()) << family;
}

TEST(ProceduralCorpus, EachFamilyIsDeterministicFromItsSeedAndVariesWithIt) {
  for (const std::string& family : kFamilies) {
    SCOPED_TRACE(family);
    const Scene a = build(family, 11), b = build(family, 11), c = build(family, 12);
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.indices, b.indices);
    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (size_t i = 0; i < a.materials.size(); ++i)
      EXPECT_EQ(a.materials[i].baseColor, b.materials[i].baseColor);
    EXPECT_NE(a.positions, c.positions);
    EXPECT_EQ(build(family + "?seed=11", 5).positions, a.positions);
  }
}

TEST(ProceduralCorpus, SpreadJittersPerMaterialAlphasAroundTheGlobalAlpha) {
  for (const std::string& family : kFamilies) {
    SCOPED_TRACE(family);
    const Scene flat = build(family + "?alpha=0.4&spread=0");
    for (const Material& m : flat.materials) EXPECT_FLOAT_EQ(m.baseColor.a, 0.4f);
    const Scene jittered = build(family + "?alpha=0.4&spread=0.5");
    float lo = 1.0f, hi = 0.0f;
    for (const Material& m : jittered.materials) {
      lo = std::min(lo, m.baseColor.a);
      hi = std::max(hi, m.baseColor.a);
    }
    EXPECT_GE(lo, 0.2f - 1e-6f);
    EXPECT_LE(hi, 0.6f + 1e-6f);
    EXPECT_GT(hi - lo, 0.01f) << "alphas do not vary per material";
  }
}

TEST(ProceduralCorpus, ParametersAreValidatedWithOneLineErrors) {
  for (const std::string spec : {"glassware?shells=5", "foliage?leaves=0", "particles?size=0",
                                 "hair?sides=2", "panels?boxes=0&panels=0", "city?rows=0"}) {
    Result<Scene> result = makeProceduralScene(spec, 1);
    ASSERT_FALSE(result.ok()) << spec;
    EXPECT_EQ(result.error().message.find('\n'), std::string::npos);
    EXPECT_NE(result.error().message.find("procedural:" + spec.substr(0, spec.find('?'))),
              std::string::npos)
        << result.error().message;
  }
}

// glassware: closed nested shells, a liquid inside them

TEST(ProceduralCorpus, GlasswareTriangleCountFollowsShellsAndSegments) {
  // per object: segments * 2 * samples per shell, segments * 2 * max(4, samples / 2) liquid,
  // samples = max(8, segments / 2)
  EXPECT_EQ(build("glassware").triangleCount(), 4u * (2u * 48u * 2u * 24u + 48u * 2u * 12u));
  EXPECT_EQ(build("glassware?count=3&segments=8&shells=3").triangleCount(),
            3u * (3u * 8u * 2u * 8u + 8u * 2u * 4u));
}

TEST(ProceduralCorpus, GlasswareShellsAreClosedAndALineThroughTheLiquidCrossesThemAll) {
  for (int shells : {1, 3}) {
    SCOPED_TRACE(shells);
    const Scene scene = build("glassware?count=1&segments=24&shells=" + std::to_string(shells));
    const std::vector<int> counts = pixelCounts(scene, 24);
    EXPECT_EQ(countOdd(counts), 0) << "a ray crossed an odd number of surfaces";
    // the centre ray meets the axis at half height, below the liquid's level (>= 55% filled)
    const int centre = counts[12 * 24 + 12];
    EXPECT_GE(centre, 2 * (shells + 1));
    // the liquid is the innermost closed surface: the count inside its outline exceeds the
    // shells' only, and every covered pixel crosses at least the outer shell
    for (int n : counts) EXPECT_TRUE(n == 0 || n >= 2);
  }
}

// foliage: flat leaves uniform in a crown ball

TEST(ProceduralCorpus, FoliageLinesThroughTheCrownCrossTheExpectedNumberOfLeaves) {
  const int leaves = 400;
  const Scene scene = build("foliage?plants=1&leaves=" + std::to_string(leaves));
  // the crown centre: the mean of the leaves' vertices (the stem's 24 vertices come first)
  glm::dvec3 crown(0.0);
  for (size_t i = 24; i < scene.positions.size(); ++i) crown += glm::dvec3(scene.positions[i]);
  crown /= static_cast<double>(scene.positions.size() - 24);
  // a fan of 8 triangles inscribed in the ellipse: (8 / 2) a b sin(2 pi / 8)
  const double area = 4.0 * std::sin(glm::pi<double>() / 4.0) * 0.09 * 0.04;
  const double expected = 3.0 * leaves * area / (4.0 * glm::pi<double>() * 0.45 * 0.45);
  procedural::Rng rng(3);
  double sum = 0.0;
  const int lines = 300;
  int maxHits = 0;
  for (int i = 0; i < lines; ++i) {
    const glm::dvec3 d(rng.unitVector());
    const int hits = countHits(scene, crown - 3.0 * d, d, 36);  // leaves only (the stem: 36)
    sum += hits;
    maxHits = std::max(maxHits, hits);
  }
  EXPECT_NEAR(sum / lines, expected, 0.25 * expected);
  EXPECT_LE(maxHits, leaves + 2);
}

// particles: billboards uniform in cloud balls, facing the default camera's direction

TEST(ProceduralCorpus, ParticlesAlongTheViewThroughACloudCentreMatchTheDensity) {
  const int count = 3000;
  const double size = 0.03;
  const Scene scene = build("particles?clouds=1&size=0.03&count=" + std::to_string(count));
  double radius = 0.0;  // the cloud's radius: the farthest particle centre (4 vertices each)
  for (size_t i = 0; i + 3 < scene.positions.size(); i += 4) {
    glm::dvec3 c(0.0);
    for (size_t k = 0; k < 4; ++k) c += glm::dvec3(scene.positions[i + k]) / 4.0;
    radius = std::max(radius, glm::length(c));
  }
  const double expected =
      3.0 * count * (13.0 / 12.0) * size * size / (glm::pi<double>() * radius * radius);
  const glm::dvec3 forward = -glm::normalize(glm::dvec3(0.0, 0.35, 1.0));
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  const glm::dvec3 up = glm::cross(right, forward);
  procedural::Rng rng(5);
  double sum = 0.0;
  const int lines = 200;
  for (int i = 0; i < lines; ++i) {
    const double dx = 0.05 * radius * rng.uniform(-1.0f, 1.0f);
    const double dy = 0.05 * radius * rng.uniform(-1.0f, 1.0f);
    sum += countHits(scene, -3.0 * forward + dx * right + dy * up, forward);
  }
  EXPECT_NEAR(sum / lines / 2.0, expected, 0.25 * expected);  // 2 triangles per square
}

// hair: tubes and a closed head

TEST(ProceduralCorpus, HairCrossingsComeInPairsAndStayBelowTwicePerStrand) {
  const int strands = 300;
  const Scene scene = build("hair?segments=8&strands=" + std::to_string(strands));
  const std::vector<int> counts = pixelCounts(scene, 32);
  const int covered =
      static_cast<int>(std::count_if(counts.begin(), counts.end(), [](int n) { return n > 0; }));
  EXPECT_GT(covered, 32 * 32 / 10);
  EXPECT_LE(countOdd(counts), covered / 20) << "tubes are closed around their axis";
  EXPECT_LE(*std::max_element(counts.begin(), counts.end()), 2 * strands + 2);
  // the head: a line through its centre crosses the sphere twice, plus strands
  EXPECT_GE(countHits(scene, glm::dvec3(0.0, 0.0, 3.0), glm::dvec3(0.0, 0.0, -1.0)), 2);
}

// panels: closed boxes in cells behind closed glass slabs

TEST(ProceduralCorpus, PanelsCountsAreEvenBoundedAndTheCentreCrossesEverySlab) {
  const int boxes = 20, panels = 3;
  const Scene scene =
      build("panels?boxes=" + std::to_string(boxes) + "&panels=" + std::to_string(panels));
  EXPECT_EQ(scene.triangleCount(), 12u * (boxes + panels));
  const std::vector<int> counts = pixelCounts(scene, 24);
  EXPECT_EQ(countOdd(counts), 0);
  EXPECT_LE(*std::max_element(counts.begin(), counts.end()), 2 * (boxes + panels));
  EXPECT_GE(counts[12 * 24 + 12], 2 * panels);
}

// city: a grid of closed buildings, some with a core

TEST(ProceduralCorpus, CityCountsAreEvenAndBoundedByTheCellsALineCanCross) {
  const int rows = 3, columns = 4;
  const Scene scene =
      build("city?rows=" + std::to_string(rows) + "&columns=" + std::to_string(columns));
  const size_t boxes = scene.triangleCount() / 12;
  EXPECT_GE(boxes, static_cast<size_t>(rows * columns));
  EXPECT_LE(boxes, static_cast<size_t>(2 * rows * columns));
  const std::vector<int> counts = pixelCounts(scene, 24);
  EXPECT_EQ(countOdd(counts), 0);
  const int bound = 4 * (rows + columns - 1);
  EXPECT_LE(*std::max_element(counts.begin(), counts.end()), bound);
  procedural::Rng rng(9);  // any line, not only the camera's
  for (int i = 0; i < 200; ++i) {
    const glm::dvec3 d(rng.unitVector());
    const glm::dvec3 through(rng.uniform(-2.0f, 2.0f), rng.uniform(0.0f, 3.0f),
                             rng.uniform(-1.5f, 1.5f));
    EXPECT_LE(countHits(scene, through - 20.0 * d, d), bound);
  }
}

}  // namespace
}  // namespace mfr
