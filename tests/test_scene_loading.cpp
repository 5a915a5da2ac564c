// Scene loading (include/mfr/scene/load.hpp): glTF, OBJ + MTL, PLY and JSON scene files written by
// the tests into a temporary directory, bad inputs, and the real scenes of ../shared/scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mfr/scene/load.hpp"
#include "mfr/scene/procedural.hpp"
#include "shared_scenes.hpp"
#include "temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// ---------------------------------------------------------------------------------------------
// Test helpers: temporary files, base64, a minimal PNG encoder and a glTF document builder.

/// This file's scratch folders (temp_dir.hpp).
class TempDir : public mfr::test::TempDir {
 public:
  TempDir() : mfr::test::TempDir("mfr_scene_loading") {}
};

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v =
        (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += table[(v >> s) & 63];
  }
  if (i < bytes.size()) {
    uint32_t v = uint8_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= uint8_t(bytes[i + 1]) << 8;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

template <typename T>
std::string bytesOf(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

void putBigEndian32(std::string& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out += static_cast<char>((v >> s) & 0xFF);
}

uint32_t crc32(const std::string& data) {
  uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char c : data) {
    crc ^= c;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

/// Uncompressed (stored-deflate) PNG. `samples` are the channel values in row order; 16-bit
/// samples are written big-endian as PNG requires. colorType: 0 grey, 2 RGB, 4 grey+alpha, 6 RGBA.
std::string encodePng(int width, int height, int colorType, int bitDepth,
                      const std::vector<uint16_t>& samples) {
  const int channels = colorType == 0 ? 1 : colorType == 2 ? 3 : colorType == 4 ? 2 : 4;
  std::string raw;
  for (int y = 0; y < height; ++y) {
    raw += '\0';  // filter: none
    for (int i = 0; i < width * channels; ++i) {
      const uint16_t v = samples[static_cast<size_t>(y * width * channels + i)];
      if (bitDepth == 16) raw += static_cast<char>(v >> 8);
      raw += static_cast<char>(v & 0xFF);
    }
  }
  std::string zlib = "\x78\x01";
  for (size_t offset = 0; offset < raw.size() || offset == 0; offset += 65535) {
    const size_t length = std::min<size_t>(65535, raw.size() - offset);
    zlib += static_cast<char>(offset + length >= raw.size() ? 1 : 0);
    zlib += static_cast<char>(length & 0xFF);
    zlib += static_cast<char>(length >> 8);
    zlib += static_cast<char>(~length & 0xFF);
    zlib += static_cast<char>((~length >> 8) & 0xFF);
    zlib += raw.substr(offset, length);
    if (raw.empty()) break;
  }
  uint32_t a = 1, b = 0;
  for (unsigned char c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  putBigEndian32(zlib, (b << 16) | a);

  std::string png = "\x89PNG\r\n\x1a\n";
  auto chunk = [&](const std::string& type, const std::string& data) {
    putBigEndian32(png, static_cast<uint32_t>(data.size()));
    png += type + data;
    putBigEndian32(png, crc32(type + data));
  };
  std::string header;
  putBigEndian32(header, static_cast<uint32_t>(width));
  putBigEndian32(header, static_cast<uint32_t>(height));
  header += static_cast<char>(bitDepth);
  header += static_cast<char>(colorType);
  header += std::string(3, '\0');
  chunk("IHDR", header);
  chunk("IDAT", zlib);
  chunk("IEND", "");
  return png;
}

/// Builds a glTF 2.0 document with one binary buffer, written as .gltf (data URI) or .glb.
class GltfDoc {
 public:
  GltfDoc() {
    doc["asset"] = {{"version", "2.0"}};
    doc["scene"] = 0;
    doc["scenes"] = json::array({json{{"nodes", json::array()}}});
    doc["nodes"] = json::array();
    doc["meshes"] = json::array();
    doc["accessors"] = json::array();
    doc["bufferViews"] = json::array();
  }

  int addView(const std::string& bytes) {
    while (bin.size() % 4 != 0) bin += '\0';
    doc["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes.size()}});
    bin += bytes;
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  int addAccessor(const std::string& bytes, int componentType, size_t count, const char* type,
                  bool normalized = false) {
    json accessor = {{"bufferView", addView(bytes)},
                     {"componentType", componentType},
                     {"count", count},
                     {"type", type}};
    if (normalized) accessor["normalized"] = true;
    doc["accessors"].push_back(accessor);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  int addPositions(const std::vector<float>& xyz) {
    const int index = addAccessor(bytesOf(xyz), 5126, xyz.size() / 3, "VEC3");
    // min/max are required for POSITION by the spec (tinygltf does not insist).
    std::array<float, 3> lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
    for (size_t i = 0; i < xyz.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], xyz[i]);
      hi[i % 3] = std::max(hi[i % 3], xyz[i]);
    }
    doc["accessors"][static_cast<size_t>(index)]["min"] = lo;
    doc["accessors"][static_cast<size_t>(index)]["max"] = hi;
    return index;
  }
  int addIndices(const std::vector<uint16_t>& indices) {
    return addAccessor(bytesOf(indices), 5123, indices.size(), "SCALAR");
  }
  int addMesh(const json& primitives) {
    doc["meshes"].push_back({{"primitives", primitives}});
    return static_cast<int>(doc["meshes"].size()) - 1;
  }
  int addNode(json node, bool root = true) {
    doc["nodes"].push_back(std::move(node));
    const int index = static_cast<int>(doc["nodes"].size()) - 1;
    if (root) doc["scenes"][0]["nodes"].push_back(index);
    return index;
  }
  int addMaterial(json material) {
    doc["materials"].push_back(std::move(material));
    return static_cast<int>(doc["materials"].size()) - 1;
  }

  std::string gltfText() const {
    json out = doc;
    if (!bin.empty())
      out["buffers"] =
          json::array({{{"byteLength", bin.size()},
                        {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    return out.dump();
  }
  std::string glbBytes() const {
    json out = doc;
    out["buffers"] = json::array({{{"byteLength", bin.size()}}});
    std::string text = out.dump();
    while (text.size() % 4 != 0) text += ' ';
    std::string data = bin;
    while (data.size() % 4 != 0) data += '\0';
    std::string glb = "glTF";
    auto put32 = [&](uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
    put32(2);
    put32(static_cast<uint32_t>(12 + 8 + text.size() + 8 + data.size()));
    put32(static_cast<uint32_t>(text.size()));
    put32(0x4E4F534A);  // JSON
    glb += text;
    put32(static_cast<uint32_t>(data.size()));
    put32(0x004E4942);  // BIN
    glb += data;
    return glb;
  }

  json doc;
  std::string bin;
};

/// A unit quad in the z = 0 plane facing +z: 4 vertices, 2 triangles, normals and uvs.
json quadPrimitive(GltfDoc& gltf, int material = -1) {
  json primitive = {
      {"attributes",
       {{"POSITION", gltf.addPositions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0})},
        {"NORMAL", gltf.addAccessor(bytesOf(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}),
                                    5126, 4, "VEC3")},
        {"TEXCOORD_0",
         gltf.addAccessor(bytesOf(std::vector<float>{0, 1, 1, 1, 1, 0, 0, 0}), 5126, 4, "VEC2")}}},
      {"indices", gltf.addIndices({0, 1, 2, 0, 2, 3})}};
  if (material >= 0) primitive["material"] = material;
  return primitive;
}

glm::vec3 faceNormal(const mfr::Scene& scene, size_t triangle) {
  const glm::vec3 a = scene.positions[scene.indices[3 * triangle]];
  const glm::vec3 b = scene.positions[scene.indices[3 * triangle + 1]];
  const glm::vec3 c = scene.positions[scene.indices[3 * triangle + 2]];
  return glm::normalize(glm::cross(b - a, c - a));
}

::testing::AssertionResult isErrorNaming(const mfr::Result<mfr::Scene>& result,
                                         const std::string& path, const std::string& text = "") {
  if (result.ok()) return ::testing::AssertionFailure() << "loaded, expected an error";
  const std::string& message = result.error().message;
  if (message.find(path) == std::string::npos)
    return ::testing::AssertionFailure() << "message '" << message << "' does not name " << path;
  if (message.find(text) == std::string::npos)
    return ::testing::AssertionFailure() << "message '" << message << "' lacks '" << text << "'";
  if (message.find('\n') != std::string::npos)
    return ::testing::AssertionFailure() << "message '" << message << "' is not one line";
  return ::testing::AssertionSuccess();
}

#define ASSERT_LOADED(result) ASSERT_TRUE((result).ok()) << (result).error().message

class SceneLoading : public ::testing::Test {
 protected:
  TempDir dir;
};

// ---------------------------------------------------------------------------------------------
// glTF

TEST_F(SceneLoading, GltfQuadLoadsVerticesTrianglesNormalsAndUvs) {
  GltfDoc gltf;
  gltf.addNode({{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf)}))}});
  const std::string path = dir.write("quad.gltf", gltf.gltfText());
  auto scene = mfr::loadScene(path);
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->name, path);
  EXPECT_EQ(scene->vertexCount(), 4u);
  EXPECT_EQ(scene->triangleCount(), 2u);
  ASSERT_EQ(scene->uvs.size(), 4u);
  EXPECT_EQ(scene->uvs[0], glm::vec2(0, 1));
  for (const glm::vec3& n : scene->normals) EXPECT_EQ(n, glm::vec3(0, 0, 1));
  EXPECT_GT(faceNormal(*scene, 0).z, 0.99f);
}

TEST_F(SceneLoading, GltfNodeTranslationRotationScaleAndMatrixAreApplied) {
  GltfDoc gltf;
  const int mesh = gltf.addMesh(json::array({quadPrimitive(gltf)}));
  // Parent scales by 2 and translates by (10, 0, 0); the child rotates 90 degrees about +y.
  const float s = std::sqrt(0.5f);
  const int child = gltf.addNode({{"mesh", mesh}, {"rotation", {0, s, 0, s}}}, false);
  gltf.addNode({{"children", {child}}, {"translation", {10, 0, 0}}, {"scale", {2, 2, 2}}});
  // A second instance placed with a column-major matrix: translation (0, 5, 0).
  gltf.addNode({{"mesh", mesh}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 5, 0, 1}}});
  auto scene = mfr::loadScene(dir.write("nodes.gltf", gltf.gltfText()));
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->vertexCount(), 8u);
  EXPECT_EQ(scene->triangleCount(), 4u);
  // First instance: x' = 10 + 2 * z, z' = -2 * x  (rotation +90 about y maps +x to -z).
  const glm::vec3 p1 = scene->positions[1];  // source (1, 0, 0)
  EXPECT_NEAR(p1.x, 10.0f, 1e-5f);
  EXPECT_NEAR(p1.y, 0.0f, 1e-5f);
  EXPECT_NEAR(p1.z, -2.0f, 1e-5f);
  // Normals follow the rotation: +z becomes +x.
  EXPECT_NEAR(scene->normals[0].x, 1.0f, 1e-5f);
  // Second instance: moved up by 5.
  EXPECT_NEAR(scene->positions[4 + 2].y, 6.0f, 1e-5f);  // source (1, 1, 0)
}

