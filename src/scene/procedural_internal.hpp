// Shared helpers of the built-in procedural scenes (src/scene/procedural*.cpp): the parameter
// reader, a platform-independent seeded random number generator, colours, framing cameras and the
// mesh builders (tube, lathe / UV sphere, billboard quad) the individual scenes are made of.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

#include "mfr/core/result.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/procedural.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::procedural {

/// No parameter combination may produce more triangles than this by default.
inline constexpr double kMaxTriangles = kMaxProceduralTriangles;

// ---------------------------------------------------------------------------------------------
// Random numbers

/// SplitMix64 (Steele, Lea, Flood 2014). Every value is derived from the raw 64-bit outputs with
/// integer and exactly rounded float arithmetic only, so a seed gives the same stream on every
/// platform (unlike the implementation-defined std:: distributions). Callers draw one value per
/// statement: the evaluation order of function arguments and operands is unspecified, so
/// glm::vec3(rng.uniform(), rng.uniform(), ...) would differ between compilers.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}

  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }

  /// Uniform in [0, 1) with 24 random bits (every value exactly representable as a float).
  float uniform() { return static_cast<float>(next() >> 40) * 0x1.0p-24f; }
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }

  /// Uniform integer in [0, n), n > 0 (multiply-shift; bias below 2^-32, irrelevant here).
  uint32_t below(uint32_t n) { return static_cast<uint32_t>(((next() >> 32) * n) >> 32); }

  /// Approximately standard normal: Irwin-Hall sum of four uniforms rescaled to unit variance
  /// (support [-2*sqrt(3), 2*sqrt(3)]; no transcendental functions, hence reproducible).
  float normal() {
    float sum = uniform();
    sum += uniform();
    sum += uniform();
    sum += uniform();
    return (sum - 2.0f) * 1.7320508f;
  }

  /// Uniform in the unit ball (rejection sampling from the cube).
  glm::vec3 inUnitBall() {
    for (;;) {
      const glm::vec3 p = inCube();
      if (glm::dot(p, p) <= 1.0f) return p;
    }
  }

  /// Uniform on the unit sphere (rejection sampling, then normalisation).
  glm::vec3 unitVector() {
    for (;;) {
      const glm::vec3 p = inCube();
      const float len2 = glm::dot(p, p);
      if (len2 <= 1.0f && len2 > 1e-4f) return p / std::sqrt(len2);
    }
  }

 private:
  glm::vec3 inCube() {
    glm::vec3 p;
    p.x = uniform(-1.0f, 1.0f);
    p.y = uniform(-1.0f, 1.0f);
    p.z = uniform(-1.0f, 1.0f);
    return p;
  }

  uint64_t state_;
};

// ---------------------------------------------------------------------------------------------
// Parameters

/// Typed access to the parameters of one scene. A getter that fails (value does not parse, or is
/// out of range) records the first error and returns the default; builders check error() once
/// after reading all their parameters. Messages are prefixed with e.g. "procedural:layers".
class ParamReader {
 public:
  ParamReader(std::string prefix, const ProceduralParams& params,
              double maxTriangles = kMaxTriangles, uint64_t memoryLimit = UINT64_MAX)
      : prefix_(std::move(prefix)),
        params_(params),
        maxTriangles_(maxTriangles),
        memoryLimit_(memoryLimit) {}

  /// Integer in [lo, hi].
  int64_t integer(std::string_view key, int64_t fallback, int64_t lo, int64_t hi);
  /// Real number in [lo, hi], or (lo, hi] when lowOpen.
  float real(std::string_view key, double fallback, double lo, double hi, bool lowOpen = false);

  const std::optional<Error>& error() const { return error_; }
  const std::string& prefix() const { return prefix_; }
  /// The triangle cap checkTriangleBudget applies.
  double maxTriangles() const { return maxTriangles_; }
  /// The memory limit checkTriangleBudget applies (sceneMemoryBytes).
  uint64_t memoryLimit() const { return memoryLimit_; }
  /// An error whose message is "<prefix>: <message>".
  Error fail(const std::string& message) const { return makeError(prefix_ + ": " + message); }

 private:
  const std::string* find(std::string_view key) const;
  void record(const std::string& message);

  std::string prefix_;
  const ProceduralParams& params_;
  double maxTriangles_;
  uint64_t memoryLimit_;
  std::optional<Error> error_;
};

/// Error unless `triangles` (computed in floating point so it cannot overflow) is within the cap
/// (params.maxTriangles()) and the scene they make fits the memory limit (params.memoryLimit()):
/// sceneMemoryBytes of the triangles and twice as many vertices (no scene makes more: a billboard
/// quad has 4 vertices and 2 triangles, a box 24 and 12, a tube or lathe fewer). Every builder
/// calls it before it allocates.
Result<void> checkTriangleBudget(const ParamReader& params, double triangles);

/// Shortest round-trip decimal form of a double ("0.5", "1e-06").
std::string formatNumber(double value);

// ---------------------------------------------------------------------------------------------
// Colours and cameras

/// HSV (all in [0, 1], hue wraps) to RGB; used directly as linear base colours.
glm::vec3 hsv(float hue, float saturation, float value);

/// Hue of the i-th colour of a maximally spread sequence (golden-ratio steps from `offset`).
float goldenHue(uint32_t i, float offset = 0.0f);

