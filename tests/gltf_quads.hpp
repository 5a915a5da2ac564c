// Writes tiny glTF 2.0 files for rendering tests: axis-aligned quads in planes z = const, facing
// +z (towards a camera on the +z axis; GltfQuad::reversed: facing -z), each with its own material,
// one embedded base64 buffer.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace mfr::test {

struct GltfQuad {
  float x0, y0, x1, y1;     // world-space rectangle
  float z;                  // plane
  nlohmann::json material;  // a glTF material object
  bool reversed = false;    // clockwise seen from +z: the quad shows its back face to +z
};

inline std::string base64Encode(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint32_t(uint8_t(bytes[i])) << 16) |
                       (uint32_t(uint8_t(bytes[i + 1])) << 8) | uint32_t(uint8_t(bytes[i + 2]));
    for (int s = 18; s >= 0; s -= 6) out += table[(v >> s) & 63];
  }
  if (i < bytes.size()) {
    uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

/// The glTF text of `quads`, in order (quad i is mesh primitive i, so primitive order = list
/// order). Positions, +z normals and 16-bit indices share one buffer.
/// A glTF document's "buffers": the one buffer `bin`, embedded as a base64 data URI.
inline nlohmann::json gltfEmbeddedBuffer(const std::string& bin) {
  return nlohmann::json::array(
      {{{"byteLength", bin.size()},
        {"uri", "data:application/octet-stream;base64," + base64Encode(bin)}}});
}

inline std::string gltfWithQuads(const std::vector<GltfQuad>& quads) {
  using nlohmann::json;
  std::string bin;
  json accessors = json::array(), views = json::array(), primitives = json::array(),
       materials = json::array();
  auto append = [&](const void* data, size_t size) {
    while (bin.size() % 4 != 0) bin += '\0';
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}});
    bin.append(static_cast<const char*>(data), size);
    return views.size() - 1;
  };
  for (const GltfQuad& q : quads) {
    const float positions[12] = {q.x0, q.y0, q.z, q.x1, q.y0, q.z,
                                 q.x1, q.y1, q.z, q.x0, q.y1, q.z};
    const float nz = q.reversed ? -1.0f : 1.0f;
    const float normals[12] = {0, 0, nz, 0, 0, nz, 0, 0, nz, 0, 0, nz};
    const uint16_t forward[6] = {0, 1, 2, 0, 2, 3}, backward[6] = {0, 2, 1, 0, 3, 2};
    const uint16_t* indices = q.reversed ? backward : forward;
    accessors.push_back({{"bufferView", append(positions, sizeof positions)},
                         {"componentType", 5126},
                         {"count", 4},
                         {"type", "VEC3"},
                         {"min", {q.x0, q.y0, q.z}},
                         {"max", {q.x1, q.y1, q.z}}});
    const size_t position = accessors.size() - 1;
    accessors.push_back({{"bufferView", append(normals, sizeof normals)},
                         {"componentType", 5126},
                         {"count", 4},
                         {"type", "VEC3"}});
    const size_t normal = accessors.size() - 1;
    accessors.push_back({{"bufferView", append(indices, sizeof forward)},
                         {"componentType", 5123},
                         {"count", 6},
                         {"type", "SCALAR"}});
    const size_t index = accessors.size() - 1;
    materials.push_back(q.material);
    primitives.push_back({{"attributes", {{"POSITION", position}, {"NORMAL", normal}}},
                          {"indices", index},
                          {"material", materials.size() - 1}});
  }
  json doc;
  doc["asset"] = {{"version", "2.0"}};
  doc["scene"] = 0;
  doc["scenes"] = json::array({{{"nodes", {0}}}});
  doc["nodes"] = json::array({{{"mesh", 0}}});
  doc["meshes"] = json::array({{{"primitives", primitives}}});
  doc["materials"] = materials;
  doc["accessors"] = accessors;
  doc["bufferViews"] = views;
  doc["buffers"] = gltfEmbeddedBuffer(bin);
  for (const GltfQuad& q : quads)
    if (q.material.contains("extensions") &&
        q.material["extensions"].contains("KHR_materials_transmission")) {
      doc["extensionsUsed"] = {"KHR_materials_transmission"};
      break;
    }
  return doc.dump();
}

/// A glTF material: base colour factor (linear RGBA) and alpha mode ("OPAQUE", "MASK", "BLEND").
inline nlohmann::json gltfMaterial(const std::vector<double>& rgba, const std::string& alphaMode) {
  return {{"pbrMetallicRoughness", {{"baseColorFactor", rgba}}}, {"alphaMode", alphaMode}};
}

}  // namespace mfr::test