TEST_F(SceneLoading, GltfMirroringNodeKeepsTrianglesFrontFacing) {
  GltfDoc gltf;
  gltf.addNode({{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf)}))}, {"scale", {-1, 1, 1}}});
  auto scene = mfr::loadScene(dir.write("mirror.gltf", gltf.gltfText()));
  ASSERT_LOADED(scene);
  EXPECT_NEAR(scene->positions[1].x, -1.0f, 1e-6f);
  // The winding is flipped with the geometry, so faces still agree with their normals.
  EXPECT_GT(glm::dot(faceNormal(*scene, 0), scene->normals[scene->indices[0]]), 0.99f);
}

TEST_F(SceneLoading, GltfAlphaModesCutoffAndBaseColorFactorAreRead) {
  GltfDoc gltf;
  const int opaque = gltf.addMaterial({{"name", "opaque"}});
  const int mask =
      gltf.addMaterial({{"name", "mask"}, {"alphaMode", "MASK"}, {"alphaCutoff", 0.3}});
  const int maskDefault = gltf.addMaterial({{"name", "maskDefault"}, {"alphaMode", "MASK"}});
  const int blend =
      gltf.addMaterial({{"name", "blend"},
                        {"alphaMode", "BLEND"},
                        {"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.4, 0.6, 0.5}}}}});
  gltf.addNode({{"mesh", gltf.addMesh(json::array(
                             {quadPrimitive(gltf, opaque), quadPrimitive(gltf, mask),
                              quadPrimitive(gltf, maskDefault), quadPrimitive(gltf, blend)}))}});
  auto scene = mfr::loadScene(dir.write("alpha.gltf", gltf.gltfText()));
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->triangleCount(), 8u);
  auto materialOf = [&](size_t triangle) {
    return scene->materials[scene->triangleMaterial[triangle]];
  };
  EXPECT_EQ(materialOf(0).name, "opaque");
  EXPECT_EQ(materialOf(0).alphaMode, mfr::AlphaMode::Opaque);
  EXPECT_EQ(materialOf(2).alphaMode, mfr::AlphaMode::Mask);
  EXPECT_FLOAT_EQ(materialOf(2).alphaCutoff, 0.3f);
  EXPECT_EQ(materialOf(4).alphaMode, mfr::AlphaMode::Mask);
  EXPECT_FLOAT_EQ(materialOf(4).alphaCutoff, 0.5f);
  EXPECT_EQ(materialOf(6).alphaMode, mfr::AlphaMode::Blend);
  EXPECT_EQ(materialOf(6).baseColor, glm::vec4(0.2f, 0.4f, 0.6f, 0.5f));
  EXPECT_FALSE(materialOf(6).transmission.has_value());
}

TEST_F(SceneLoading, GltfTransmissionBecomesBlendAlphaWithFloor) {
  GltfDoc gltf;
  auto transmissive = [](double factor, double alpha) {
    return json{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, alpha}}}},
                {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", factor}}}}}};
  };
  const int clear = gltf.addMaterial(transmissive(1.0, 1.0));
  const int partial = gltf.addMaterial(transmissive(0.4, 0.5));
  const int noFactor = gltf.addMaterial(
      {{"alphaMode", "MASK"}, {"extensions", {{"KHR_materials_transmission", json::object()}}}});
  gltf.addNode(
      {{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf, clear), quadPrimitive(gltf, partial),
                                          quadPrimitive(gltf, noFactor)}))}});
  const std::string path = dir.write("transmission.gltf", gltf.gltfText());

  auto scene = mfr::loadScene(path);
  ASSERT_LOADED(scene);
  const auto& clearMaterial = scene->materials[scene->triangleMaterial[0]];
  EXPECT_EQ(clearMaterial.alphaMode, mfr::AlphaMode::Blend);
  EXPECT_FLOAT_EQ(*clearMaterial.transmission, 1.0f);
  EXPECT_FLOAT_EQ(clearMaterial.baseColor.a, 0.1f);  // default floor
  const auto& partialMaterial = scene->materials[scene->triangleMaterial[2]];
  EXPECT_FLOAT_EQ(*partialMaterial.transmission, 0.4f);
  EXPECT_FLOAT_EQ(partialMaterial.baseColor.a, 0.6f * 0.5f);
  const auto& noFactorMaterial = scene->materials[scene->triangleMaterial[4]];
  EXPECT_FLOAT_EQ(*noFactorMaterial.transmission, 0.0f);
  EXPECT_FLOAT_EQ(noFactorMaterial.baseColor.a, 1.0f);
  EXPECT_EQ(noFactorMaterial.alphaMode, mfr::AlphaMode::Blend);

  mfr::LoadOptions options;
  options.transmissionAlphaFloor = 0.25f;
  auto floored = mfr::loadScene(path, options);
  ASSERT_LOADED(floored);
  EXPECT_FLOAT_EQ(floored->materials[floored->triangleMaterial[0]].baseColor.a, 0.25f);
}

