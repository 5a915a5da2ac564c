// Wavefront OBJ + MTL loader on top of tinyobjloader (polygons triangulated by polygon.hpp:
// tinyobjloader's own ear clipping is quadratic and folds large discs onto themselves).
//
// Conventions:
//  - Texture coordinates are flipped (uv.y = 1 - v): OBJ puts v = 0 at the bottom of the image,
//    the scene (like glTF) at the top row.
//  - Kd is the linear base colour, multiplied by map_Kd (loaded with stb_image to RGBA8, sRGB as
//    stored), resolved relative to the directory of the MTL file that declared it. A missing or
//    undecodable texture is an error naming it.
//  - map_d (an alpha texture: the image's alpha channel when it has one, else its first channel)
//    multiplies the alpha: it is folded into the alpha channel of the material's one texture
//    (map_Kd's, or a white one), and the material blends.
//  - mtllib and map_Kd files must be regular files inside the folder of the file naming them
//    (LoadOptions::allowOutsideReferences lifts the folder rule); a refused one is an error naming
//    it, checked before it is opened. A missing MTL file only falls back to the default material.
//    Texture headers are checked against the image size cap before decoding.
//  - Alpha is tinyobjloader's `dissolve`: `d` when present, otherwise 1 - `Tr` (tinyobjloader
//    already does this inversion, and ignores `Tr` when `d` is present). Alpha < 1 -> Blend, else
//    Opaque. Faces without a (known) material use a default opaque white material.
//  - Vertex normals are used when every face corner has one; otherwise all are recomputed.
//  - tinyobjloader reads "nan"/"inf" coordinates as 0; those values are restored so that
//    validateScene rejects them instead of the scene silently changing.
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <map>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "file_loaders.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/image_check.hpp"
#include "mfr/core/memory_limit.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/scene/load.hpp"
#include "polygon.hpp"

#include <stb_image.h>  // Debian libstb (linked by the library): image headers

namespace mfr {
namespace {

namespace fs = std::filesystem;

/// Reads the MTL files an OBJ names (inside the OBJ's folder) and remembers which file each
/// material came from, so texture paths resolve against their own MTL file.
class MtlReader : public tinyobj::MaterialReader {
 public:
  MtlReader(fs::path objFile, bool allowOutside)
      : objFile_(std::move(objFile)), allowOutside_(allowOutside) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* materialMap, std::string* warn,
                  std::string* err) override {
    const std::string what = "mtllib " + quoteInput(name);
    auto file = openReference(objFile_, name, what, allowOutside_);
    if (!file && !isNoSuchFileError(file.error())) {
      if (refusal.empty()) refusal = file.error().message;  // refused, not missing
      return false;
    }
    if (!file) {
      if (warn) *warn += "material file " + what + " not found\n";
      return false;
    }
    auto text = file->readText();
    if (!text) {
      if (refusal.empty()) refusal = text.error().message;
      return false;
    }
    std::istringstream stream(std::move(*text));
    tinyobj::LoadMtl(materialMap, materials, &stream, warn, err);
    files.resize(materials->size(), file->path());  // its textures resolve against its folder
    return true;
  }

  std::vector<fs::path> files;  // the MTL file of each material, by material index
  std::string refusal;          // the first refused mtllib (fails the load)

 private:
  fs::path objFile_;
  bool allowOutside_;
};

std::string firstLine(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return {};
  const size_t end = text.find_first_of("\r\n", begin);
  return text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

/// First line of `text` containing one of `needles` (case-insensitively), or "".
std::string lineContaining(const std::string& text, std::initializer_list<const char*> needles) {
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* needle : needles) {
    const size_t at = lower.find(needle);
    if (at == std::string::npos) continue;
    const size_t begin =
        text.find_last_of('\n', at) == std::string::npos ? 0 : text.find_last_of('\n', at) + 1;
    return firstLine(text.substr(begin));
  }
  return {};
}

/// tinyobjloader parses "nan" and "inf" as 0: put the real (non-finite) values back.
void restoreNonFiniteCoordinates(const std::string& text, std::vector<float>& vertices) {
  std::istringstream in(text);
  std::string line;
  size_t vertex = 0;
  while (std::getline(in, line)) {
    const size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line[start] != 'v' || start + 1 >= line.size() ||
        (line[start + 1] != ' ' && line[start + 1] != '\t'))
      continue;
    const char* token = line.c_str() + start + 1;
    for (size_t c = 0; c < 3; ++c) {
      char* end = nullptr;
      const float value = std::strtof(token, &end);
      if (end == token) break;
      if (!std::isfinite(value) && 3 * vertex + c < vertices.size())
        vertices[3 * vertex + c] = value;
      token = end;
    }
    ++vertex;
  }
}

