// A tiny glTF 2.0 file for the vertex colour tests (issue 24): one quad x, y in [-1, 1] (z = 0,
// facing +z) whose COLOR_0 is `left` at the two vertices x = -1 and `right` at the two x = 1, in
// one of the accessor formats glTF allows (float VEC3 / VEC4, normalized unsigned byte,
// normalized unsigned short). The colour is linear in x, so any triangulation and any
// perspective-correct interpolation gives colour(x) = left + (right - left) (x + 1) / 2 at the
// surface point x: the tests' expectation.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "gltf_quads.hpp"
#include "mfr/core/image.hpp"
#include "mfr/scene/camera.hpp"
#include "quad_checks.hpp"

namespace mfr::test {

enum class ColorFormat { FloatRgb, FloatRgba, Unorm8Rgba, Unorm16Rgb };

inline const char* toString(ColorFormat f) {
  switch (f) {
    case ColorFormat::FloatRgb:
      return "FloatRgb";
    case ColorFormat::FloatRgba:
      return "FloatRgba";
    case ColorFormat::Unorm8Rgba:
      return "Unorm8Rgba";
    default:
      return "Unorm16Rgb";
  }
}

/// The colour a format stores for `value` (components in [0, 1]), as the glTF specification
/// decodes it (section 3.11: c / 255, c / 65535 for the rounded code c); alpha 1 for RGB formats.
inline std::array<double, 4> storedColor(ColorFormat f, const std::array<double, 4>& value) {
  std::array<double, 4> out = value;
  const bool rgb = f == ColorFormat::FloatRgb || f == ColorFormat::Unorm16Rgb;
  for (int c = 0; c < 4; ++c) {
    if (f == ColorFormat::Unorm8Rgba) out[c] = std::round(value[c] * 255.0) / 255.0;
    if (f == ColorFormat::Unorm16Rgb) out[c] = std::round(value[c] * 65535.0) / 65535.0;
    if (f == ColorFormat::FloatRgb || f == ColorFormat::FloatRgba)
      out[c] = static_cast<double>(static_cast<float>(value[c]));
  }
  if (rgb) out[3] = 1.0;
  return out;
}

/// The glTF text of the quad with `material` (a glTF material object; null: none, the default
/// material) and COLOR_0 in `format` (left / right: RGBA in [0, 1]; RGB formats drop alpha).
inline std::string vertexColorQuadGltf(ColorFormat format, const std::array<double, 4>& left,
                                       const std::array<double, 4>& right,
                                       const nlohmann::json& material) {
  using nlohmann::json;
  const float positions[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const float normals[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  const std::array<double, 4>* corner[4] = {&left, &right, &right, &left};
  std::string bin;
  json views = json::array();
  auto append = [&](const void* data, size_t size, int stride) {
    while (bin.size() % 4 != 0) bin += '\0';
    json view = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}};
    if (stride > 0) view["byteStride"] = stride;
    views.push_back(view);
    bin.append(static_cast<const char*>(data), size);
    return views.size() - 1;
  };
  json colorAccessor;
  switch (format) {
    case ColorFormat::FloatRgb:
    case ColorFormat::FloatRgba: {
      const int n = format == ColorFormat::FloatRgb ? 3 : 4;
      float values[16];
      for (int v = 0; v < 4; ++v)
        for (int c = 0; c < n; ++c) values[v * n + c] = static_cast<float>((*corner[v])[c]);
      colorAccessor = {{"bufferView", append(values, sizeof(float) * 4 * n, 0)},
                       {"componentType", 5126},
                       {"type", n == 3 ? "VEC3" : "VEC4"}};
      break;
    }
    case ColorFormat::Unorm8Rgba: {
      uint8_t values[16];
      for (int v = 0; v < 4; ++v)
        for (int c = 0; c < 4; ++c)
          values[v * 4 + c] = static_cast<uint8_t>(std::round((*corner[v])[c] * 255.0));
      colorAccessor = {{"bufferView", append(values, sizeof values, 0)},
                       {"componentType", 5121},
                       {"normalized", true},
                       {"type", "VEC4"}};
      break;
    }
    case ColorFormat::Unorm16Rgb: {
      // 6-byte elements padded to 8 (vertex attributes are 4-byte aligned): a strided view
      uint16_t values[16] = {};
      for (int v = 0; v < 4; ++v)
        for (int c = 0; c < 3; ++c)
          values[v * 4 + c] = static_cast<uint16_t>(std::round((*corner[v])[c] * 65535.0));
      colorAccessor = {{"bufferView", append(values, sizeof values, 8)},
                       {"componentType", 5123},
                       {"normalized", true},
                       {"type", "VEC3"}};
      break;
    }
  }
  colorAccessor["count"] = 4;
  json accessors = json::array({{{"bufferView", append(positions, sizeof positions, 0)},
                                 {"componentType", 5126},
                                 {"count", 4},
                                 {"type", "VEC3"},
                                 {"min", {-1, -1, 0}},
                                 {"max", {1, 1, 0}}},
                                {{"bufferView", append(normals, sizeof normals, 0)},
                                 {"componentType", 5126},
                                 {"count", 4},
                                 {"type", "VEC3"}},
                                colorAccessor,
                                {{"bufferView", append(indices, sizeof indices, 0)},
                                 {"componentType", 5123},
                                 {"count", 6},
                                 {"type", "SCALAR"}}});
  json primitive = {{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"COLOR_0", 2}}},
                    {"indices", 3}};
  json doc;
  doc["asset"] = {{"version", "2.0"}};
  doc["scene"] = 0;
  doc["scenes"] = json::array({{{"nodes", {0}}}});
  doc["nodes"] = json::array({{{"mesh", 0}}});
  if (!material.is_null()) {
    primitive["material"] = 0;
    doc["materials"] = json::array({material});
  }
  doc["meshes"] = json::array({{{"primitives", json::array({primitive})}}});
  doc["accessors"] = accessors;
  doc["bufferViews"] = views;
  doc["buffers"] = gltfEmbeddedBuffer(bin);
  return doc.dump();
}