TEST_F(SceneLoading, GltfPrimitiveWithoutOrWithInvalidMaterialGetsOpaqueWhiteDefault) {
  GltfDoc gltf;
  gltf.addNode(
      {{"mesh", gltf.addMesh(json::array(
                    {quadPrimitive(gltf), quadPrimitive(gltf, 7 /* no such material */)}))}});
  auto scene = mfr::loadScene(dir.write("default.gltf", gltf.gltfText()));
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->materials.size(), 1u);
  EXPECT_EQ(scene->materials[0].alphaMode, mfr::AlphaMode::Opaque);
  EXPECT_EQ(scene->materials[0].baseColor, glm::vec4(1.0f));
  EXPECT_EQ(scene->materials[0].baseColorTexture, -1);
}

TEST_F(SceneLoading, GltfQuantizedNormalizedNonIndexedAndSparseAccessorsAreDecoded) {
  GltfDoc gltf;
  // KHR_mesh_quantization style: SHORT positions (not normalized), normalized BYTE normals,
  // normalized UNSIGNED_BYTE texture coordinates, no indices.
  const int positions = gltf.addAccessor(
      bytesOf(std::vector<int16_t>{0, 0, 0, 0, 4, 0, 0, 0, 0, -3, 0, 0, 0, 0, 0, 0}), 5122, 3,
      "VEC3");
  gltf.doc["bufferViews"][gltf.doc["accessors"][static_cast<size_t>(positions)]["bufferView"]
                              .get<size_t>()]["byteStride"] =
      8;  // padded to 4-byte aligned elements (xyz + 1 unused short)
  const int normals =
      gltf.addAccessor(bytesOf(std::vector<int8_t>{0, 0, 127, 0, 0, 0, -128, 0, 0, 0, 127, 0}),
                       5120, 3, "VEC3", true);
  gltf.doc["bufferViews"][gltf.doc["accessors"][static_cast<size_t>(normals)]["bufferView"]
                              .get<size_t>()]["byteStride"] = 4;
  const int uvs = gltf.addAccessor(bytesOf(std::vector<uint8_t>{0, 255, 255, 0, 51, 102}), 5121, 3,
                                   "VEC2", true);
  gltf.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  gltf.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  // A sparse accessor: positions of a second triangle = base with vertex 2 replaced.
  const int sparseIndices = gltf.addView(bytesOf(std::vector<uint8_t>{2, 0, 0, 0}));
  const int sparseValues = gltf.addView(bytesOf(std::vector<float>{7, 8, 9}));
  const int base =
      gltf.addAccessor(bytesOf(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), 5126, 3, "VEC3");
  gltf.doc["accessors"][static_cast<size_t>(base)]["sparse"] = {
      {"count", 1},
      {"indices", {{"bufferView", sparseIndices}, {"componentType", 5121}}},
      {"values", {{"bufferView", sparseValues}}}};
  gltf.addNode(
      {{"mesh",
        gltf.addMesh(json::array(
            {{{"attributes", {{"POSITION", positions}, {"NORMAL", normals}, {"TEXCOORD_0", uvs}}}},
             {{"attributes", {{"POSITION", base}}}}}))}});
  auto scene = mfr::loadScene(dir.write("quantized.gltf", gltf.gltfText()));
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->vertexCount(), 6u);
  EXPECT_EQ(scene->triangleCount(), 2u);
  EXPECT_EQ(scene->positions[1], glm::vec3(4, 0, 0));
  EXPECT_EQ(scene->positions[2], glm::vec3(0, -3, 0));
  EXPECT_NEAR(scene->normals[0].z, 1.0f, 1e-6f);
  EXPECT_NEAR(scene->normals[1].z, -1.0f, 1e-6f);  // -128 clamps to -1
  EXPECT_NEAR(scene->uvs[0].y, 1.0f, 1e-6f);
  EXPECT_NEAR(scene->uvs[2].x, 0.2f, 1e-6f);
  EXPECT_NEAR(scene->uvs[2].y, 0.4f, 1e-6f);
  EXPECT_EQ(scene->positions[3 + 1], glm::vec3(1, 0, 0));
  EXPECT_EQ(scene->positions[3 + 2], glm::vec3(7, 8, 9));  // sparse substitution
  EXPECT_EQ(scene->uvs[3], glm::vec2(0.0f));               // no TEXCOORD_0: zeros
}