/// A texture file (already resolved): header checked against the size cap and the memory limit
/// before decoding. `decodedBytes` adds up the textures' bytes so far.
Result<Texture> loadTexture(const OpenFile& file, const std::string& what, uint64_t memoryLimit,
                            uint64_t& decodedBytes, int* fileChannels = nullptr) {
  auto bytes = file.read(std::min<uint64_t>(memoryLimit, std::numeric_limits<int>::max()));
  if (!bytes) return bytes.error();
  MFR_TRY(checkPngChunks(bytes->data(), bytes->size(), what));  // before stb trusts a chunk length
  MFR_TRY(checkImageData(bytes->data(), bytes->size(), what));  // all the data its header declares
  const auto size = static_cast<int>(bytes->size());
  int width = 0, height = 0, channels = 0;
  if (stbi_info_from_memory(bytes->data(), size, &width, &height, &channels)) {
    MFR_TRY(checkImageDimensions(width, height, what));
    decodedBytes = saturatingAdd(decodedBytes,
                                 static_cast<uint64_t>(width) * static_cast<uint64_t>(height) * 4);
    MFR_TRY(checkMemory(decodedBytes, memoryLimit, "its decoded textures"));
  }
  auto decoded =
      decodeImageUnchecked(bytes->data(), bytes->size(),
                           "texture " + what + " (" + quoteInput(file.path().string(), 200) + ")");
  if (!decoded) return decoded.error();
  if (fileChannels) *fileChannels = decoded->fileChannels;
  Texture texture;
  texture.width = decoded->width;
  texture.height = decoded->height;
  texture.rgba = std::move(decoded->bytes);
  return texture;
}

struct CornerKey {
  int v, n, t;
  bool operator==(const CornerKey&) const = default;
};
struct CornerHash {
  size_t operator()(const CornerKey& k) const {
    uint64_t h = static_cast<uint32_t>(k.v);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<uint32_t>(k.n);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<uint32_t>(k.t);
    return static_cast<size_t>(h ^ (h >> 29));
  }
};

/// The corner count of every face of the text with three or more corners, in file order (the
/// order tinyobjloader keeps them in, which stores the count in a byte: a 300-corner face reads
/// as 44). Also checks what tinyobjloader reads without overflow checks: every index of an `f`
/// line must be a 32-bit integer (4294967299 wrapped to 3). Linear in the text.
Result<std::vector<uint32_t>> scanFaces(const std::string& text) {
  std::vector<uint32_t> faces;
  size_t line = 1;
  for (size_t at = 0; at < text.size(); ++line) {
    size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    size_t i = text.find_first_not_of(" \t", at);
    if (i < end && text[i] == 'f' && i + 1 < end && (text[i + 1] == ' ' || text[i + 1] == '\t')) {
      uint32_t corners = 0;
      bool inToken = false;
      for (i += 1; i < end && text[i] != '#'; ++i) {
        const char c = text[i];
        const bool space = c == ' ' || c == '\t' || c == '\r';
        if (!space && !inToken) ++corners;
        inToken = !space;
        if (c != '-' && (c < '0' || c > '9')) continue;
        const size_t start = i;
        if (c == '-') ++i;
        uint64_t value = 0;
        bool overflow = false;
        for (; i < end && text[i] >= '0' && text[i] <= '9'; ++i) {
          value = value * 10 + static_cast<uint64_t>(text[i] - '0');
          overflow = overflow || value > uint64_t{INT32_MAX};
        }
        if (overflow)
          return makeError("line " + std::to_string(line) + ": face index " +
                           quoteInput(std::string_view(text).substr(start, i - start), 40) +
                           " is out of range (at most " + std::to_string(INT32_MAX) + ")");
        --i;  // the loop steps past the last digit
      }
      if (corners >= 3) faces.push_back(corners);
    }
    at = end + 1;
  }
  return faces;
}

// What tinyobjloader read: vertex attributes, shapes, materials and each material's MTL file.
struct ObjData {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::vector<fs::path> mtlFiles;  // the MTL file of each material, by material index
};

