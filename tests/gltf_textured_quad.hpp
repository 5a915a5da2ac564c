// A tiny glTF 2.0 file for the sampler tests: one quad x, y in [-1, 1] (z = 0, facing +z) whose
// texture coordinates run outside [0, 1] (u = -1.5 at x = -1 to 2.5 at x = 1; v = -1.5 at the top,
// y = 1, to 2.5 at the bottom), textured with a 4x2 RGBA8 image of eight distinct colours, the
// texture's sampler given (or none). The image is an embedded PNG (mfr::writePng).
#pragma once

#include <unistd.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "gltf_quads.hpp"
#include "mfr/core/image.hpp"

namespace mfr::test {

inline constexpr int kQuadTextureWidth = 4;
inline constexpr int kQuadTextureHeight = 2;
/// sRGB8 texels, rows top to bottom: red, green, blue, white; yellow, cyan, magenta, black (0 and
/// 255 only, so each channel decodes to exactly 0 or 1).
inline constexpr std::array<std::array<uint8_t, 3>, 8> kQuadTexels = {{{255, 0, 0},
                                                                       {0, 255, 0},
                                                                       {0, 0, 255},
                                                                       {255, 255, 255},
                                                                       {255, 255, 0},
                                                                       {0, 255, 255},
                                                                       {255, 0, 255},
                                                                       {0, 0, 0}}};

/// u, v of a point (x, y) of the quad.
inline double quadU(double x) {
  return -1.5 + 2.0 * (x + 1.0);
}
inline double quadV(double y) {
  return -1.5 + 2.0 * (1.0 - y);
}

/// The glTF text; `sampler` null: the texture names no sampler (glTF defaults).
inline std::string texturedQuadGltf(const nlohmann::json* sampler) {
  using nlohmann::json;
  Image8 image;
  image.width = kQuadTextureWidth;
  image.height = kQuadTextureHeight;
  for (const auto& t : kQuadTexels) image.rgba.insert(image.rgba.end(), {t[0], t[1], t[2], 255});
  const std::filesystem::path png = std::filesystem::temp_directory_path() /
                                    ("mfr_sampler_quad_" + std::to_string(::getpid()) + ".png");
  if (!writePng(png.string(), image).ok()) return {};
  std::ifstream in(png, std::ios::binary);
  const std::string pngBytes((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  std::filesystem::remove(png);

  const float positions[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const float normals[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  float uvs[8];
  for (int i = 0; i < 4; ++i) {
    uvs[2 * i] = static_cast<float>(quadU(positions[3 * i]));
    uvs[2 * i + 1] = static_cast<float>(quadV(positions[3 * i + 1]));
  }
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  std::string bin;
  json views = json::array();
  auto append = [&](const void* data, size_t size) {
    while (bin.size() % 4 != 0) bin += '\0';
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}});
    bin.append(static_cast<const char*>(data), size);
    return views.size() - 1;
  };
  json accessors = json::array({{{"bufferView", append(positions, sizeof positions)},
                                 {"componentType", 5126},
                                 {"count", 4},
                                 {"type", "VEC3"},
                                 {"min", {-1, -1, 0}},
                                 {"max", {1, 1, 0}}},
                                {{"bufferView", append(normals, sizeof normals)},
                                 {"componentType", 5126},
                                 {"count", 4},
                                 {"type", "VEC3"}},
                                {{"bufferView", append(uvs, sizeof uvs)},
                                 {"componentType", 5126},
                                 {"count", 4},
                                 {"type", "VEC2"}},
                                {{"bufferView", append(indices, sizeof indices)},
                                 {"componentType", 5123},
                                 {"count", 6},
                                 {"type", "SCALAR"}}});
  json doc;
  doc["asset"] = {{"version", "2.0"}};
  doc["scene"] = 0;
  doc["scenes"] = json::array({{{"nodes", {0}}}});
  doc["nodes"] = json::array({{{"mesh", 0}}});
  doc["meshes"] = json::array(
      {{{"primitives",
         json::array({{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}},
                       {"indices", 3},
                       {"material", 0}}})}}});
  doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}},
                                   {"alphaMode", "OPAQUE"}}});
  doc["images"] = json::array({{{"uri", "data:image/png;base64," + base64Encode(pngBytes)}}});
  json texture = {{"source", 0}};
  if (sampler) {
    texture["sampler"] = 0;
    doc["samplers"] = json::array({*sampler});
  }
  doc["textures"] = json::array({texture});
  doc["accessors"] = accessors;
  doc["bufferViews"] = views;
  doc["buffers"] = gltfEmbeddedBuffer(bin);
  return doc.dump();
}

}  // namespace mfr::test