TEST_F(SceneLoading, GltfStripsAndFansAreTriangulatedAndPointsAndLinesSkipped) {
  GltfDoc gltf;
  // Five vertices on a convex arc; strip -> 3 triangles, fan -> 3 triangles.
  const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0};
  json primitives = json::array();
  for (int mode : {0, 1, 3, 4, 5, 6})
    primitives.push_back({{"attributes", {{"POSITION", gltf.addPositions(xyz)}}}, {"mode", mode}});
  gltf.addNode({{"mesh", gltf.addMesh(primitives)}});
  auto scene = mfr::loadScene(dir.write("modes.gltf", gltf.gltfText()));
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->triangleCount(), 1u + 3u + 3u);  // triangles (5 -> 1), strip, fan
  // Strip triangles alternate winding so they all face the same way.
  for (size_t t = 1; t < 4; ++t) EXPECT_GT(faceNormal(*scene, t).z, 0.0f) << "strip triangle " << t;
}

TEST_F(SceneLoading, GltfBaseColorTexturesOfAnyChannelCountAndDepthBecomeRgba8) {
  GltfDoc gltf;
  struct Case {
    int colorType, bitDepth;
    std::vector<uint16_t> samples;  // one pixel
    std::array<uint8_t, 4> expected;
  };
  const std::vector<Case> cases = {{0, 8, {100}, {100, 100, 100, 255}},
                                   {4, 8, {50, 60}, {50, 50, 50, 60}},
                                   {2, 8, {1, 2, 3}, {1, 2, 3, 255}},
                                   {6, 8, {1, 2, 3, 4}, {1, 2, 3, 4}},
                                   {6, 16, {65535, 0, 32896, 257 * 7}, {255, 0, 128, 7}}};
  json primitives = json::array();
  for (const Case& c : cases) {
    gltf.doc["images"].push_back(
        {{"uri",
          "data:image/png;base64," + base64(encodePng(1, 1, c.colorType, c.bitDepth, c.samples))}});
    gltf.doc["textures"].push_back({{"source", gltf.doc["images"].size() - 1}});
    const int material =
        gltf.addMaterial({{"pbrMetallicRoughness",
                           {{"baseColorTexture", {{"index", gltf.doc["textures"].size() - 1}}}}}});
    primitives.push_back(quadPrimitive(gltf, material));
  }
  gltf.addNode({{"mesh", gltf.addMesh(primitives)}});
  auto scene = mfr::loadScene(dir.write("textures.gltf", gltf.gltfText()));
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->textures.size(), cases.size());
  for (size_t i = 0; i < cases.size(); ++i) {
    const mfr::Material& material = scene->materials[scene->triangleMaterial[2 * i]];
    ASSERT_GE(material.baseColorTexture, 0);
    const mfr::Texture& texture = scene->textures[static_cast<size_t>(material.baseColorTexture)];
    ASSERT_EQ(texture.width, 1);
    ASSERT_EQ(texture.height, 1);
    for (int k = 0; k < 4; ++k)
      EXPECT_EQ(texture.rgba[static_cast<size_t>(k)], cases[i].expected[static_cast<size_t>(k)])
          << "case " << i << " channel " << k;
  }
}

TEST_F(SceneLoading, GltfBinaryGlbLoadsLikeText) {
  GltfDoc gltf;
  gltf.addNode(
      {{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf)}))}, {"translation", {0, 0, 3}}});
  auto scene = mfr::loadScene(dir.write("quad.glb", gltf.glbBytes()));
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->triangleCount(), 2u);
  EXPECT_EQ(scene->positions[0], glm::vec3(0, 0, 3));
}

TEST_F(SceneLoading, GltfExternalBufferAndImageResolveRelativeToTheGltfFile) {
  GltfDoc gltf;
  gltf.doc["images"] = {{{"uri", "images/red.png"}}};
  gltf.doc["textures"] = {{{"source", 0}}};
  const int material =
      gltf.addMaterial({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  gltf.addNode({{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf, material)}))}});
  json doc = gltf.doc;
  doc["buffers"] = {{{"byteLength", gltf.bin.size()}, {"uri", "data/quad.bin"}}};
  dir.write("model/data/quad.bin", gltf.bin);
  dir.write("model/images/red.png", encodePng(2, 1, 2, 8, {255, 0, 0, 255, 0, 0}));
  auto scene = mfr::loadScene(dir.write("model/quad.gltf", doc.dump()));
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->triangleCount(), 2u);
  ASSERT_EQ(scene->textures.size(), 1u);
  EXPECT_EQ(scene->textures[0].width, 2);
  EXPECT_EQ(scene->textures[0].rgba[0], 255);
}

TEST_F(SceneLoading, GltfMissingBaseColorImageIsAnErrorNamingIt) {
  GltfDoc gltf;
  gltf.doc["images"] = {{{"uri", "missing.png"}}};
  gltf.doc["textures"] = {{{"source", 0}}};
  const int material =
      gltf.addMaterial({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  gltf.addNode({{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf, material)}))}});
  const std::string path = dir.write("missing_image.gltf", gltf.gltfText());
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "missing.png"));
}