using Rgba = std::array<double, 4>;

/// Seen from the side and above: depth changes strongly across the quad, so screen-linear
/// (affine) interpolation of the colour would be visibly wrong.
inline Camera vertexColorTilted() {
  Camera camera;
  camera.eye = {2.2f, 0.6f, 1.6f};
  camera.target = {0.0f, 0.0f, 0.0f};
  camera.fovYDegrees = 60.0f;
  return camera;
}

/// Where the ray of pixel centre (px, py) meets the plane z = 0 (a camera looking at it), and the
/// ray's |cos| with the plane's normal: lookAt's basis and the pixel's NDC, written out here.
struct QuadHit {
  glm::dvec2 point;
  double cosine;
  double viewDepth;  // distance along the view direction (what the near plane cuts)
};
inline QuadHit hitQuad(const Camera& c, int px, int py, int width, int height) {
  const glm::dvec3 eye(c.eye), forward = glm::normalize(glm::dvec3(c.target) - eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(c.up)));
  const glm::dvec3 up = glm::cross(right, forward);
  const double t = std::tan(glm::radians(static_cast<double>(c.fovYDegrees)) / 2.0);
  const double aspect = static_cast<double>(width) / height;
  const double nx = 2.0 * (px + 0.5) / width - 1.0, ny = 1.0 - 2.0 * (py + 0.5) / height;
  const glm::dvec3 dir = forward + right * (nx * t * aspect) + up * (ny * t);
  const double s = -eye.z / dir.z;
  const glm::dvec3 p = eye + s * dir;
  return {{p.x, p.y}, std::abs(dir.z) / glm::length(dir), glm::dot(p - eye, forward)};
}

/// The expected linear colour of pixel (px, py): factor x colour(x) at the surface point, lit by
/// the headlight 0.2 + 0.8 |n.v|, over `background` by factor alpha x colour alpha (MASK: kept
/// where that alpha >= 0.5, opaque; OPAQUE: alpha 1). False for pixels not to compare: off the
/// quad or within 0.02 of its edge, (MASK) within 0.03 of the cutoff, and within 0.02 of the
/// camera's near plane when it sets one (nearer: the background).
inline bool expectedQuadPixel(const Camera& camera, int px, int py, int width, int height,
                              const Rgba& left, const Rgba& right, const Rgba& factor,
                              const std::string& alphaMode, const glm::dvec3& background,
                              glm::dvec3& out) {
  const QuadHit hit = hitQuad(camera, px, py, width, height);
  if (std::abs(hit.point.x) > 0.98 || std::abs(hit.point.y) > 0.98) return false;
  if (camera.zNear > 0.0f) {
    if (std::abs(hit.viewDepth - camera.zNear) < 0.02) return false;
    if (hit.viewDepth < camera.zNear) {
      out = background;
      return true;
    }
  }
  const double s = (hit.point.x + 1.0) / 2.0;
  Rgba c;
  for (int i = 0; i < 4; ++i) c[i] = left[i] + (right[i] - left[i]) * s;
  double alpha = factor[3] * c[3];
  const double light = 0.2 + 0.8 * hit.cosine;
  const glm::dvec3 lit(factor[0] * c[0] * light, factor[1] * c[1] * light,
                       factor[2] * c[2] * light);
  if (alphaMode == "MASK") {
    if (std::abs(alpha - 0.5) < 0.03) return false;
    out = alpha >= 0.5 ? lit : background;
    return true;
  }
  if (alphaMode == "OPAQUE") alpha = 1.0;
  out = lit * alpha + background * (1.0 - alpha);
  return true;
}

/// Every pixel of a size x size `image` that expectedQuadPixel names against its expectation
/// (expectLinearPixel). Returns the pixels compared.
inline int expectQuadColors(const ImageRGB& image, const Camera& camera, int size, const Rgba& left,
                            const Rgba& right, const Rgba& factor, const std::string& alphaMode,
                            const glm::dvec3& background) {
  int compared = 0, wrong = 0;
  for (int py = 0; py < size; ++py)
    for (int px = 0; px < size; ++px) {
      glm::dvec3 e;
      if (!expectedQuadPixel(camera, px, py, size, size, left, right, factor, alphaMode, background,
                             e))
        continue;
      ++compared;
      expectLinearPixel(image.at(px, py), e, px, py, wrong);
    }
  EXPECT_EQ(wrong, 0) << "of " << compared << " pixels";
  return compared;
}

/// A glTF material: factor, alpha mode, double-sided (cutoff 0.5 for MASK).
inline nlohmann::json vertexColorMaterial(const Rgba& factor, const std::string& alphaMode) {
  nlohmann::json m = {{"pbrMetallicRoughness", {{"baseColorFactor", factor}}},
                      {"alphaMode", alphaMode},
                      {"doubleSided", true}};
  if (alphaMode == "MASK") m["alphaCutoff"] = 0.5;
  return m;
}

}  // namespace mfr::test
