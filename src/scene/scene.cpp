#include "mfr/scene/scene.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "mfr/core/memory_limit.hpp"
#include "mfr/core/quote.hpp"

namespace mfr {

uint64_t sceneMemoryBytes(uint64_t vertices, uint64_t triangles) {
  return saturatingAdd(saturatingMul(vertices, kSceneBytesPerVertex),
                       saturatingMul(triangles, kSceneBytesPerTriangle));
}

Result<void> checkSceneMemory(uint64_t vertices, uint64_t triangles, uint64_t limit,
                              const std::string& what) {
  return checkMemory(sceneMemoryBytes(vertices, triangles), limit,
                     what + ": its " + std::to_string(vertices) + " vertices and " +
                         std::to_string(triangles) + " triangles");
}

Bounds sceneBounds(const Scene& scene) {
  Bounds b;
  if (scene.indices.empty()) return b;
  b.min = glm::vec3(std::numeric_limits<float>::max());
  b.max = glm::vec3(-std::numeric_limits<float>::max());
  for (uint32_t index : scene.indices) {
    b.min = glm::min(b.min, scene.positions[index]);
    b.max = glm::max(b.max, scene.positions[index]);
  }
  return b;
}

static bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Result<void> validateScene(const Scene& scene) {
  const std::string& name = scene.name;
  if (scene.indices.empty()) return makeError(name + ": scene has no triangles");
  if (scene.indices.size() % 3 != 0)
    return makeError(name + ": index count is not a multiple of 3");
  if (scene.triangleMaterial.size() != scene.triangleCount())
    return makeError(name + ": one material index per triangle expected");
  if (scene.normals.size() != scene.positions.size())
    return makeError(name + ": one normal per vertex expected");
  if (!scene.uvs.empty() && scene.uvs.size() != scene.positions.size())
    return makeError(name + ": one texture coordinate per vertex expected");
  if (!scene.colors.empty() && scene.colors.size() != scene.positions.size())
    return makeError(name + ": one vertex colour per vertex expected");
  if (scene.materials.empty()) return makeError(name + ": scene has no materials");
  if (!scene.cameraProblems.empty() && scene.cameraProblems.size() != scene.cameras.size())
    return makeError(name + ": one camera problem per camera expected");
  for (uint32_t index : scene.indices)
    if (index >= scene.positions.size())
      return makeError(name + ": vertex index " + std::to_string(index) + " out of range");
  for (uint32_t m : scene.triangleMaterial)
    if (m >= scene.materials.size())
      return makeError(name + ": material index " + std::to_string(m) + " out of range");
  for (size_t i = 0; i < scene.positions.size(); ++i)
    if (!finite(scene.positions[i]))
      return makeError(name + ": vertex " + std::to_string(i) +
                       " has a NaN or infinite coordinate");
  for (size_t i = 0; i < scene.positions.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (std::abs(scene.positions[i][c]) > kMaxCoordinate) {
        char value[32];
        std::snprintf(value, sizeof value, "%g", static_cast<double>(scene.positions[i][c]));
        return makeError(name + ": vertex " + std::to_string(i) + " has coordinate " + value +
                         ", beyond the +-1e18 that the single-precision bounds, framing and "
                         "clipping arithmetic can square");
      }
  for (size_t i = 0; i < scene.normals.size(); ++i)
    if (!finite(scene.normals[i]))
      return makeError(name + ": normal " + std::to_string(i) + " is NaN or infinite");
  for (const Material& m : scene.materials) {
    if (m.baseColorTexture >= static_cast<int>(scene.textures.size()))
      return makeError(name + ": material " + quoteInput(m.name) + " names a missing texture");
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(m.baseColor[c]))
        return makeError(name + ": material " + quoteInput(m.name) +
                         " has a non-finite base colour");
  }
  for (size_t i = 0; i < scene.colors.size(); ++i)
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(scene.colors[i][c]))
        return makeError(name + ": vertex colour " + std::to_string(i) + " is NaN or infinite");
  for (const Texture& t : scene.textures)
    if (t.width <= 0 || t.height <= 0 ||
        t.rgba.size() != static_cast<size_t>(t.width) * static_cast<size_t>(t.height) * 4)
      return makeError(name + ": texture with inconsistent size");
  if (scene.alphaOverride && !(*scene.alphaOverride >= 0.0f && *scene.alphaOverride <= 1.0f))
    return makeError(name + ": alpha override must be in [0, 1]");
  return {};
}

void computeVertexNormals(Scene& scene) {
  if (!scene.normals.empty()) return;
  scene.normals.assign(scene.positions.size(), glm::vec3(0.0f));
  for (size_t t = 0; t + 2 < scene.indices.size(); t += 3) {
    const uint32_t i0 = scene.indices[t], i1 = scene.indices[t + 1], i2 = scene.indices[t + 2];
    if (i0 >= scene.positions.size() || i1 >= scene.positions.size() ||
        i2 >= scene.positions.size())
      continue;
    const glm::vec3 n = glm::cross(scene.positions[i1] - scene.positions[i0],
                                   scene.positions[i2] - scene.positions[i0]);
    scene.normals[i0] += n;
    scene.normals[i1] += n;
    scene.normals[i2] += n;
  }
  for (glm::vec3& n : scene.normals) {
    const float len = glm::length(n);
    n = (len > 0.0f && std::isfinite(len)) ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
}

}  // namespace mfr