TEST_F(SceneLoading, GltfCameraNodeGivesPerspectiveCamera) {
  GltfDoc gltf;
  gltf.addNode({{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf)}))}});
  gltf.doc["cameras"] = {
      {{"type", "perspective"},
       {"perspective", {{"yfov", 0.5}, {"znear", 0.25}, {"aspectRatio", 1.5}}}},
      {{"type", "orthographic"},
       {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}}};
  // Placed at (0.5, 0.5, 5) under a parent turned 180 degrees about y: ends up at
  // (-0.5, 0.5, -5) looking down +z, towards the quad.
  const int cameraNode = gltf.addNode({{"camera", 0}, {"translation", {0.5, 0.5, 5}}}, false);
  gltf.addNode({{"children", {cameraNode}}, {"rotation", {0, 1, 0, 0}}});
  gltf.addNode({{"camera", 1}});  // orthographic: listed, refused by --view (issue 49)
  auto scene = mfr::loadScene(dir.write("camera.gltf", gltf.gltfText()));
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->cameras.size(), 2u);
  ASSERT_EQ(scene->cameraProblems.size(), 2u);
  EXPECT_EQ(scene->cameraProblems[0], "");
  EXPECT_NE(scene->cameraProblems[1].find("orthographic"), std::string::npos);
  const mfr::Camera& camera = scene->cameras[0];
  EXPECT_NEAR(camera.eye.x, -0.5f, 1e-5f);
  EXPECT_NEAR(camera.eye.y, 0.5f, 1e-5f);
  EXPECT_NEAR(camera.eye.z, -5.0f, 1e-5f);
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  EXPECT_NEAR(forward.z, 1.0f, 1e-5f);
  EXPECT_NEAR(camera.target.z, 0.0f, 1e-5f);  // on the view axis, at the depth of the scene centre
  EXPECT_NEAR(camera.up.y, 1.0f, 1e-5f);
  EXPECT_NEAR(camera.fovYDegrees, 0.5f * 180.0f / 3.14159265f, 1e-3f);
  EXPECT_FLOAT_EQ(camera.zNear, 0.25f);
  EXPECT_FLOAT_EQ(camera.zFar, 0.0f);  // infinite projection: fitted later
}

// ---------------------------------------------------------------------------------------------
// OBJ

TEST_F(SceneLoading, ObjQuadIsTriangulatedWithFlippedTexcoordsAndComputedNormals) {
  const std::string path = dir.write("quad.obj",
                                     "# quad\n"
                                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                     "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                     "f 1/1 2/2 3/3 4/4\n");
  auto scene = mfr::loadScene(path);
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->vertexCount(), 4u);
  EXPECT_EQ(scene->triangleCount(), 2u);
  ASSERT_EQ(scene->uvs.size(), 4u);
  // OBJ v = 0 is the bottom image row; the scene's v = 0 is the top row.
  for (size_t i = 0; i < scene->vertexCount(); ++i) {
    const glm::vec3 p = scene->positions[i];
    EXPECT_EQ(scene->uvs[i], glm::vec2(p.x, 1.0f - p.y)) << "vertex " << i;
    EXPECT_NEAR(scene->normals[i].z, 1.0f, 1e-6f);
  }
  ASSERT_EQ(scene->materials.size(), 1u);  // no MTL: one default material
  EXPECT_EQ(scene->materials[0].alphaMode, mfr::AlphaMode::Opaque);
}

TEST_F(SceneLoading, ObjFileNormalsAreUsed) {
  const std::string path = dir.write("normals.obj",
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nvn 1 0 0\n"
                                     "f 1//1 2//2 3//1\n");
  auto scene = mfr::loadScene(path);
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->normals[0], glm::vec3(0, 0, 1));  // normalized
  EXPECT_EQ(scene->normals[1], glm::vec3(1, 0, 0));
  EXPECT_TRUE(scene->uvs.empty());
}

TEST_F(SceneLoading, ObjMaterialsTakeKdAndAlphaFromDissolveOrInvertedTr) {
  dir.write("materials.mtl",
            "newmtl solid\nKd 0.5 0.25 1\n"
            "newmtl half\nKd 1 1 1\nd 0.5\n"
            "newmtl tr\nKd 1 1 1\nTr 0.25\n"
            "newmtl both\nKd 1 1 1\nd 1\nTr 0.9\n");
  const std::string path = dir.write("materials.obj",
                                     "mtllib materials.mtl\n"
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                     "usemtl solid\nf 1 2 3\n"
                                     "usemtl half\nf 1 2 3\n"
                                     "usemtl tr\nf 1 2 3\n"
                                     "usemtl both\nf 1 2 3\n"
                                     "usemtl unknown\nf 1 2 3\n");
  auto scene = mfr::loadScene(path);
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->triangleCount(), 5u);
  auto materialOf = [&](size_t t) { return scene->materials[scene->triangleMaterial[t]]; };
  EXPECT_EQ(materialOf(0).baseColor, glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
  EXPECT_EQ(materialOf(0).alphaMode, mfr::AlphaMode::Opaque);
  EXPECT_FLOAT_EQ(materialOf(1).baseColor.a, 0.5f);
  EXPECT_EQ(materialOf(1).alphaMode, mfr::AlphaMode::Blend);
  EXPECT_FLOAT_EQ(materialOf(2).baseColor.a, 0.75f);  // Tr is transparency: alpha = 1 - Tr
  EXPECT_EQ(materialOf(2).alphaMode, mfr::AlphaMode::Blend);
  EXPECT_FLOAT_EQ(materialOf(3).baseColor.a, 1.0f);  // d wins over Tr
  EXPECT_EQ(materialOf(3).alphaMode, mfr::AlphaMode::Opaque);
  EXPECT_EQ(materialOf(4).name, "default");  // unknown material name
}

TEST_F(SceneLoading, ObjMapKdIsLoadedRelativeToItsMtlFile) {
  dir.write("assets/tex/checker.png", encodePng(2, 2, 6, 8,
                                                {255, 0, 0, 255, 0, 255, 0, 128,  //
                                                 0, 0, 255, 255, 9, 9, 9, 0}));
  dir.write("assets/look.mtl", "newmtl textured\nKd 1 1 1\nmap_Kd tex/checker.png\n");
  const std::string path = dir.write("mesh.obj",
                                     "mtllib assets/look.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                     "vt 0 0\nvt 1 0\nvt 0 1\nusemtl textured\nf 1/1 2/2 3/3\n");
  auto scene = mfr::loadScene(path);
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->textures.size(), 1u);
  EXPECT_EQ(scene->materials[0].baseColorTexture, 0);
  const mfr::Texture& texture = scene->textures[0];
  ASSERT_EQ(texture.width, 2);
  ASSERT_EQ(texture.height, 2);
  EXPECT_EQ(texture.rgba[4 + 1], 255);  // top row, second pixel: green
  EXPECT_EQ(texture.rgba[4 + 3], 128);
  EXPECT_EQ(texture.rgba[8 + 2], 255);  // second row, first pixel: blue
}