// The OBJ text through tinyobjloader (polygons kept whole), its MTL files confined as the
// options say; its warnings about out-of-range indices are errors.
Result<ObjData> parseObj(const std::string& path, const std::string& text,
                         const LoadOptions& options) {
  std::istringstream stream(text);
  ObjData obj;
  tinyobj::attrib_t& attrib = obj.attrib;
  std::string warn, err;
  MtlReader mtlReader(path, options.allowOutsideReferences);
  const bool loaded = tinyobj::LoadObj(&attrib, &obj.shapes, &obj.materials, &warn, &err, &stream,
                                       &mtlReader, /*triangulate=*/false);  // polygon.hpp
  if (!mtlReader.refusal.empty()) return makeError(path + ": " + mtlReader.refusal);
  if (!loaded) {
    const std::string reason = firstLine(err);
    return makeError(path + ": " + (reason.empty() ? "invalid OBJ file" : reason));
  }
  // tinyobjloader only warns about faces with out-of-range indices (and drops some of them).
  if (const std::string bad = lineContaining(warn, {"out of bounds", "invalid vertex index"});
      !bad.empty())
    return makeError(path + ": " + bad);
  obj.mtlFiles = std::move(mtlReader.files);
  return obj;
}

// A map_d texture's alpha per texel: the image's alpha channel when it has one (grey + alpha,
// RGBA), else its first channel (grey, or red), as stored (linear).
uint8_t mapDAlpha(const Texture& t, size_t texel, int channels) {
  return channels == 2 || channels == 4 ? t.rgba[texel * 4 + 3] : t.rgba[texel * 4];
}

// The base colour texture of a material with map_d: map_Kd's colour (white without one) and
// map_Kd's alpha times map_d's, on map_Kd's texel grid (map_d sampled at the nearest texel
// centre when the sizes differ), so that the one texture a material has carries both.
Texture combineAlpha(const Texture* color, const Texture& alpha, int alphaChannels) {
  Texture out = color ? *color : Texture{alpha.width, alpha.height, {}};
  if (!color) out.rgba.assign(static_cast<size_t>(out.width) * out.height * 4, 255);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      const int ax = static_cast<int>((static_cast<int64_t>(x) * alpha.width) / out.width);
      const int ay = static_cast<int>((static_cast<int64_t>(y) * alpha.height) / out.height);
      const uint8_t d = mapDAlpha(
          alpha, static_cast<size_t>(ay) * alpha.width + static_cast<size_t>(ax), alphaChannels);
      uint8_t& a = out.rgba[(static_cast<size_t>(y) * out.width + static_cast<size_t>(x)) * 4 + 3];
      a = static_cast<uint8_t>((a * d + 127) / 255);
    }
  return out;
}

// Materials with their map_Kd and map_d textures (each file decoded once; Kd multiplies map_Kd in
// the engines, as every base colour factor multiplies its texture).
Result<void> addObjMaterials(const std::string& path,
                             const std::vector<tinyobj::material_t>& materials,
                             const std::vector<fs::path>& mtlFiles, const LoadOptions& options,
                             uint64_t memoryLimit, Scene& scene) {
  struct Decoded {
    Texture texture;
    int channels = 4;
  };
  std::map<std::string, Decoded> decoded;   // by resolved file
  std::map<std::string, int> textureByKey;  // map_Kd file [+ "|" + map_d file] -> scene texture
  uint64_t textureBytes = 0;
  for (size_t m = 0; m < materials.size(); ++m) {
    const tinyobj::material_t& src = materials[m];
    Material material;
    material.name = src.name;
    const float alpha = std::clamp(static_cast<float>(src.dissolve), 0.0f, 1.0f);
    material.baseColor = glm::vec4(src.diffuse[0], src.diffuse[1], src.diffuse[2], alpha);
    material.alphaMode = alpha < 1.0f ? AlphaMode::Blend : AlphaMode::Opaque;
    const fs::path mtlFile = m < mtlFiles.size() ? mtlFiles[m] : fs::path(path);
    // a texture statement's file, decoded once: its resolved path and the decoded image
    auto decode = [&](const std::string& texname,
                      const char* field) -> Result<std::pair<std::string, const Decoded*>> {
      std::string name = texname;
      std::replace(name.begin(), name.end(), '\\', '/');  // paths written on Windows
      const std::string what = std::string(field) + " " + quoteInput(name);
      auto file = openReference(mtlFile, name, what, options.allowOutsideReferences);
      if (!file) return makeError(path + ": " + file.error().message);
      const std::string key = file->path().string();
      auto it = decoded.find(key);
      if (it == decoded.end()) {
        Decoded d;
        auto texture = loadTexture(*file, what, memoryLimit, textureBytes, &d.channels);
        if (!texture) return makeError(path + ": " + texture.error().message);
        d.texture = std::move(*texture);
        it = decoded.emplace(key, std::move(d)).first;
      }
      return std::pair<std::string, const Decoded*>(key, &it->second);
    };
    std::optional<std::pair<std::string, const Decoded*>> color, cutout;
    if (!src.diffuse_texname.empty()) {
      auto d = decode(src.diffuse_texname, "map_Kd");
      if (!d) return d.error();
      color = *d;
    }
    if (!src.alpha_texname.empty()) {
      auto d = decode(src.alpha_texname, "map_d");
      if (!d) return d.error();
      cutout = *d;
      material.alphaMode = AlphaMode::Blend;  // the alpha varies over the surface
    }
    if (color || cutout) {
      const std::string key = (color ? color->first : std::string("white")) +
                              (cutout ? "|" + cutout->first : std::string());
      auto it = textureByKey.find(key);
      if (it == textureByKey.end()) {
        Texture texture = cutout ? combineAlpha(color ? &color->second->texture : nullptr,
                                                cutout->second->texture, cutout->second->channels)
                                 : color->second->texture;
        it = textureByKey.emplace(key, static_cast<int>(scene.textures.size())).first;
        scene.textures.push_back(std::move(texture));
      }
      material.baseColorTexture = it->second;
    }
    scene.materials.push_back(std::move(material));
  }
  return {};
}