/// A camera looking at the sphere (center, radius) from the +z side, slightly above (the
/// direction frameBounds uses), at the distance where the whole sphere fits the vertical field of
/// view with 5% margin; clip planes are left at 0 (fit them once the scene is built).
Camera cameraForSphere(const glm::vec3& center, float radius, float fovYDegrees = 45.0f);

/// The camera looking at the centre of the scene's bounds from the direction cameraForSphere uses,
/// at the smallest distance where every vertex lies within 95% of the view frustum of a square
/// viewport (tighter than frameBounds, which frames the bounding box's sphere), clip planes 5%
/// beyond the nearest and farthest vertex.
Camera frameVertices(const Scene& scene, float fovYDegrees = 45.0f);

// ---------------------------------------------------------------------------------------------
// Mesh building

/// Appends vertices, triangles and materials to a scene.
class MeshBuilder {
 public:
  explicit MeshBuilder(Scene& scene) : scene_(scene) {}

  void reserve(size_t vertices, size_t triangles);
  uint32_t material(std::string name, const glm::vec3& color, float alpha);
  uint32_t vertex(const glm::vec3& position, const glm::vec3& normal);
  /// Adds triangle (a, b, c), wound counter-clockwise around the mean of its vertex normals (the
  /// order is swapped when the given one disagrees with the normals).
  void triangle(uint32_t a, uint32_t b, uint32_t c, uint32_t material);
  /// Two triangles (a, b, c) and (a, c, d) of the quad a-b-c-d.
  void quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d, uint32_t material);

  Scene& scene() { return scene_; }

 private:
  Scene& scene_;
};

/// Triangles appendTube makes for `points` centre-line points and `sides` sides.
inline double tubeTriangles(double points, double sides) {
  return (points - 1.0) * sides * 2.0;
}

/// An open tube of `radius` around the centre line (at least two points), `sides` vertices per
/// ring. Rings are oriented by a parallel-transported frame along the analytic `tangents` (one per
/// point, unit length); vertex normals are the analytic tube normals.
void appendTube(MeshBuilder& mesh, std::span<const glm::vec3> centerline,
                std::span<const glm::vec3> tangents, float radius, int sides, uint32_t material);

/// Point of a lathe profile: radius from the axis, height, and the unit surface normal in the
/// (radial, up) plane.
struct ProfilePoint {
  float r = 0.0f;
  float y = 0.0f;
  glm::vec2 normal{1.0f, 0.0f};
};

/// Triangles appendLathe makes for the profile with `segments` steps around the axis.
double latheTriangles(std::span<const ProfilePoint> profile, double segments);

/// Surface of revolution of the profile about the vertical axis through `base` (profile heights are
/// relative to base.y). Points with r <= 0 lie on the axis and become a single vertex (fan). The
/// angle starts at +x and the ring has no seam duplicate.
void appendLathe(MeshBuilder& mesh, std::span<const ProfilePoint> profile, int segments,
                 const glm::vec3& base, uint32_t material);

/// Sets each point's normal from its neighbours (central differences of the polyline), rotated to
/// the right of the direction of travel: a profile that runs upwards gets outward normals.
void computeProfileNormals(std::span<ProfilePoint> profile);

/// Triangles appendUvSphere makes (2 * sectors * (rings - 1)).
inline double uvSphereTriangles(double rings, double sectors) {
  return 2.0 * sectors * (rings - 1.0);
}

/// UV sphere with poles on the y axis: `rings` latitude bands, `sectors` longitude steps, vertices
/// exactly on the sphere, normals radial.
void appendUvSphere(MeshBuilder& mesh, const glm::vec3& center, float radius, int rings,
                    int sectors, uint32_t material);

/// Triangles appendBox makes.
inline constexpr double kBoxTriangles = 12.0;

/// Closed axis-aligned box [lo, hi] (hi > lo on every axis): 6 faces of 4 own vertices with the
/// face normal, 12 triangles, so a ray through its interior crosses it exactly twice.
void appendBox(MeshBuilder& mesh, const glm::vec3& lo, const glm::vec3& hi, uint32_t material);

/// A per-material alpha around the scene's `alpha`: alpha * [1 - spread, 1 + spread], clamped to
/// [0.02, 1] (the corpus families' "per-material alphas"; spread 0 keeps the global alpha).
float jitteredAlpha(Rng& rng, float alpha, float spread);

// ---------------------------------------------------------------------------------------------
// The scenes (the dispatcher has already rejected unknown keys and parsed the seed).

Result<Scene> buildLayers(ParamReader& params, uint64_t seed);
Result<Scene> buildHairball(ParamReader& params, uint64_t seed);
Result<Scene> buildSmoke(ParamReader& params, uint64_t seed);
Result<Scene> buildBottles(ParamReader& params, uint64_t seed);
Result<Scene> buildSpheres(ParamReader& params, uint64_t seed);
// The training corpus families (issue 14 sec. 2): one file each, procedural_<name>.cpp.
Result<Scene> buildGlassware(ParamReader& params, uint64_t seed);
Result<Scene> buildFoliage(ParamReader& params, uint64_t seed);
Result<Scene> buildParticles(ParamReader& params, uint64_t seed);
Result<Scene> buildHair(ParamReader& params, uint64_t seed);
Result<Scene> buildPanels(ParamReader& params, uint64_t seed);
Result<Scene> buildCity(ParamReader& params, uint64_t seed);

}  // namespace mfr::procedural