TEST_F(SceneLoading, ObjMissingTextureIsAnErrorNamingIt) {
  dir.write("missing_texture.mtl", "newmtl m\nmap_Kd nowhere.png\n");
  const std::string path = dir.write("missing_texture.obj",
                                     "mtllib missing_texture.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                     "usemtl m\nf 1 2 3\n");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "nowhere.png"));
}

TEST_F(SceneLoading, ObjMissingMtlFileFallsBackToOneDefaultMaterial) {
  const std::string path = dir.write("no_mtl.obj",
                                     "mtllib absent.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                     "usemtl whatever\nf 1 2 3\n");
  auto scene = mfr::loadScene(path);
  ASSERT_LOADED(scene);
  ASSERT_EQ(scene->materials.size(), 1u);
  EXPECT_EQ(scene->materials[0].baseColor, glm::vec4(1.0f));
}

// ---------------------------------------------------------------------------------------------
// PLY

// (its red vertex colours are the surface's: tests/test_vertex_color_formats.cpp)
TEST_F(SceneLoading, AsciiPlyLoadsWithQuadsTriangulatedAndOneOpaqueMaterial) {
  const std::string path = dir.write("quad.ply",
                                     "ply\nformat ascii 1.0\ncomment test\n"
                                     "element vertex 5\nproperty float x\nproperty float y\n"
                                     "property float z\nproperty uchar red\nproperty uchar green\n"
                                     "property uchar blue\n"
                                     "element face 2\nproperty list uchar int vertex_indices\n"
                                     "end_header\n"
                                     "0 0 0 255 0 0\n1 0 0 255 0 0\n1 1 0 255 0 0\n0 1 0 255 0 0\n"
                                     "2 2 0 255 0 0\n"
                                     "4 0 1 2 3\n3 1 4 2\n");
  auto scene = mfr::loadScene(path);
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->triangleCount(), 3u);
  EXPECT_EQ(scene->vertexCount(), 5u);  // identical vertices joined again
  ASSERT_EQ(scene->materials.size(), 1u);
  EXPECT_EQ(scene->materials[0].baseColor, glm::vec4(1.0f));  // white: the colours are red
  EXPECT_EQ(scene->materials[0].alphaMode, mfr::AlphaMode::Opaque);
  ASSERT_EQ(scene->colors.size(), 5u);
  for (const glm::vec4& c : scene->colors) EXPECT_EQ(c, glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  for (const glm::vec3& n : scene->normals) EXPECT_NEAR(n.z, 1.0f, 1e-5f);
}

std::string binaryPlyTriangle() {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nproperty float nx\nproperty float ny\n"
      "property float nz\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::vector<float> vertices = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  ply += bytesOf(vertices);
  ply += '\3';
  ply += bytesOf(std::vector<int32_t>{0, 1, 2});
  return ply;
}

TEST_F(SceneLoading, BinaryPlyLoadsWithItsNormals) {
  auto scene = mfr::loadScene(dir.write("triangle.ply", binaryPlyTriangle()));
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->triangleCount(), 1u);
  EXPECT_EQ(scene->vertexCount(), 3u);
  for (const glm::vec3& n : scene->normals) EXPECT_NEAR(n.y, 1.0f, 1e-6f);  // from the file
}

// ---------------------------------------------------------------------------------------------
// JSON scene files

std::string writeTransmissiveQuad(const TempDir& dir, const std::string& name) {
  GltfDoc gltf;
  const int material = gltf.addMaterial(
      {{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}}}});
  gltf.addNode({{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf, material)}))}});
  gltf.doc["cameras"] = {
      {{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}}};
  gltf.addNode({{"camera", 0}, {"translation", {0, 0, 4}}});
  return dir.write(name, gltf.gltfText());
}

TEST_F(SceneLoading, JsonSceneLoadsItsMeshRelativeToItselfAndAppliesOverrides) {
  writeTransmissiveQuad(dir, "meshes/quad.gltf");
  const std::string path = dir.write("scenes/view.json", R"({
    "mesh": "../meshes/quad.gltf",
    "cameras": [{"eye": [1, 2, 3], "target": [0, 0, 0], "fov": 30, "near": 0.5, "far": 50},
                {"eye": [0, 0, -3], "target": [0, 0, 0], "up": [1, 0, 0]}],
    "background": [0.1, 0.2, 0.3],
    "alpha": 0.4,
    "transmission_alpha_floor": 0.2
  })");
  // "../meshes" leaves the JSON file's folder: refused unless references outside are allowed
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "'mesh' ../meshes/quad.gltf"));
  mfr::LoadOptions options;
  options.allowOutsideReferences = true;
  auto scene = mfr::loadScene(path, options);
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->name, path);
  EXPECT_EQ(scene->triangleCount(), 2u);
  ASSERT_EQ(scene->cameras.size(), 2u);  // replace the file's camera
  EXPECT_EQ(scene->cameras[0].eye, glm::vec3(1, 2, 3));
  EXPECT_FLOAT_EQ(scene->cameras[0].fovYDegrees, 30.0f);
  EXPECT_FLOAT_EQ(scene->cameras[0].zNear, 0.5f);
  EXPECT_FLOAT_EQ(scene->cameras[0].zFar, 50.0f);
  EXPECT_EQ(scene->cameras[1].up, glm::vec3(1, 0, 0));
  EXPECT_FLOAT_EQ(scene->cameras[1].fovYDegrees, 45.0f);
  EXPECT_EQ(scene->background, glm::vec3(0.1f, 0.2f, 0.3f));
  ASSERT_TRUE(scene->alphaOverride.has_value());
  EXPECT_FLOAT_EQ(*scene->alphaOverride, 0.4f);
  EXPECT_FLOAT_EQ(scene->materials[0].baseColor.a, 0.2f);  // transmission floor from the JSON
}