// The default material, appended the first time some face needs it.
struct DefaultMaterial {
  Scene& scene;
  size_t objMaterials;
  uint32_t index = UINT32_MAX;

  uint32_t materialFor(int id) {
    if (id >= 0 && static_cast<size_t>(id) < objMaterials) return static_cast<uint32_t>(id);
    if (index == UINT32_MAX) {
      Material material;
      material.name = "default";
      material.alphaMode = AlphaMode::Opaque;
      index = static_cast<uint32_t>(scene.materials.size());
      scene.materials.push_back(std::move(material));
    }
    return index;
  }
};

// Whether every corner has a normal and whether any has a texture coordinate.
struct CornerUse {
  bool allNormals = true, anyUvs = false;
};

// Every corner's indices within the vertex, normal and texture-coordinate arrays.
Result<CornerUse> checkCorners(const std::string& path, const ObjData& obj) {
  const tinyobj::attrib_t& attrib = obj.attrib;
  const std::vector<tinyobj::shape_t>& shapes = obj.shapes;
  const size_t vertexCount = attrib.vertices.size() / 3;
  const size_t normalCount = attrib.normals.size() / 3;
  const size_t uvCount = attrib.texcoords.size() / 2;
  CornerUse use;
  for (const tinyobj::shape_t& shape : shapes)
    for (const tinyobj::index_t& corner : shape.mesh.indices) {
      if (corner.vertex_index < 0 || static_cast<size_t>(corner.vertex_index) >= vertexCount)
        return makeError(path + ": face references vertex " +
                         std::to_string(corner.vertex_index + 1) + " of " +
                         std::to_string(vertexCount));
      if (corner.normal_index >= 0 && static_cast<size_t>(corner.normal_index) >= normalCount)
        return makeError(path + ": face references missing normal " +
                         std::to_string(corner.normal_index + 1));
      if (corner.texcoord_index >= 0 && static_cast<size_t>(corner.texcoord_index) >= uvCount)
        return makeError(path + ": face references missing texture coordinate " +
                         std::to_string(corner.texcoord_index + 1));
      use.allNormals = use.allNormals && corner.normal_index >= 0;
      use.anyUvs = use.anyUvs || corner.texcoord_index >= 0;
    }
  return use;
}

