// Helpers shared by the tests: hand-made scenes in screen-space terms.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/image.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::test {

/// The camera of the screen-space helpers: eye at (0,0,1) looking at the origin, fov 90, so on the
/// plane z = 0 a square image maps world x, y in [-1, 1] to the whole viewport.
inline Camera screenCamera() {
  Camera c;
  c.eye = {0.0f, 0.0f, 1.0f};
  c.target = {0.0f, 0.0f, 0.0f};
  c.up = {0.0f, 1.0f, 0.0f};
  c.fovYDegrees = 90.0f;
  c.zNear = 0.1f;
  c.zFar = 10.0f;
  return c;
}

/// World point on the plane z (z <= 0 further away) that projects to pixel coordinates (sx, sy)
/// (y down, pixel centres at +0.5) of a size x size image through screenCamera().
inline glm::vec3 screenPoint(double sx, double sy, int size, float z = 0.0f) {
  const double ndcX = sx / size * 2.0 - 1.0, ndcY = 1.0 - sy / size * 2.0;
  const double distance = 1.0 - z;
  return glm::vec3(static_cast<float>(ndcX * distance), static_cast<float>(ndcY * distance), z);
}

struct TestTriangle {
  glm::vec3 a, b, c;
  glm::vec4 color{1.0f, 1.0f, 1.0f, 0.5f};
};

/// A scene of independent triangles, one Blend material per triangle, normals facing +z.
inline Scene makeScene(const std::vector<TestTriangle>& triangles) {
  Scene s;
  s.name = "test-scene";
  for (const TestTriangle& t : triangles) {
    const uint32_t base = static_cast<uint32_t>(s.positions.size());
    s.positions.insert(s.positions.end(), {t.a, t.b, t.c});
    s.normals.insert(s.normals.end(), 3, glm::vec3(0.0f, 0.0f, 1.0f));
    s.indices.insert(s.indices.end(), {base, base + 1, base + 2});
    s.triangleMaterial.push_back(static_cast<uint32_t>(s.materials.size()));
    Material m;
    m.name = "material ";
    m.name += std::to_string(s.materials.size());
    m.baseColor = t.color;
    m.alphaMode = AlphaMode::Blend;
    s.materials.push_back(m);
  }
  return s;
}

/// Two triangles forming the screen-space rectangle [x0, x1] x [y0, y1] at depth z.
inline std::vector<TestTriangle> screenRect(double x0, double y0, double x1, double y1, int size,
                                            float z = 0.0f, glm::vec4 color = glm::vec4(1.0f)) {
  const glm::vec3 p00 = screenPoint(x0, y0, size, z), p10 = screenPoint(x1, y0, size, z);
  const glm::vec3 p01 = screenPoint(x0, y1, size, z), p11 = screenPoint(x1, y1, size, z);
  return {{p00, p10, p11, color}, {p00, p11, p01, color}};
}

/// The largest absolute difference of one colour channel over two images of the same size.
inline float largestDifference(const ImageRGB& a, const ImageRGB& b) {
  float worst = 0.0f;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const glm::vec3 d = glm::abs(a.pixels[i] - b.pixels[i]);
    worst = std::max({worst, d.r, d.g, d.b});
  }
  return worst;
}

}  // namespace mfr::test