TEST_F(SceneLoading, JsonSceneWithoutOverridesKeepsTheMeshFileCameras) {
  writeTransmissiveQuad(dir, "quad.gltf");
  auto scene = mfr::loadScene(dir.write("plain.json", R"({"mesh": "quad.gltf"})"));
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->cameras.size(), 1u);
  EXPECT_FALSE(scene->alphaOverride.has_value());
  EXPECT_FLOAT_EQ(scene->materials[0].baseColor.a, 0.1f);
}

TEST_F(SceneLoading, JsonSceneCanNameAProceduralScene) {
  const std::vector<std::string> names = mfr::proceduralSceneNames();
  ASSERT_FALSE(names.empty());
  auto scene = mfr::loadScene(
      dir.write("procedural.json", json{{"mesh", "procedural:" + names.front()}}.dump()));
  ASSERT_LOADED(scene);
  EXPECT_GT(scene->triangleCount(), 0u);
}

TEST_F(SceneLoading, JsonSceneWithWrongTypeOrOutOfRangeValueNamesTheKey) {
  writeTransmissiveQuad(dir, "quad.gltf");
  const std::string alpha = dir.write("alpha.json", R"({"mesh": "quad.gltf", "alpha": 1.5})");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(alpha), alpha, "'alpha'"));
  const std::string background =
      dir.write("bg.json", R"({"mesh": "quad.gltf", "background": "red"})");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(background), background, "'background'"));
  const std::string camera = dir.write(
      "camera.json", R"({"mesh": "quad.gltf", "cameras": [{"eye": [0, 0, 1], "zoom": 2}]})");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(camera), camera, "'cameras[0].zoom'"));
  const std::string nested = dir.write("nested.json", R"({"mesh": "other.json"})");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(nested), nested, "'mesh'"));
}

// ---------------------------------------------------------------------------------------------
// Bad input: every error is one line naming the file.

TEST_F(SceneLoading, MissingFileIsAnError) {
  const std::string path = dir.file("absent.gltf");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "no such file"));
}

TEST_F(SceneLoading, UnsupportedExtensionIsAnError) {
  const std::string path = dir.write("scene.xyz", "whatever");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "unsupported scene format '.xyz'"));
}

TEST_F(SceneLoading, ExtensionMatchingIsCaseInsensitive) {
  auto scene = mfr::loadScene(dir.write("TRIANGLE.PLY", binaryPlyTriangle()));
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->triangleCount(), 1u);
}

TEST_F(SceneLoading, MalformedGltfTruncatedJsonIsAnError) {
  GltfDoc gltf;
  gltf.addNode({{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf)}))}});
  const std::string text = gltf.gltfText();
  const std::string path = dir.write("truncated.gltf", text.substr(0, text.size() / 2));
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path));
}

TEST_F(SceneLoading, MalformedGltfBadAccessorIndexIsAnError) {
  GltfDoc gltf;
  gltf.addNode({{"mesh", gltf.addMesh(json::array({{{"attributes", {{"POSITION", 42}}}}}))}});
  gltf.addView("123456789012");  // a buffer, so only the accessor index is wrong
  const std::string path = dir.write("bad_accessor.gltf", gltf.gltfText());
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "accessor 42"));
}

TEST_F(SceneLoading, MalformedGltfAccessorBeyondItsBufferIsAnError) {
  GltfDoc gltf;
  const int positions = gltf.addPositions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  gltf.doc["accessors"][static_cast<size_t>(positions)]["count"] = 1000000;  // buffer holds 3
  gltf.addNode(
      {{"mesh", gltf.addMesh(json::array({{{"attributes", {{"POSITION", positions}}}}}))}});
  const std::string path = dir.write("overflow.gltf", gltf.gltfText());
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "past the end"));
}

TEST_F(SceneLoading, MalformedGltfIndexBeyondTheVerticesIsAnError) {
  GltfDoc gltf;
  json primitive = quadPrimitive(gltf);
  primitive["indices"] = gltf.addIndices({0, 1, 9});
  gltf.addNode({{"mesh", gltf.addMesh(json::array({primitive}))}});
  const std::string path = dir.write("bad_index.gltf", gltf.gltfText());
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "index 9"));
}

TEST_F(SceneLoading, MalformedGltfNodeCycleIsAnError) {
  GltfDoc gltf;
  const int mesh = gltf.addMesh(json::array({quadPrimitive(gltf)}));
  gltf.addNode({{"mesh", mesh}, {"children", {1}}});
  gltf.addNode({{"children", {0}}}, false);
  const std::string path = dir.write("cycle.gltf", gltf.gltfText());
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "node"));
}

TEST_F(SceneLoading, TruncatedGlbIsAnErrorAtEveryLength) {
  GltfDoc gltf;
  gltf.addNode({{"mesh", gltf.addMesh(json::array({quadPrimitive(gltf)}))}});
  const std::string glb = gltf.glbBytes();
  for (size_t length = 0; length < glb.size(); length += 5) {
    const std::string path =
        dir.write("truncated_" + std::to_string(length) + ".glb", glb.substr(0, length));
    EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path)) << "length " << length;
  }
}

TEST_F(SceneLoading, MalformedObjIsAnError) {
  const std::string path = dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path));
}

TEST_F(SceneLoading, ObjFaceReferencingMissingVertexIsAnError) {
  const std::string quad =
      dir.write("missing_vertex_quad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 9\n");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(quad), quad));
  const std::string path =
      dir.write("missing_vertex.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "vertex"));
}

TEST_F(SceneLoading, NanVertexInObjIsAnError) {
  const std::string path = dir.write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "NaN"));
}

TEST_F(SceneLoading, ObjWithOnlyVerticesHasNoTriangles) {
  const std::string path = dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "scene has no triangles"));
}

TEST_F(SceneLoading, MalformedPlyGarbageIsAnError) {
  const std::string path = dir.write("garbage.ply", "this is not a ply file\n\x01\x02\x03");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path));
}

TEST_F(SceneLoading, MalformedPlyTruncatedBinaryIsAnError) {
  const std::string ply = binaryPlyTriangle();
  const std::string path = dir.write("truncated.ply", ply.substr(0, ply.size() - 20));
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path));
}

TEST_F(SceneLoading, PlyFaceIndexBeyondTheVerticesIsAnError) {
  std::string ply = binaryPlyTriangle();
  const int32_t bad = 3;  // only vertices 0..2 exist
  std::memcpy(ply.data() + ply.size() - 4, &bad, 4);
  const std::string path = dir.write("bad_index.ply", ply);
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "index 3"));
}