// One scene vertex per distinct (position, normal, uv) corner; polygons triangulated here
// (polygon.hpp), in time linear in their corners when convex.
Result<void> addObjFaces(const std::string& path, const ObjData& obj,
                         const std::vector<uint32_t>& faceCorners, CornerUse use,
                         DefaultMaterial& defaults, Scene& scene) {
  const tinyobj::attrib_t& attrib = obj.attrib;
  const std::vector<tinyobj::shape_t>& shapes = obj.shapes;
  std::unordered_map<CornerKey, uint32_t, CornerHash> vertexOf;
  // tinyobjloader keeps each face's corner count in a byte: the scan's counts, when they agree
  // with what it stored (they always should), else its own.
  size_t storedFaces = 0, storedCorners = 0;
  for (const tinyobj::shape_t& shape : shapes) {
    storedFaces += shape.mesh.num_face_vertices.size();
    storedCorners += shape.mesh.indices.size();
  }
  uint64_t scannedCorners = 0;
  for (const uint32_t corners : faceCorners) scannedCorners += corners;
  const bool useScan = faceCorners.size() == storedFaces && scannedCorners == storedCorners;
  size_t face = 0;
  std::vector<glm::vec3> polygon;
  std::vector<uint32_t> triangles;
  for (const tinyobj::shape_t& shape : shapes) {
    const tinyobj::mesh_t& mesh = shape.mesh;
    size_t offset = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f, ++face) {
      const size_t corners = useScan ? (faceCorners)[face] : mesh.num_face_vertices[f];
      if (corners < 3 || offset + corners > mesh.indices.size()) {  // no surface: skip
        offset += corners;
        continue;
      }
      polygon.clear();
      for (size_t k = 0; k < corners; ++k) {
        const auto v = static_cast<size_t>(mesh.indices[offset + k].vertex_index);
        polygon.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1],
                             attrib.vertices[3 * v + 2]);
      }
      triangles.clear();
      if (auto split = triangulatePolygon(polygon, triangles); !split)
        return makeError(path + ": " + split.error().message + " (the face starting at vertex " +
                         std::to_string(mesh.indices[offset].vertex_index + 1) + ")");
      const uint32_t material =
          defaults.materialFor(f < mesh.material_ids.size() ? mesh.material_ids[f] : -1);
      for (size_t t = 0; t < triangles.size(); ++t) {
        const tinyobj::index_t& corner = mesh.indices[offset + triangles[t]];
        const CornerKey key{corner.vertex_index, use.allNormals ? corner.normal_index : -1,
                            corner.texcoord_index};
        auto [it, inserted] =
            vertexOf.try_emplace(key, static_cast<uint32_t>(scene.positions.size()));
        if (inserted) {
          const auto v = static_cast<size_t>(key.v);
          scene.positions.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1],
                                       attrib.vertices[3 * v + 2]);
          if (use.allNormals) {
            const auto n = static_cast<size_t>(key.n);
            const glm::vec3 normal(attrib.normals[3 * n], attrib.normals[3 * n + 1],
                                   attrib.normals[3 * n + 2]);
            const float length = glm::length(normal);
            scene.normals.push_back(length > 0.0f ? normal / length : normal);
          }
          if (use.anyUvs) {
            const auto uv = static_cast<size_t>(key.t);
            scene.uvs.push_back(key.t < 0 ? glm::vec2(0.0f)
                                          : glm::vec2(attrib.texcoords[2 * uv],
                                                      1.0f - attrib.texcoords[2 * uv + 1]));
          }
        }
        scene.indices.push_back(it->second);
        if (t % 3 == 2) scene.triangleMaterial.push_back(material);
      }
      offset += corners;
    }
  }
  return {};
}

Result<Scene> buildObjScene(const std::string& path, const OpenFile& file,
                            const LoadOptions& options) {
  const uint64_t memoryLimit = options.memoryLimitBytes.value_or(defaultMemoryLimit());
  auto text = file.readText(memoryLimit);
  if (!text) return text.error();
  auto faceCorners = scanFaces(*text);
  if (!faceCorners) return makeError(path + ": " + faceCorners.error().message);
  auto obj = parseObj(path, *text, options);
  if (!obj) return obj.error();
  restoreNonFiniteCoordinates(*text, obj->attrib.vertices);

  Scene scene;
  scene.name = path;
  MFR_TRY(addObjMaterials(path, obj->materials, obj->mtlFiles, options, memoryLimit, scene));
  DefaultMaterial defaults{scene, obj->materials.size()};
  auto use = checkCorners(path, *obj);
  if (!use) return use.error();
  MFR_TRY(addObjFaces(path, *obj, *faceCorners, *use, defaults, scene));
  if (scene.materials.empty()) defaults.materialFor(-1);  // no faces: still a well-formed list

  computeVertexNormals(scene);
  MFR_TRY(validateScene(scene));
  return scene;
}

}  // namespace

Result<Scene> loadObj(const std::string& path, const OpenFile& file, const LoadOptions& options) {
  try {
    return buildObjScene(path, file, options);
  } catch (const std::bad_alloc&) {
    return makeError(path + ": out of memory");
  } catch (const std::exception& e) {
    return makeError(path + ": " + e.what());
  }
}

}  // namespace mfr