TEST_F(SceneLoading, PlyWithHugeElementCountFailsFast) {
  const std::string path = dir.write("huge_count.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                     "property float y\nproperty float z\nelement face 487683372\n"
                                     "property list uchar int vertex_indices\nend_header\n"
                                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "truncated"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

TEST_F(SceneLoading, JsonWithUnknownKeyIsAnError) {
  writeTransmissiveQuad(dir, "quad.gltf");
  const std::string path =
      dir.write("unknown.json", R"({"mesh": "quad.gltf", "colour": [1, 0, 0]})");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "'colour'"));
}

TEST_F(SceneLoading, JsonWithoutMeshIsAnError) {
  const std::string path = dir.write("no_mesh.json", R"({"alpha": 0.5})");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "'mesh'"));
}

TEST_F(SceneLoading, JsonSyntaxErrorIsAnError) {
  const std::string path = dir.write("syntax.json", R"({"mesh": )");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "JSON error"));
}

TEST_F(SceneLoading, JsonWhoseMeshFailsToLoadNamesBothFiles) {
  const std::string path = dir.write("dangling.json", R"({"mesh": "nothing.obj"})");
  EXPECT_TRUE(isErrorNaming(mfr::loadScene(path), path, "nothing.obj: no such file"));
}

// ---------------------------------------------------------------------------------------------
// Real scenes (../shared/scenes/README.md): triangle counts as listed there.

struct RealScene {
  const char* name;
  const char* file;
  size_t triangles;
};

const RealScene kRealScenes[] = {
    {"IridescentDishWithOlives",
     "khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf", 24448},
    {"StainedGlassLamp", "khronos/StainedGlassLamp/glTF-JPG-PNG/StainedGlassLamp.gltf", 35132},
    {"GlassVaseFlowers", "khronos/GlassVaseFlowers/glTF-Binary/GlassVaseFlowers.glb", 14036},
    {"TransmissionTest", "khronos/TransmissionTest/glTF-Binary/TransmissionTest.glb", 128775},
    {"AlphaBlendModeTest", "khronos/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb", 61},
    {"StanfordBunny", "stanford/bunny/bun_zipper.ply", 69451},
    {"StanfordBunnyRes2", "stanford/bunny/bun_zipper_res2.ply", 16301},
    {"StanfordDragon", "stanford/dragon/dragon_100k.ply", 100000},
};

// gtest prints a failing parameter with this (not as raw bytes)
void PrintTo(const RealScene& scene, std::ostream* os) {
  *os << scene.name << " (" << scene.file << ")";
}

class ReadmeScene : public ::testing::TestWithParam<RealScene> {};

TEST_P(ReadmeScene, LoadsWithTheReadmeTriangleCount) {
  MFR_SHARED_SCENE(file, GetParam().file);
  auto scene = mfr::loadScene(file.string());
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->triangleCount(), GetParam().triangles);
  EXPECT_FALSE(scene->materials.empty());
  for (const mfr::Texture& texture : scene->textures) EXPECT_FALSE(texture.rgba.empty());
}

INSTANTIATE_TEST_SUITE_P(SceneLoadingReal, ReadmeScene, ::testing::ValuesIn(kRealScenes),
                         [](const auto& info) { return std::string(info.param.name); });

class SceneLoadingRealDetails : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!mfr::test::sharedScenesPresent())
      GTEST_SKIP() << "shared scenes folder absent: " << root.string();
  }
  // the folder is there: a missing file is a failure naming it (not a skip)
  mfr::Result<mfr::Scene> load(const std::string& file) {
    EXPECT_TRUE(mfr::test::sharedSceneExists(file));
    return mfr::loadScene((root / file).string());
  }
  fs::path root = mfr::test::sharedScenesRoot();
};

TEST_F(SceneLoadingRealDetails, StainedGlassLampHasDecodedTexturesAndBlendAndMaskLayers) {
  auto scene = load(kRealScenes[1].file);
  ASSERT_LOADED(scene);
  EXPECT_FALSE(scene->textures.empty());
  for (const mfr::Texture& texture : scene->textures) {
    EXPECT_GT(texture.width, 0);
    EXPECT_EQ(texture.rgba.size(), size_t(texture.width) * size_t(texture.height) * 4);
  }
  auto has = [&](mfr::AlphaMode mode) {
    return std::any_of(scene->materials.begin(), scene->materials.end(),
                       [&](const mfr::Material& m) { return m.alphaMode == mode; });
  };
  EXPECT_TRUE(has(mfr::AlphaMode::Blend));
  EXPECT_TRUE(has(mfr::AlphaMode::Mask));
  EXPECT_FALSE(scene->uvs.empty());
}

TEST_F(SceneLoadingRealDetails, AlphaBlendModeTestHasAllThreeAlphaModes) {
  auto scene = load(kRealScenes[4].file);
  ASSERT_LOADED(scene);
  for (mfr::AlphaMode mode : {mfr::AlphaMode::Opaque, mfr::AlphaMode::Mask, mfr::AlphaMode::Blend})
    EXPECT_TRUE(std::any_of(scene->materials.begin(), scene->materials.end(),
                            [&](const mfr::Material& m) { return m.alphaMode == mode; }));
}

TEST_F(SceneLoadingRealDetails, TransmissionScenesFoldTransmissionIntoAlphaAndKeepTheirCameras) {
  auto scene = load(kRealScenes[3].file);
  ASSERT_LOADED(scene);
  EXPECT_EQ(scene->cameras.size(), 1u);
  EXPECT_TRUE(
      std::any_of(scene->materials.begin(), scene->materials.end(), [](const mfr::Material& m) {
        return m.transmission && *m.transmission > 0.5f && m.alphaMode == mfr::AlphaMode::Blend &&
               m.baseColor.a < 1.0f;
      }));
  auto dish = load(kRealScenes[0].file);
  ASSERT_LOADED(dish);
  EXPECT_EQ(dish->cameras.size(), 1u);
}

TEST_F(SceneLoadingRealDetails, AllRealScenesLoadWithinAFewSeconds) {
  const auto start = std::chrono::steady_clock::now();
  size_t loaded = 0;
  for (const RealScene& real : kRealScenes) {
    ASSERT_TRUE(mfr::test::sharedSceneExists(real.file));
    auto scene = load(real.file);
    ASSERT_LOADED(scene);
    ++loaded;
  }
  EXPECT_EQ(loaded, std::size(kRealScenes));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
#ifdef NDEBUG
  EXPECT_LT(seconds, 10.0);
#endif
  RecordProperty("seconds", std::to_string(seconds));
}

}  // namespace
