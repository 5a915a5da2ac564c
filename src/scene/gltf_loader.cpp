// glTF 2.0 loader (.gltf and .glb) on top of tinygltf, following the Khronos glTF 2.0 specification
// (accessors incl. sparse and normalized integers, node hierarchy with matrix or TRS transforms,
// triangle primitives, metallic-roughness base colour, COLOR_0 vertex colours, alpha modes,
// doubleSided (Scene::cull; mirroring transforms reverse the winding), perspective cameras) and the
// KHR_materials_transmission (folded into alpha, see LoadOptions), KHR_mesh_quantization,
// EXT_mesh_gpu_instancing (one copy of the mesh per instance) and KHR_texture_transform (on the
// base colour texture, applied to the texture coordinates at load) extensions.
//
// Images are not decoded while tinygltf parses the file: a custom image callback keeps the encoded
// bytes, and only images used as a base colour texture are decoded (in parallel) afterwards.
// tinygltf trusts bufferView ranges, so every accessor and image range is bounds-checked here.
//
// Files: the glTF is read here and handed to tinygltf from memory; tinygltf reads external buffers
// and images only through the file-system callbacks below, which confine them to the glTF's folder
// (mfr/core/file_access.hpp). Before tinygltf runs, every external uri is resolved and checked
// (regular file inside the folder, a buffer's byteLength equal to its file's size), so a refused
// reference is an error naming it and nothing it names is ever opened. Image headers are checked
// against the image size cap before decoding.
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "file_loaders.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/image_check.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/memory_limit.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/scene/load.hpp"

#include <stb_image.h>  // Debian libstb (linked by the library): image headers

namespace mfr {
namespace {

// ---------------------------------------------------------------------------------------------
// Image bytes kept by the tinygltf callback.

struct EncodedImages {
  const tinygltf::Model* model = nullptr;         // the model tinygltf is filling in
  std::vector<std::vector<unsigned char>> bytes;  // by image index; empty: not available
};

bool keepEncodedImage(tinygltf::Image* image, const int imageIndex, std::string* err,
                      std::string* /*warn*/, int /*reqWidth*/, int /*reqHeight*/,
                      const unsigned char* bytes, int size, void* user) {
  auto* images = static_cast<EncodedImages*>(user);
  if (imageIndex < 0 || size < 0) return false;
  if (image->bufferView >= 0) {
    // tinygltf hands us &buffer.data[view.byteOffset] without checking the view against the buffer.
    const tinygltf::Model& model = *images->model;
    if (static_cast<size_t>(image->bufferView) >= model.bufferViews.size()) return false;
    const auto& view = model.bufferViews[static_cast<size_t>(image->bufferView)];
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) return false;
    const auto& buffer = model.buffers[static_cast<size_t>(view.buffer)];
    if (view.byteOffset > buffer.data.size() ||
        view.byteLength > buffer.data.size() - view.byteOffset) {
      if (err)
        *err += "image[" + std::to_string(imageIndex) + "] bufferView lies outside its buffer\n";
      return false;
    }
  }
  if (images->bytes.size() <= static_cast<size_t>(imageIndex))
    images->bytes.resize(static_cast<size_t>(imageIndex) + 1);
  if (size > 0) images->bytes[static_cast<size_t>(imageIndex)].assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

std::string firstLine(const std::string& text) {
  size_t begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return {};
  size_t end = text.find_first_of("\r\n", begin);
  return text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

bool startsWithGlbMagic(const std::vector<unsigned char>& bytes) {
  return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

// ---------------------------------------------------------------------------------------------
// File access: external buffers and images, confined to the glTF's folder.

/// tinygltf's base folder of a file path (GetBaseDir): everything before the last separator.
std::string baseDirOf(const std::string& path) {
  const size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? std::string() : path.substr(0, slash);
}

/// tinygltf's uri decoding (dlib::urldecode): '+' is a space, %XX a byte.
std::string decodeUri(const std::string& uri) {
  const auto hex = [](unsigned char c) -> unsigned char {
    if (c >= '0' && c <= '9') return static_cast<unsigned char>(c - '0');
    if (c >= 'a' && c <= 'f') return static_cast<unsigned char>(c - 'a' + 10);
    if (c >= 'A' && c <= 'F') return static_cast<unsigned char>(c - 'A' + 10);
    return 0;
  };
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && uri.size() > i + 2) {
      out += static_cast<char>((hex(static_cast<unsigned char>(uri[i + 1])) << 4) |
                               hex(static_cast<unsigned char>(uri[i + 2])));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

/// What the file-system callbacks know (their user data): every external file, read once before
/// tinygltf runs, by the reference tinygltf will ask for.
struct GltfFiles {
  std::string path;  // the glTF file
  bool allowOutside = false;
  uint64_t maxFileBytes = 0;                                // cap for any external file
  std::map<std::string, std::vector<unsigned char>> bytes;  // decoded reference -> contents
  std::map<std::string, int> readsLeft;  // how many uris name it (the last read takes the bytes)

  /// The reference inside the glTF that tinygltf's candidate path `candidate` stands for; empty
  /// for tinygltf's second guess, the working folder (never allowed).
  std::string referenceOf(const std::string& candidate) const {
    const std::string base = baseDirOf(path);
    if (base.empty()) return candidate;
    const std::string prefix = base.back() == '/' ? base : base + "/";
    return candidate.rfind(prefix, 0) == 0 ? candidate.substr(prefix.size()) : std::string();
  }
};

bool gltfFileExists(const std::string& candidate, void* user) {
  const auto* files = static_cast<GltfFiles*>(user);
  const std::string reference = files->referenceOf(candidate);
  return !reference.empty() && files->bytes.count(reference) != 0;
}

/// No expansion of `~` or variables: a uri is a relative path, nothing else.
std::string gltfExpandFilePath(const std::string& path, void*) {
  return path;
}

/// Hands tinygltf a file read by checkReferences; tinygltf never opens a file itself.
bool gltfReadWholeFile(std::vector<unsigned char>* out, std::string* err,
                       const std::string& candidate, void* user) {
  auto* files = static_cast<GltfFiles*>(user);
  const std::string reference = files->referenceOf(candidate);
  const auto it = reference.empty() ? files->bytes.end() : files->bytes.find(reference);
  if (it == files->bytes.end()) {
    if (err) *err += "uri " + quoteInput(reference) + ": not named by the file\n";
    return false;
  }
  if (--files->readsLeft[reference] <= 0)
    *out = std::move(it->second);
  else
    *out = it->second;
  return true;
}

bool gltfWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&,
                        void*) {
  if (err) *err += "writing is not supported\n";
  return false;
}

/// The JSON of a .gltf, or of a GLB's first (JSON) chunk (checkGlb has checked the chunks).
Result<nlohmann::json> gltfJson(const std::vector<unsigned char>& bytes) {
  const unsigned char* begin = bytes.data();
  size_t size = bytes.size();
  if (startsWithGlbMagic(bytes)) {
    uint32_t chunkLength = 0;
    std::memcpy(&chunkLength, begin + 12, 4);
    begin += 20;
    size = chunkLength;
  }
  // before anything recursive reads it (tinygltf converts extras and extensions recursively)
  const std::string deep =
      jsonDepthProblem(std::string_view(reinterpret_cast<const char*>(begin), size));
  if (!deep.empty()) return makeError(deep);
  try {
    return nlohmann::json::parse(begin, begin + size);
  } catch (const nlohmann::json::exception& e) {
    return makeError(jsonErrorText(e.what()));
  }
}

uint32_t le32(const std::vector<unsigned char>& bytes, size_t offset) {
  uint32_t v = 0;
  std::memcpy(&v, bytes.data() + offset, 4);
  return v;
}

/// A binary glTF's header and chunk lengths against the file (glTF 2.0 section 4.4), before the
/// loader trusts them: version 2, a declared length within the file, a JSON chunk first, every
/// chunk inside the declared length.
Result<void> checkGlb(const std::vector<unsigned char>& bytes) {
  if (bytes.size() < 12)
    return makeError("GLB file of " + std::to_string(bytes.size()) +
                     " bytes is shorter than its 12-byte header");
  const uint32_t version = le32(bytes, 4), length = le32(bytes, 8);
  if (version != 2)
    return makeError("GLB version " + std::to_string(version) + " (only version 2 is supported)");
  if (length > bytes.size())
    return makeError("GLB header declares " + std::to_string(length) + " bytes, the file has " +
                     std::to_string(bytes.size()));
  size_t offset = 12;
  for (int chunk = 0; offset < length; ++chunk) {
    if (length - offset < 8)
      return makeError("GLB chunk " + std::to_string(chunk) + " at byte " + std::to_string(offset) +
                       " is cut off in its 8-byte header");
    const uint32_t chunkLength = le32(bytes, offset), type = le32(bytes, offset + 4);
    const size_t left = length - offset - 8;
    const std::string name = type == 0x4E4F534Au   ? "JSON"
                             : type == 0x004E4942u ? "BIN"
                                                   : "of type " + std::to_string(type);
    if (chunkLength > left)
      return makeError("GLB chunk " + std::to_string(chunk) + " (" + name + ") declares " +
                       std::to_string(chunkLength) + " bytes, only " + std::to_string(left) +
                       " are left in the file");
    if (chunk == 0 && type != 0x4E4F534Au)
      return makeError("GLB file does not start with a JSON chunk");
    offset += 8 + size_t{chunkLength};
  }
  if (offset == 12) return makeError("GLB file has no JSON chunk");
  return {};
}

/// The number of bytes a base64 data URI's payload decodes to, or nullopt when it is not base64.
std::optional<uint64_t> dataUriBytes(const std::string& uri) {
  const size_t comma = uri.find(',');
  static const std::string kBase64 = ";base64";
  if (comma == std::string::npos || comma < kBase64.size() ||
      uri.compare(comma - kBase64.size(), kBase64.size(), kBase64) != 0)
    return std::nullopt;
  uint64_t chars = uri.size() - comma - 1;
  size_t padding = 0;
  for (size_t i = uri.size(); i > comma + 1 && uri[i - 1] == '=' && padding < 2; --i) ++padding;
  return chars / 4 * 3 + (chars % 4 == 0 ? 0 : chars % 4 - 1) - (chars % 4 == 0 ? padding : 0);
}

/// The glTF extensions mfr implements: an asset that requires any other must be refused (glTF 2.0
/// section 3.12). KHR_mesh_quantization only widens the accessor types, which readAccessor reads;
/// EXT_mesh_gpu_instancing is expanded into one copy of the mesh per instance;
/// KHR_texture_transform is applied to the base colour texture's coordinates (the only texture mfr
/// samples).
bool isImplementedExtension(const std::string& name) {
  return name == "KHR_materials_transmission" || name == "KHR_mesh_quantization" ||
         name == "EXT_mesh_gpu_instancing" || name == "KHR_texture_transform";
}

/// Offsets, lengths, counts and indices of accessors and buffer views that must be non-negative
/// integers (glTF 2.0 sections 5.1, 5.11): tinygltf reads an unsigned field that is not one
/// (accessor byteOffset -4) as absent, 0, and keeps a negative sparse count or index (-1: "none"),
/// so the loader would read another range or none, silently.
Result<void> checkNonNegative(const nlohmann::json& doc) {
  const auto check = [](const nlohmann::json& object, const std::string& where,
                        std::initializer_list<const char*> fields) -> Result<void> {
    if (!object.is_object()) return {};
    for (const char* field : fields) {
      const auto it = object.find(field);
      if (it == object.end() || it->is_number_unsigned()) continue;
      return makeError(where + "." + field + " " + oneLine(it->dump(), 40) +
                       ": must be a non-negative integer");
    }
    return {};
  };
  if (auto it = doc.find("bufferViews"); it != doc.end() && it->is_array())
    for (size_t i = 0; i < it->size(); ++i)
      MFR_TRY(check((*it)[i], "bufferViews[" + std::to_string(i) + "]",
                    {"buffer", "byteOffset", "byteLength"}));
  if (auto it = doc.find("accessors"); it != doc.end() && it->is_array())
    for (size_t i = 0; i < it->size(); ++i) {
      const nlohmann::json& accessor = (*it)[i];
      const std::string where = "accessors[" + std::to_string(i) + "]";
      MFR_TRY(check(accessor, where, {"bufferView", "byteOffset", "count"}));
      if (!accessor.is_object() || !accessor.contains("sparse")) continue;
      const nlohmann::json& sparse = accessor["sparse"];
      MFR_TRY(check(sparse, where + ".sparse", {"count"}));
      if (!sparse.is_object()) continue;
      for (const char* part : {"indices", "values"})
        if (sparse.contains(part))
          MFR_TRY(check(sparse[part], where + ".sparse." + part, {"bufferView", "byteOffset"}));
    }
  return {};
}

/// What the JSON says before tinygltf reads it: required extensions mfr implements, buffer views'
/// strides, data URIs' lengths; then every external uri opened and read once (regular files
/// inside the folder unless allowed outside, a buffer's file exactly its byteLength), kept for the
/// read callback.
Result<void> checkReferences(const nlohmann::json& doc, GltfFiles& files) {
  if (!doc.is_object()) return {};
  if (auto it = doc.find("extensionsRequired"); it != doc.end() && it->is_array())
    for (const nlohmann::json& name : *it)
      if (name.is_string() && !isImplementedExtension(name.get<std::string>()))
        return makeError("requires extension " + quoteInput(name.get<std::string>()) +
                         ", which mfr does not implement (it implements "
                         "KHR_materials_transmission, KHR_mesh_quantization, "
                         "EXT_mesh_gpu_instancing and KHR_texture_transform)");
  if (auto it = doc.find("bufferViews"); it != doc.end() && it->is_array())
    for (size_t i = 0; i < it->size(); ++i) {
      const nlohmann::json& view = (*it)[i];
      if (!view.is_object() || !view.contains("byteStride")) continue;
      const nlohmann::json& stride = view["byteStride"];
      const bool valid = stride.is_number_integer() && stride.get<int64_t>() >= 4 &&
                         stride.get<int64_t>() <= 252 && stride.get<int64_t>() % 4 == 0;
      if (!valid)
        return makeError("bufferViews[" + std::to_string(i) + "].byteStride " +
                         jsonExcerpt(stride, 40) + ": must be a multiple of 4 in [4, 252]");
    }
  MFR_TRY(checkNonNegative(doc));
  // an item's uri, when it has one
  const auto uriOf = [](const nlohmann::json& item) -> const std::string* {
    if (!item.is_object()) return nullptr;
    const auto uri = item.find("uri");
    return uri != item.end() && uri->is_string() ? &uri->get_ref<const std::string&>() : nullptr;
  };
  // a file named by a uri, read once (a second uri naming it shares the bytes)
  const auto read = [&files](const std::string& uri, const std::string& what,
                             std::optional<uint64_t> declared) -> Result<void> {
    const std::string reference = decodeUri(uri);
    const auto sizeDiffers = [&](uint64_t size) {
      return makeError(what + ": byteLength " + std::to_string(*declared) +
                       " differs from the file's size, " + std::to_string(size) + " bytes");
    };
    auto known = files.bytes.find(reference);
    if (known == files.bytes.end()) {
      auto file = openReference(files.path, reference, what, files.allowOutside);
      if (!file) return file.error();
      if (declared && file->size() != *declared) return sizeDiffers(file->size());  // unread
      auto bytes = file->read(declared.value_or(files.maxFileBytes));
      if (!bytes) return bytes.error();
      if (declared && bytes->size() != *declared)
        return makeError(what + ": the file shrank while it was read");
      known = files.bytes.emplace(reference, std::move(*bytes)).first;
    } else if (declared && known->second.size() != *declared) {
      return sizeDiffers(known->second.size());
    }
    ++files.readsLeft[reference];
    return {};
  };
  if (auto it = doc.find("buffers"); it != doc.end() && it->is_array())
    for (size_t i = 0; i < it->size(); ++i) {
      const std::string* uri = uriOf((*it)[i]);
      if (!uri) continue;  // the GLB's own buffer, or invalid (tinygltf reports it)
      const auto length = (*it)[i].find("byteLength");
      std::optional<uint64_t> declared;
      if (length != (*it)[i].end() && length->is_number_unsigned())
        declared = length->get<uint64_t>();
      if (tinygltf::IsDataURI(*uri)) {
        const auto decoded = dataUriBytes(*uri);
        if (declared && decoded && *decoded != *declared)
          return makeError("buffer " + std::to_string(i) + ": byteLength " +
                           std::to_string(*declared) + " differs from the size of its data URI, " +
                           std::to_string(*decoded) + " bytes");
        continue;
      }
      MFR_TRY(read(*uri, "buffer " + std::to_string(i) + " uri " + quoteInput(*uri), declared));
    }
  if (auto it = doc.find("images"); it != doc.end() && it->is_array())
    for (size_t i = 0; i < it->size(); ++i)
      if (const std::string* uri = uriOf((*it)[i]); uri && !tinygltf::IsDataURI(*uri))
        MFR_TRY(
            read(*uri, "image " + std::to_string(i) + " uri " + quoteInput(*uri), std::nullopt));
  return {};
}

// ---------------------------------------------------------------------------------------------
// Accessors.

size_t componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;  // INT and DOUBLE are not valid glTF 2.0 accessor component types
  }
}

int componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    default:
      return 0;  // matrices are never read here
  }
}

/// One component, normalized integers mapped as in the glTF specification (section 3.11).
double readComponent(const unsigned char* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      uint8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? v / 4294967295.0 : v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

/// A checked, strided range of `count` elements inside one buffer.
struct ElementRange {
  const unsigned char* data = nullptr;
  size_t stride = 0;
};

/// The texture coordinates a base colour texture reads: its set (TEXCOORD_n) and the
/// KHR_texture_transform matrix uv' = T * R * S * uv (identity without the extension), as the two
/// rows of its 2x3 affine part.
struct UvTransform {
  int texCoord = 0;
  glm::dvec3 row0{1.0, 0.0, 0.0};  // u' = row0 . (u, v, 1)
  glm::dvec3 row1{0.0, 1.0, 0.0};  // v' = row1 . (u, v, 1)

  /// From the extension's offset (ox, oy), rotation r (radians) and scale (sx, sy): T R S with
  /// T = [1 0 ox; 0 1 oy], R = [cos r, sin r; -sin r, cos r], S = diag(sx, sy) (the extension's
  /// specification).
  static UvTransform fromOffsetRotationScale(int texCoord, glm::dvec2 offset, double rotation,
                                             glm::dvec2 scale) {
    const double c = std::cos(rotation), s = std::sin(rotation);
    return {texCoord, {c * scale.x, s * scale.y, offset.x}, {-s * scale.x, c * scale.y, offset.y}};
  }

  glm::vec2 apply(double u, double v) const {
    return {static_cast<float>(row0.x * u + row0.y * v + row0.z),
            static_cast<float>(row1.x * u + row1.y * v + row1.z)};
  }
};

/// A primitive's accessors, read and checked once: addMeshInstances places it once per instance.
struct PrimitiveData {
  bool skipped = false;           // points or lines: not a surface, counted per placement
  std::string what;               // "mesh 0 ('name') primitive 1", for errors
  std::vector<double> positions;  // xyz per vertex
  std::vector<double> normals;    // xyz per vertex, or empty (area-weighted from the faces)
  std::vector<double> uvs;        // the base colour's texture coordinate set, or empty
  std::vector<double> colors;     // COLOR_0 as linear RGBA, or empty
  UvTransform transform;
  std::vector<uint32_t> triangles;  // vertex indices, three a triangle (empty: nothing to draw)
  uint32_t material = 0;            // scene material
};

// ---------------------------------------------------------------------------------------------

class GltfSceneBuilder {
 public:
  GltfSceneBuilder(const tinygltf::Model& model, const EncodedImages& images,
                   const std::string& path, const LoadOptions& options)
      : model_(model),
        images_(images),
        path_(path),
        options_(options),
        memoryLimit_(options.memoryLimitBytes.value_or(defaultMemoryLimit())) {}

  Result<Scene> build();

 private:
  Error fail(const std::string& what) const { return makeError(path_ + ": " + what); }

  Result<ElementRange> elementRange(int bufferViewIndex, size_t byteOffset, size_t count,
                                    size_t elementSize, bool allowStride,
                                    const std::string& what) const;
  Result<void> checkAccessor(int index, int expectedType, const std::string& what) const;
  Result<std::vector<double>> readAccessor(int index, int expectedType,
                                           const std::string& what) const;
  Result<std::vector<double>> readColors(int index, size_t vertexCount,
                                         const std::string& what) const;
  Result<UvTransform> baseColorUvTransform(int gltfMaterial) const;
  Result<std::vector<int>> rootNodes() const;
  Result<void> checkExpansion();
  Result<void> visitNodes();
  Result<void> addMeshInstances(const tinygltf::Node& node, int nodeIndex, const glm::dmat4& world);
  Result<std::vector<PrimitiveData>> readMesh(int meshIndex);
  Result<PrimitiveData> readPrimitive(const tinygltf::Primitive& primitive,
                                      const std::string& what);
  Result<void> placeMesh(const std::vector<PrimitiveData>& mesh, const glm::dmat4& world);
  uint32_t materialIndex(int gltfMaterial);
  int textureIndex(int gltfTexture);
  Result<void> readSamplers();
  TextureSampler samplerOf(int gltfTexture) const;
  Result<void> decodeTextures();
  Result<void> addCameras();

  const tinygltf::Model& model_;
  const EncodedImages& images_;
  const std::string& path_;
  const LoadOptions& options_;
  const uint64_t memoryLimit_;

  Scene scene_;
  bool anyUvs_ = false;
  bool anyColors_ = false;
  std::map<int, uint32_t> materialMap_;   // glTF material (-1: default) -> scene material
  std::map<int, int> imageMap_;           // glTF image -> scene texture
  std::vector<TextureSampler> samplers_;  // per glTF sampler (readSamplers)
  std::vector<std::pair<int, glm::dmat4>> cameraNodes_;  // (camera index, node world matrix)
};

Result<ElementRange> GltfSceneBuilder::elementRange(int bufferViewIndex, size_t byteOffset,
                                                    size_t count, size_t elementSize,
                                                    bool allowStride,
                                                    const std::string& what) const {
  if (bufferViewIndex < 0 || static_cast<size_t>(bufferViewIndex) >= model_.bufferViews.size())
    return fail(what + ": bufferView " + std::to_string(bufferViewIndex) + " does not exist");
  const tinygltf::BufferView& view = model_.bufferViews[static_cast<size_t>(bufferViewIndex)];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model_.buffers.size())
    return fail(what + ": buffer " + std::to_string(view.buffer) + " does not exist");
  const std::vector<unsigned char>& data = model_.buffers[static_cast<size_t>(view.buffer)].data;
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
    return fail(what + ": bufferView " + std::to_string(bufferViewIndex) + " lies outside buffer " +
                std::to_string(view.buffer));
  const size_t stride = (allowStride && view.byteStride != 0) ? view.byteStride : elementSize;
  if (count > 0) {
    // byteOffset + stride * (count - 1) + elementSize <= byteLength, without overflow.
    const size_t length = view.byteLength;
    const bool fits =
        byteOffset <= length && elementSize <= length - byteOffset &&
        (count - 1) <= (length - byteOffset - elementSize) / std::max<size_t>(stride, 1);
    if (!fits)
      return fail(what + ": reads past the end of bufferView " + std::to_string(bufferViewIndex));
  }
  return ElementRange{data.data() + view.byteOffset + byteOffset, stride};
}

/// readAccessor's checks of accessor `index`, without reading it: it exists, has the type, and its
/// count fits its bufferView (without one: the cap).
Result<void> GltfSceneBuilder::checkAccessor(int index, int expectedType,
                                             const std::string& what) const {
  if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size())
    return fail(what + ": accessor " + std::to_string(index) + " does not exist");
  const tinygltf::Accessor& accessor = model_.accessors[static_cast<size_t>(index)];
  const std::string where = what + " (accessor " + std::to_string(index) + ")";
  if (accessor.type != expectedType) return fail(where + ": unexpected element type");
  const size_t csize = componentSize(accessor.componentType);
  if (csize == 0) return fail(where + ": invalid component type");
  const size_t elementSize = csize * static_cast<size_t>(componentCount(accessor.type));
  if (accessor.bufferView >= 0) {
    auto range = elementRange(accessor.bufferView, accessor.byteOffset, accessor.count, elementSize,
                              true, where);
    return range ? Result<void>() : Result<void>(range.error());
  }
  if (accessor.count > (size_t{1} << 22)) return fail(where + ": count too large");
  return {};
}

/// All components of accessor `index` as doubles (count * components values), sparse substitution
/// applied. An accessor without a bufferView reads as zeros.
Result<std::vector<double>> GltfSceneBuilder::readAccessor(int index, int expectedType,
                                                           const std::string& what) const {
  MFR_TRY(checkAccessor(index, expectedType, what));  // index, type, component type, count
  const tinygltf::Accessor& accessor = model_.accessors[static_cast<size_t>(index)];
  const std::string where = what + " (accessor " + std::to_string(index) + ")";
  const size_t csize = componentSize(accessor.componentType);
  const auto components = static_cast<size_t>(componentCount(accessor.type));
  const size_t elementSize = csize * components;

  std::vector<double> values;
  if (accessor.bufferView >= 0) {
    auto range = elementRange(accessor.bufferView, accessor.byteOffset, accessor.count, elementSize,
                              true, where);
    if (!range) return range.error();
    values.resize(accessor.count * components);
    for (size_t i = 0; i < accessor.count; ++i)
      for (size_t c = 0; c < components; ++c)
        values[i * components + c] = readComponent(range->data + i * range->stride + c * csize,
                                                   accessor.componentType, accessor.normalized);
  } else {
    // No bufferView: zeros (possibly overridden by sparse values); checkAccessor capped the
    // count, which nothing in the file bounds here.
    values.assign(accessor.count * components, 0.0);
  }

  if (accessor.sparse.isSparse && accessor.sparse.count > 0) {
    const auto& sparse = accessor.sparse;
    const size_t count = static_cast<size_t>(sparse.count);
    const size_t indexSize = componentSize(sparse.indices.componentType);
    if (sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
        sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
        sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || indexSize == 0 ||
        sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0)
      return fail(where + ": invalid sparse accessor");
    auto indexRange =
        elementRange(sparse.indices.bufferView, static_cast<size_t>(sparse.indices.byteOffset),
                     count, indexSize, false, where + " sparse indices");
    if (!indexRange) return indexRange.error();
    auto valueRange =
        elementRange(sparse.values.bufferView, static_cast<size_t>(sparse.values.byteOffset), count,
                     elementSize, false, where + " sparse values");
    if (!valueRange) return valueRange.error();
    for (size_t i = 0; i < count; ++i) {
      const auto target = static_cast<size_t>(
          readComponent(indexRange->data + i * indexSize, sparse.indices.componentType, false));
      if (target >= accessor.count) return fail(where + ": sparse index out of range");
      for (size_t c = 0; c < components; ++c)
        values[target * components + c] =
            readComponent(valueRange->data + i * elementSize + c * csize, accessor.componentType,
                          accessor.normalized);
    }
  }
  return values;
}

/// COLOR_0 as linear RGBA (glTF 2.0 section 3.7.2.1: VEC3 or VEC4 of float, normalized unsigned
/// byte or normalized unsigned short; VEC3 has alpha 1), 4 values per vertex.
Result<std::vector<double>> GltfSceneBuilder::readColors(int index, size_t vertexCount,
                                                         const std::string& what) const {
  if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size())
    return fail(what + ": accessor " + std::to_string(index) + " does not exist");
  const tinygltf::Accessor& accessor = model_.accessors[static_cast<size_t>(index)];
  const std::string where = what + " (accessor " + std::to_string(index) + ")";
  if (accessor.type != TINYGLTF_TYPE_VEC3 && accessor.type != TINYGLTF_TYPE_VEC4)
    return fail(where + ": must be VEC3 or VEC4");
  const bool validComponents =
      accessor.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
      (accessor.normalized && (accessor.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                               accessor.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT));
  if (!validComponents)
    return fail(where + ": must be float, normalized unsigned byte or normalized unsigned short");
  auto read = readAccessor(index, accessor.type, what);
  if (!read) return read.error();
  const size_t components = accessor.type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
  if (read->size() / components != vertexCount) return fail(what + ": count differs");
  if (components == 4) return read;
  std::vector<double> rgba(vertexCount * 4, 1.0);
  for (size_t i = 0; i < vertexCount; ++i)
    for (size_t c = 0; c < 3; ++c) rgba[4 * i + c] = (*read)[3 * i + c];
  return rgba;
}

/// The base colour texture's coordinate set and KHR_texture_transform of glTF material
/// `gltfMaterial` (a valid index). The transform is applied to the primitive's texture coordinates
/// at load time: it is affine and every primitive has its own copy of its vertices, read by the
/// one texture mfr samples, so interpolating the transformed coordinates is transforming the
/// interpolated ones (docs/GLTF.md), identically for both engines.
Result<UvTransform> GltfSceneBuilder::baseColorUvTransform(int gltfMaterial) const {
  const tinygltf::Material& material = model_.materials[static_cast<size_t>(gltfMaterial)];
  const tinygltf::TextureInfo& info = material.pbrMetallicRoughness.baseColorTexture;
  UvTransform transform;
  transform.texCoord = std::max(0, info.texCoord);
  if (info.index < 0) return transform;
  const auto ext = info.extensions.find("KHR_texture_transform");
  if (ext == info.extensions.end()) return transform;
  const std::string what = "material " + std::to_string(gltfMaterial) + " (" +
                           quoteInput(material.name, 60) +
                           ") baseColorTexture KHR_texture_transform";
  const tinygltf::Value& value = ext->second;
  if (!value.IsObject()) return fail(what + ": must be an object");
  auto number = [&](const tinygltf::Value& v, const std::string& field) -> Result<double> {
    if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
      return fail(what + ": " + field + " must be a finite number");
    return v.GetNumberAsDouble();
  };
  auto pair = [&](const char* field, glm::dvec2 fallback) -> Result<glm::dvec2> {
    if (!value.Has(field)) return fallback;
    const tinygltf::Value& v = value.Get(field);
    if (!v.IsArray() || v.ArrayLen() != 2)
      return fail(what + ": " + field + " must be an array of 2 numbers");
    auto x = number(v.Get(0), std::string(field) + "[0]");
    if (!x) return x.error();
    auto y = number(v.Get(1), std::string(field) + "[1]");
    if (!y) return y.error();
    return glm::dvec2(*x, *y);
  };
  auto offset = pair("offset", glm::dvec2(0.0));
  if (!offset) return offset.error();
  auto scale = pair("scale", glm::dvec2(1.0));
  if (!scale) return scale.error();
  double rotation = 0.0;
  if (value.Has("rotation")) {
    auto r = number(value.Get("rotation"), "rotation");
    if (!r) return r.error();
    rotation = *r;
  }
  int texCoord = transform.texCoord;
  if (value.Has("texCoord")) {
    const tinygltf::Value& t = value.Get("texCoord");
    if (!t.IsInt() || t.GetNumberAsInt() < 0)
      return fail(what + ": texCoord must be a non-negative integer");
    texCoord = t.GetNumberAsInt();
  }
  return UvTransform::fromOffsetRotationScale(texCoord, *offset, rotation, *scale);
}

glm::dmat4 localTransform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3) m = glm::translate(m, glm::make_vec3(node.translation.data()));
  if (node.rotation.size() == 4) {
    const auto& r = node.rotation;  // x, y, z, w
    m *= glm::mat4_cast(glm::normalize(glm::dquat(r[3], r[0], r[1], r[2])));
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::make_vec3(node.scale.data()));
  return m;
}

/// The chosen scene's root nodes: `--scene N`, else the file's `scene`, else its first, else every
/// node that is no other node's child.
Result<std::vector<int>> GltfSceneBuilder::rootNodes() const {
  if (options_.sceneIndex) {
    const int n = *options_.sceneIndex;
    if (n < 0 || static_cast<size_t>(n) >= model_.scenes.size())
      return fail("scene " + std::to_string(n) + ": the file has " +
                  std::to_string(model_.scenes.size()) + " scene(s)");
    return model_.scenes[static_cast<size_t>(n)].nodes;
  }
  if (model_.defaultScene >= 0 && static_cast<size_t>(model_.defaultScene) < model_.scenes.size())
    return model_.scenes[static_cast<size_t>(model_.defaultScene)].nodes;
  if (!model_.scenes.empty()) return model_.scenes[0].nodes;
  std::vector<int> roots;
  std::vector<char> isChild(model_.nodes.size(), 0);
  for (const tinygltf::Node& node : model_.nodes)
    for (int child : node.children)
      if (child >= 0 && static_cast<size_t>(child) < isChild.size())
        isChild[static_cast<size_t>(child)] = 1;
  for (size_t i = 0; i < model_.nodes.size(); ++i)
    if (!isChild[i]) roots.push_back(static_cast<int>(i));
  return roots;
}

/// The instances EXT_mesh_gpu_instancing gives a node: its first attribute accessor's count (1
/// without the extension; addMeshInstances checks the attributes themselves).
size_t instanceCount(const tinygltf::Model& model, const tinygltf::Node& node) {
  const auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == node.extensions.end() || !ext->second.Has("attributes") ||
      !ext->second.Get("attributes").IsObject())
    return 1;
  const tinygltf::Value& attributes = ext->second.Get("attributes");
  for (const char* name : {"TRANSLATION", "ROTATION", "SCALE"}) {
    if (!attributes.Has(name) || !attributes.Get(name).IsInt()) continue;
    const int accessor = attributes.Get(name).GetNumberAsInt();
    if (accessor >= 0 && static_cast<size_t>(accessor) < model.accessors.size())
      return model.accessors[static_cast<size_t>(accessor)].count;
  }
  return 1;
}

/// What the node tree expands into, before any of it is built: the vertices and triangles of
/// every mesh as often as nodes and EXT_mesh_gpu_instancing place it (a 4-million-vertex accessor
/// of zeros is 622 bytes of JSON; used by 16 nodes it would be 6.5 GB), times their bytes
/// (sceneMemoryBytes), plus the largest primitive's and instance list's read-out (doubles), against
/// the memory limit. The scene's arrays are then reserved once at their final size.
Result<void> GltfSceneBuilder::checkExpansion() {
  auto roots = rootNodes();
  if (!roots) return roots.error();
  const auto accessorCount = [&](int index) -> std::optional<uint64_t> {
    if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size()) return std::nullopt;
    return model_.accessors[static_cast<size_t>(index)].count;
  };
  uint64_t vertices = 0, triangles = 0, transient = 0;
  std::vector<char> visited(model_.nodes.size(), 0);
  std::vector<int> stack(roots->rbegin(), roots->rend());
  while (!stack.empty()) {
    const int index = stack.back();
    stack.pop_back();
    if (index < 0 || static_cast<size_t>(index) >= model_.nodes.size() ||
        visited[static_cast<size_t>(index)])
      continue;  // visitNodes names it
    visited[static_cast<size_t>(index)] = 1;
    const tinygltf::Node& node = model_.nodes[static_cast<size_t>(index)];
    stack.insert(stack.end(), node.children.rbegin(), node.children.rend());
    if (node.mesh < 0 || static_cast<size_t>(node.mesh) >= model_.meshes.size()) continue;
    if (const auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
        ext != node.extensions.end() && ext->second.Has("attributes") &&
        ext->second.Get("attributes").IsObject()) {  // each count fits its bufferView
      const tinygltf::Value& attributes = ext->second.Get("attributes");
      const std::string what = "node " + std::to_string(index) + " EXT_mesh_gpu_instancing ";
      const std::pair<const char*, int> kinds[3] = {{"TRANSLATION", TINYGLTF_TYPE_VEC3},
                                                    {"ROTATION", TINYGLTF_TYPE_VEC4},
                                                    {"SCALE", TINYGLTF_TYPE_VEC3}};
      for (const auto& [name, type] : kinds)
        if (attributes.Has(name) && attributes.Get(name).IsInt())
          MFR_TRY(checkAccessor(attributes.Get(name).GetNumberAsInt(), type, what + name));
    }
    const uint64_t instances = instanceCount(model_, node);
    // translation, rotation and scale read as doubles
    transient = std::max(transient, saturatingMul(instances, 10 * sizeof(double)));
    const tinygltf::Mesh& mesh = model_.meshes[static_cast<size_t>(node.mesh)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& primitive = mesh.primitives[p];
      const std::string what = "mesh " + std::to_string(node.mesh) + " (" +
                               quoteInput(mesh.name, 60) + ") primitive " + std::to_string(p);
      const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
      const auto position = primitive.attributes.find("POSITION");
      if ((mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
           mode != TINYGLTF_MODE_TRIANGLE_FAN) ||
          position == primitive.attributes.end())
        continue;
      // a count the file cannot hold is that error, not a memory one (as addPrimitive reads it)
      MFR_TRY(checkAccessor(position->second, TINYGLTF_TYPE_VEC3, what + " POSITION"));
      if (primitive.indices >= 0)
        MFR_TRY(checkAccessor(primitive.indices, TINYGLTF_TYPE_SCALAR, what + " indices"));
      const std::optional<uint64_t> v = accessorCount(position->second);
      if (!v) continue;
      const uint64_t corners =
          primitive.indices >= 0 ? accessorCount(primitive.indices).value_or(0) : *v;
      const uint64_t t =
          mode == TINYGLTF_MODE_TRIANGLES ? corners / 3 : (corners > 2 ? corners - 2 : 0);
      vertices = saturatingAdd(vertices, saturatingMul(*v, instances));
      triangles = saturatingAdd(triangles, saturatingMul(t, instances));
      // addPrimitive's read-out: position, normal, uv and colour as doubles, the indices as doubles
      // and twice as 32-bit corners
      transient = std::max(transient, saturatingAdd(saturatingMul(*v, (3 + 3 + 2 + 7) * 8),
                                                    saturatingMul(corners, 8 + 4 + 4)));
    }
  }
  const uint64_t needed = saturatingAdd(sceneMemoryBytes(vertices, triangles), transient);
  if (auto fits =
          checkMemory(needed, memoryLimit_,
                      "the " + std::to_string(vertices) + " vertices and " +
                          std::to_string(triangles) + " triangles its nodes and instances place");
      !fits)
    return fail(fits.error().message);
  if (vertices > std::numeric_limits<uint32_t>::max())
    return fail("more than 2^32 vertices in the scene (" + std::to_string(vertices) +
                " after node references and instancing)");
  scene_.positions.reserve(vertices);
  scene_.normals.reserve(vertices);
  scene_.uvs.reserve(vertices);
  scene_.colors.reserve(vertices);
  scene_.indices.reserve(saturatingMul(triangles, 3));
  scene_.triangleMaterial.reserve(triangles);
  return {};
}

/// Walks the chosen scene's node trees (iteratively: depth is not bounded by the stack). The glTF
/// node hierarchy must be disjoint strict trees, so a node reached twice (cycle or shared child)
/// makes the file invalid.
Result<void> GltfSceneBuilder::visitNodes() {
  auto roots = rootNodes();
  if (!roots) return roots.error();
  std::vector<char> visited(model_.nodes.size(), 0);
  std::vector<std::pair<int, glm::dmat4>> stack;
  for (auto it = roots->rbegin(); it != roots->rend(); ++it)
    stack.emplace_back(*it, glm::dmat4(1.0));
  while (!stack.empty()) {
    const auto [index, parent] = stack.back();
    stack.pop_back();
    if (index < 0 || static_cast<size_t>(index) >= model_.nodes.size())
      return fail("node " + std::to_string(index) + " does not exist");
    if (visited[static_cast<size_t>(index)])
      return fail("node " + std::to_string(index) + " appears twice in the node hierarchy");
    visited[static_cast<size_t>(index)] = 1;
    const tinygltf::Node& node = model_.nodes[static_cast<size_t>(index)];
    const glm::dmat4 world = parent * localTransform(node);
    if (node.mesh >= 0) MFR_TRY(addMeshInstances(node, index, world));
    if (node.camera >= 0) cameraNodes_.emplace_back(node.camera, world);
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
      stack.emplace_back(*it, world);
  }
  return {};
}

/// A node's mesh, once, or once per instance of EXT_mesh_gpu_instancing: instance i is the
/// node's world transform times T(i) R(i) S(i) from the TRANSLATION, ROTATION (unit quaternions,
/// possibly normalized integers) and SCALE accessors, each optional, all of one count.
Result<void> GltfSceneBuilder::addMeshInstances(const tinygltf::Node& node, int nodeIndex,
                                                const glm::dmat4& world) {
  // before any instance is read: checkExpansion counted no instances for a mesh that is not there
  if (static_cast<size_t>(node.mesh) >= model_.meshes.size())
    return fail("mesh " + std::to_string(node.mesh) + " does not exist");
  // the mesh is read once, when the first instance is placed (after that instance's checks), and
  // placed per instance: their vertices and triangles were checked against the memory limit
  // (checkExpansion)
  std::optional<std::vector<PrimitiveData>> mesh;
  const auto place = [&](const glm::dmat4& transform) -> Result<void> {
    if (!mesh) {
      auto read = readMesh(node.mesh);
      if (!read) return read.error();
      mesh = std::move(*read);
    }
    return placeMesh(*mesh, transform);
  };
  const auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == node.extensions.end() || !ext->second.Has("attributes") ||
      !ext->second.Get("attributes").IsObject())
    return place(world);
  const tinygltf::Value& attributes = ext->second.Get("attributes");
  const std::string what = "node " + std::to_string(nodeIndex) + " EXT_mesh_gpu_instancing";
  std::vector<double> values[3];  // translation, rotation, scale
  const char* names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  const int types[3] = {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4, TINYGLTF_TYPE_VEC3};
  std::optional<size_t> count;
  for (int a = 0; a < 3; ++a) {
    if (!attributes.Has(names[a])) continue;
    const tinygltf::Value& accessor = attributes.Get(names[a]);
    if (!accessor.IsInt()) return fail(what + " " + names[a] + ": must be an accessor index");
    auto read = readAccessor(accessor.GetNumberAsInt(), types[a], what + " " + names[a]);
    if (!read) return read.error();
    const size_t n = read->size() / (a == 1 ? 4 : 3);
    if (count && *count != n)
      return fail(what + ": " + names[a] + " has " + std::to_string(n) +
                  " instances, another attribute " + std::to_string(*count));
    count = n;
    values[a] = std::move(*read);
  }
  if (!count) return place(world);
  for (size_t i = 0; i < *count; ++i) {
    glm::dmat4 instance(1.0);
    if (!values[0].empty())
      instance = glm::translate(
          instance, glm::dvec3(values[0][3 * i], values[0][3 * i + 1], values[0][3 * i + 2]));
    if (!values[1].empty()) {
      const glm::dquat q(values[1][4 * i + 3], values[1][4 * i], values[1][4 * i + 1],
                         values[1][4 * i + 2]);  // stored x, y, z, w
      if (!(glm::length(q) > 0.0))
        return fail(what + ": ROTATION " + std::to_string(i) + " is not a unit quaternion");
      instance *= glm::mat4_cast(glm::normalize(q));
    }
    if (!values[2].empty())
      instance = glm::scale(
          instance, glm::dvec3(values[2][3 * i], values[2][3 * i + 1], values[2][3 * i + 2]));
    MFR_TRY(place(world * instance));
  }
  return {};
}

// `meshIndex` exists: addMeshInstances checked it
Result<std::vector<PrimitiveData>> GltfSceneBuilder::readMesh(int meshIndex) {
  const tinygltf::Mesh& mesh = model_.meshes[static_cast<size_t>(meshIndex)];
  std::vector<PrimitiveData> primitives;
  primitives.reserve(mesh.primitives.size());
  for (size_t p = 0; p < mesh.primitives.size(); ++p) {
    const std::string what = "mesh " + std::to_string(meshIndex) + " (" +
                             quoteInput(mesh.name, 60) + ") primitive " + std::to_string(p);
    auto read = readPrimitive(mesh.primitives[p], what);
    if (!read) return read.error();
    primitives.push_back(std::move(*read));
  }
  return primitives;
}

/// Triangle list for a triangle, strip or fan primitive (glTF section 3.7.2.1); empty otherwise.
std::vector<uint32_t> triangulate(int mode, const std::vector<uint32_t>& v) {
  std::vector<uint32_t> out;
  const size_t n = v.size();
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    out.assign(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n - n % 3));
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 0; i + 2 < n; ++i) {
      const bool odd = i % 2 == 1;
      out.insert(out.end(), {v[i], v[i + (odd ? 2 : 1)], v[i + (odd ? 1 : 2)]});
    }
  } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (size_t i = 0; i + 2 < n; ++i) out.insert(out.end(), {v[i + 1], v[i + 2], v[0]});
  }
  return out;
}

Result<PrimitiveData> GltfSceneBuilder::readPrimitive(const tinygltf::Primitive& primitive,
                                                      const std::string& what) {
  PrimitiveData out;
  out.what = what;
  const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    out.skipped = true;  // points and lines are not surfaces: counted, not rendered
    return out;
  }
  const auto position = primitive.attributes.find("POSITION");
  if (position == primitive.attributes.end()) return out;  // nothing to draw

  auto positions = readAccessor(position->second, TINYGLTF_TYPE_VEC3, what + " POSITION");
  if (!positions) return positions.error();
  const size_t vertexCount = positions->size() / 3;

  std::vector<double> normals;
  if (auto it = primitive.attributes.find("NORMAL"); it != primitive.attributes.end()) {
    auto read = readAccessor(it->second, TINYGLTF_TYPE_VEC3, what + " NORMAL");
    if (!read) return read.error();
    if (read->size() != positions->size()) return fail(what + ": NORMAL count differs");
    normals = std::move(*read);
  }

  // The texture coordinate set the base colour texture uses (TEXCOORD_0 unless it says otherwise,
  // KHR_texture_transform's texCoord over the texture's) and the extension's transform.
  UvTransform transform;
  if (primitive.material >= 0 &&
      static_cast<size_t>(primitive.material) < model_.materials.size()) {
    auto read = baseColorUvTransform(primitive.material);
    if (!read) return read.error();
    transform = *read;
  }
  const int texCoord = transform.texCoord;
  std::vector<double> uvs;
  const std::string uvName = "TEXCOORD_" + std::to_string(texCoord);
  if (auto it = primitive.attributes.find(uvName); it != primitive.attributes.end()) {
    auto read = readAccessor(it->second, TINYGLTF_TYPE_VEC2, what + " " + uvName);
    if (!read) return read.error();
    if (read->size() / 2 != vertexCount) return fail(what + ": " + uvName + " count differs");
    uvs = std::move(*read);
  }

  std::vector<double> colors;  // COLOR_0: linear RGBA, alpha 1 when the accessor is VEC3
  if (auto it = primitive.attributes.find("COLOR_0"); it != primitive.attributes.end()) {
    auto read = readColors(it->second, vertexCount, what + " COLOR_0");
    if (!read) return read.error();
    colors = std::move(*read);
  }

  std::vector<uint32_t> corners;
  if (primitive.indices >= 0) {
    auto read = readAccessor(primitive.indices, TINYGLTF_TYPE_SCALAR, what + " indices");
    if (!read) return read.error();
    const int type = model_.accessors[static_cast<size_t>(primitive.indices)].componentType;
    if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      return fail(what + ": indices must be unsigned integers");
    corners.reserve(read->size());
    for (double i : *read) {
      if (i >= static_cast<double>(vertexCount))
        return fail(what + ": vertex index " + std::to_string(static_cast<uint64_t>(i)) +
                    " out of range (" + std::to_string(vertexCount) + " vertices)");
      corners.push_back(static_cast<uint32_t>(i));
    }
  } else {
    corners.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i) corners[i] = static_cast<uint32_t>(i);
  }
  out.triangles = triangulate(mode, corners);
  out.positions = std::move(*positions);
  out.normals = std::move(normals);
  out.uvs = std::move(uvs);
  out.colors = std::move(colors);
  out.transform = transform;
  if (!out.triangles.empty()) out.material = materialIndex(primitive.material);  // as used
  return out;
}

Result<void> GltfSceneBuilder::placeMesh(const std::vector<PrimitiveData>& mesh,
                                         const glm::dmat4& world) {
  // Geometry to world space; normals by the inverse transpose; mirrored transforms flip winding
  // so that counter-clockwise stays front-facing.
  const double det = glm::determinant(glm::dmat3(world));
  const bool singular = !(std::abs(det) > 1e-300) || !std::isfinite(det);  // e.g. scale 0
  const glm::dmat3 normalMatrix =
      singular ? glm::dmat3(1.0) : glm::transpose(glm::inverse(glm::dmat3(world)));
  const bool mirrored = det < 0.0;
  for (const PrimitiveData& primitive : mesh) {
    if (primitive.skipped) ++scene_.primitivesSkipped;
    if (primitive.triangles.empty()) continue;
    const std::vector<double>& normals = primitive.normals;
    const std::vector<double>& uvs = primitive.uvs;
    const std::vector<double>& colors = primitive.colors;
    const size_t vertexCount = primitive.positions.size() / 3;
    const size_t base = scene_.positions.size();
    if (vertexCount > std::numeric_limits<uint32_t>::max() - base)
      return fail(primitive.what + ": more than 2^32 vertices in the scene");
    for (size_t i = 0; i < vertexCount; ++i) {
      const glm::dvec3 p = glm::make_vec3(primitive.positions.data() + 3 * i);
      scene_.positions.emplace_back(glm::vec3(world * glm::dvec4(p, 1.0)));
      if (!normals.empty()) {
        const glm::dvec3 n = normalMatrix * glm::make_vec3(normals.data() + 3 * i);
        const double length = glm::length(n);
        scene_.normals.emplace_back(length > 0.0 ? glm::vec3(n / length) : glm::vec3(n));
      } else {
        scene_.normals.emplace_back(0.0f);  // filled from the faces below
      }
      scene_.uvs.emplace_back(uvs.empty() ? glm::vec2(0.0f)
                                          : primitive.transform.apply(uvs[2 * i], uvs[2 * i + 1]));
      scene_.colors.emplace_back(colors.empty() ? glm::vec4(1.0f)
                                                : glm::vec4(static_cast<float>(colors[4 * i]),
                                                            static_cast<float>(colors[4 * i + 1]),
                                                            static_cast<float>(colors[4 * i + 2]),
                                                            static_cast<float>(colors[4 * i + 3])));
    }
    anyUvs_ = anyUvs_ || !uvs.empty();
    anyColors_ = anyColors_ || !colors.empty();

    const std::vector<uint32_t>& triangles = primitive.triangles;
    for (size_t t = 0; t < triangles.size(); t += 3) {
      const uint32_t a = static_cast<uint32_t>(base) + triangles[t];
      uint32_t b = static_cast<uint32_t>(base) + triangles[t + 1];
      uint32_t c = static_cast<uint32_t>(base) + triangles[t + 2];
      if (mirrored) std::swap(b, c);
      scene_.indices.insert(scene_.indices.end(), {a, b, c});
      scene_.triangleMaterial.push_back(primitive.material);
      if (normals.empty()) {  // area-weighted vertex normals of this primitive
        const glm::vec3 n = glm::cross(scene_.positions[b] - scene_.positions[a],
                                       scene_.positions[c] - scene_.positions[a]);
        scene_.normals[a] += n;
        scene_.normals[b] += n;
        scene_.normals[c] += n;
      }
    }
    if (normals.empty()) {
      for (size_t i = base; i < scene_.normals.size(); ++i) {
        const float length = glm::length(scene_.normals[i]);
        scene_.normals[i] = (length > 0.0f && std::isfinite(length)) ? scene_.normals[i] / length
                                                                     : glm::vec3(0.0f, 0.0f, 1.0f);
      }
    }
  }
  return {};
}

/// Scene material for a glTF material index; missing or invalid indices get the glTF default
/// material (white, opaque).
uint32_t GltfSceneBuilder::materialIndex(int gltfMaterial) {
  if (gltfMaterial < 0 || static_cast<size_t>(gltfMaterial) >= model_.materials.size())
    gltfMaterial = -1;
  if (auto it = materialMap_.find(gltfMaterial); it != materialMap_.end()) return it->second;

  Material material;
  material.name = "default";
  material.alphaMode = AlphaMode::Opaque;
  material.doubleSided = false;  // glTF's default material is single-sided
  if (gltfMaterial >= 0) {
    const tinygltf::Material& src = model_.materials[static_cast<size_t>(gltfMaterial)];
    material.name = src.name;
    const auto& factor = src.pbrMetallicRoughness.baseColorFactor;
    if (factor.size() == 4)
      material.baseColor = glm::vec4(static_cast<float>(factor[0]), static_cast<float>(factor[1]),
                                     static_cast<float>(factor[2]), static_cast<float>(factor[3]));
    material.baseColorTexture = textureIndex(src.pbrMetallicRoughness.baseColorTexture.index);
    if (material.baseColorTexture >= 0)
      material.baseColorSampler = samplerOf(src.pbrMetallicRoughness.baseColorTexture.index);
    if (src.alphaMode == "MASK")
      material.alphaMode = AlphaMode::Mask;
    else if (src.alphaMode == "BLEND")
      material.alphaMode = AlphaMode::Blend;
    material.alphaCutoff = static_cast<float>(src.alphaCutoff);
    material.doubleSided = src.doubleSided;
    if (auto ext = src.extensions.find("KHR_materials_transmission"); ext != src.extensions.end()) {
      double transmission = 0.0;
      if (ext->second.Has("transmissionFactor") && ext->second.Get("transmissionFactor").IsNumber())
        transmission = ext->second.Get("transmissionFactor").GetNumberAsDouble();
      const float t = std::clamp(static_cast<float>(transmission), 0.0f, 1.0f);
      material.transmission = t;
      material.baseColor.a *= std::max(options_.transmissionAlphaFloor, 1.0f - t);
      material.alphaMode = AlphaMode::Blend;
    }
  }
  const auto index = static_cast<uint32_t>(scene_.materials.size());
  scene_.materials.push_back(std::move(material));
  materialMap_.emplace(gltfMaterial, index);
  return index;
}

/// Reserves a scene texture slot for a glTF texture's image (decoded later), or -1.
int GltfSceneBuilder::textureIndex(int gltfTexture) {
  if (gltfTexture < 0 || static_cast<size_t>(gltfTexture) >= model_.textures.size()) return -1;
  const int image = model_.textures[static_cast<size_t>(gltfTexture)].source;
  if (image < 0 || static_cast<size_t>(image) >= model_.images.size()) return -1;
  if (auto it = imageMap_.find(image); it != imageMap_.end()) return it->second;
  const int index = static_cast<int>(imageMap_.size());
  imageMap_.emplace(image, index);
  return index;
}

/// The glTF samplers as mfr samples: wrapS and wrapT (REPEAT 10497, CLAMP_TO_EDGE 33071,
/// MIRRORED_REPEAT 33648; absent: REPEAT) and the filter, magFilter's (NEAREST 9728, LINEAR 9729;
/// absent: linear). minFilter is checked (9728, 9729, 9984-9987) but not used: mfr takes one sample
/// per fragment without derivatives and keeps no mip-maps (docs/GLTF.md). Any other value is an
/// error naming the sampler.
Result<void> GltfSceneBuilder::readSamplers() {
  for (size_t i = 0; i < model_.samplers.size(); ++i) {
    const tinygltf::Sampler& src = model_.samplers[i];
    const std::string what = "sampler " + std::to_string(i) +
                             (src.name.empty() ? "" : " (" + quoteInput(src.name) + ")");
    auto wrap = [&](int value, const char* field) -> Result<TextureWrap> {
      switch (value) {
        case -1:
        case 10497:
          return TextureWrap::Repeat;
        case 33071:
          return TextureWrap::ClampToEdge;
        case 33648:
          return TextureWrap::MirroredRepeat;
        default:
          return fail(what + ": " + field + " " + std::to_string(value) +
                      " is not REPEAT (10497), CLAMP_TO_EDGE (33071) or MIRRORED_REPEAT (33648)");
      }
    };
    auto wrapS = wrap(src.wrapS, "wrapS");
    if (!wrapS) return wrapS.error();
    auto wrapT = wrap(src.wrapT, "wrapT");
    if (!wrapT) return wrapT.error();
    TextureSampler sampler{*wrapS, *wrapT, TextureFilter::Linear};
    if (src.magFilter == 9728)
      sampler.filter = TextureFilter::Nearest;
    else if (src.magFilter != -1 && src.magFilter != 9729)
      return fail(what + ": magFilter " + std::to_string(src.magFilter) +
                  " is not NEAREST (9728) or LINEAR (9729)");
    if (src.minFilter != -1 && src.minFilter != 9728 && src.minFilter != 9729 &&
        (src.minFilter < 9984 || src.minFilter > 9987))
      return fail(what + ": minFilter " + std::to_string(src.minFilter) +
                  " is not NEAREST (9728), LINEAR (9729) or a mipmap filter (9984-9987)");
    samplers_.push_back(sampler);
  }
  return {};
}

/// The sampler of a glTF texture (readSamplers), the glTF default without one.
TextureSampler GltfSceneBuilder::samplerOf(int gltfTexture) const {
  if (gltfTexture < 0 || static_cast<size_t>(gltfTexture) >= model_.textures.size()) return {};
  const int sampler = model_.textures[static_cast<size_t>(gltfTexture)].sampler;
  if (sampler < 0 || static_cast<size_t>(sampler) >= samplers_.size()) return {};
  return samplers_[static_cast<size_t>(sampler)];
}

uint8_t toByte(const tinygltf::Image& image, size_t component) {
  if (image.bits == 16) {
    uint16_t v;
    std::memcpy(&v, image.image.data() + 2 * component, 2);
    return static_cast<uint8_t>((v * 255u + 32767u) / 65535u);
  }
  return image.image[component];
}

/// RGBA8 copy of a decoded image with 1 (grey), 2 (grey, alpha), 3 or 4 channels of 8 or 16 bits.
Result<Texture> toRgba8(const tinygltf::Image& image) {
  const int channels = image.component;
  if (image.width <= 0 || image.height <= 0 || channels < 1 || channels > 4 ||
      (image.bits != 8 && image.bits != 16))
    return makeError("unsupported image layout");
  const size_t pixels = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  if (image.image.size() < pixels * static_cast<size_t>(channels) * (image.bits / 8))
    return makeError("truncated image data");
  Texture texture;
  texture.width = image.width;
  texture.height = image.height;
  texture.rgba.resize(pixels * 4);
  for (size_t i = 0; i < pixels; ++i) {
    const size_t src = i * static_cast<size_t>(channels);
    uint8_t* dst = texture.rgba.data() + 4 * i;
    if (channels <= 2) {
      dst[0] = dst[1] = dst[2] = toByte(image, src);
      dst[3] = channels == 2 ? toByte(image, src + 1) : 255;
    } else {
      for (size_t c = 0; c < 3; ++c) dst[c] = toByte(image, src + c);
      dst[3] = channels == 4 ? toByte(image, src + 3) : 255;
    }
  }
  return texture;
}

/// Decodes the images that base colour textures use, in parallel, with stb_image.
Result<void> GltfSceneBuilder::decodeTextures() {
  std::vector<int> images(imageMap_.size());
  for (const auto& [image, slot] : imageMap_) images[static_cast<size_t>(slot)] = image;
  const auto nameOf = [&](size_t imageIndex) {
    const tinygltf::Image& source = model_.images[imageIndex];
    return "image " + std::to_string(imageIndex) +
           (source.uri.empty() ? "" : " (" + quoteInput(source.uri, 80) + ")");
  };
  // Headers first: every image's size against the cap, all of them against the memory limit
  // (decoded 8 or 16 bits per channel, then the RGBA8 copy), before anything is decoded.
  uint64_t decodeBytes = 0;
  for (const int image : images) {
    const auto imageIndex = static_cast<size_t>(image);
    if (imageIndex >= images_.bytes.size() || images_.bytes[imageIndex].empty()) continue;
    const std::vector<unsigned char>& bytes = images_.bytes[imageIndex];
    if (auto chunks = checkPngChunks(bytes.data(), bytes.size(), nameOf(imageIndex)); !chunks)
      return fail(chunks.error().message);  // before stb allocates what a chunk declares
    if (auto data = checkImageData(bytes.data(), bytes.size(), nameOf(imageIndex)); !data)
      return fail(data.error().message);  // a truncated file: refused before any decoding
    int width = 0, height = 0, channels = 0;
    if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max()) ||
        !stbi_info_from_memory(bytes.data(), static_cast<int>(bytes.size()), &width, &height,
                               &channels))
      continue;  // the decoder reports it
    if (auto fits = checkImageDimensions(width, height, nameOf(imageIndex)); !fits)
      return fail(fits.error().message);
    decodeBytes = saturatingAdd(
        decodeBytes, saturatingMul(static_cast<uint64_t>(width) * static_cast<uint64_t>(height),
                                   4 + 2 * static_cast<uint64_t>(std::max(channels, 1))));
  }
  if (auto fits = checkMemory(decodeBytes, memoryLimit_, "its decoded textures"); !fits)
    return fail(fits.error().message);

  std::vector<Result<Texture>> decoded(images.size(), makeError(""));
  tbb::parallel_for(size_t{0}, images.size(), [&](size_t i) {
    const auto imageIndex = static_cast<size_t>(images[i]);
    const std::string name = nameOf(imageIndex);
    if (imageIndex >= images_.bytes.size() || images_.bytes[imageIndex].empty()) {
      decoded[i] = fail(name + " could not be read");
      return;
    }
    const std::vector<unsigned char>& bytes = images_.bytes[imageIndex];
    // stb_image as tinygltf's LoadImageData calls it (RGBA, 16 bits kept), through callbacks that
    // never let a read past the end reach a texture
    auto pixels = decodeImageUnchecked(bytes.data(), bytes.size(), name, true);
    if (!pixels) {
      decoded[i] = fail(pixels.error().message);
      return;
    }
    tinygltf::Image image;
    image.width = pixels->width;
    image.height = pixels->height;
    image.component = 4;
    image.bits = pixels->bits;
    image.image = std::move(pixels->bytes);
    auto texture = toRgba8(image);
    decoded[i] =
        texture ? std::move(texture) : Result<Texture>(fail(name + ": " + texture.error().message));
  });
  for (auto& texture : decoded) {
    if (!texture) return texture.error();
    scene_.textures.push_back(std::move(*texture));
  }
  return {};
}

/// The file's cameras in the file's order (glTF `cameras`): --view N is camera N, as `mfr info`
/// lists them. A perspective camera is placed by the first node of the scene that names it: eye at
/// the node origin looking down its -Z axis with +Y up; the target is put on the view axis at the
/// depth of the scene centre so that orbits around it (see orbit()) circle the scene. Orthographic
/// cameras and cameras no node of the scene places keep a placeholder and a reason in
/// Scene::cameraProblems: --view refuses them (fileCamera, scene_request.hpp) rather than picking
/// another.
Result<void> GltfSceneBuilder::addCameras() {
  const Bounds bounds = sceneBounds(scene_);
  std::vector<const glm::dmat4*> placement(model_.cameras.size(), nullptr);
  for (const auto& [cameraIndex, world] : cameraNodes_)  // node order: the first node wins
    if (cameraIndex >= 0 && static_cast<size_t>(cameraIndex) < placement.size() &&
        !placement[static_cast<size_t>(cameraIndex)])
      placement[static_cast<size_t>(cameraIndex)] = &world;
  bool anyProblem = false;
  std::vector<std::string> problems(model_.cameras.size());
  for (size_t i = 0; i < model_.cameras.size(); ++i) {
    const tinygltf::Camera& src = model_.cameras[i];
    const std::string name = "camera " + std::to_string(i);
    Camera camera;  // a placeholder where --view refuses the camera
    std::string& problem = problems[i];
    if (src.type != "perspective") {
      problem = "is " + quoteInput(src.type, 40) + " (mfr renders perspective cameras only)";
    } else {
      // glTF 2.0 section 5.13: yfov > 0 (and below pi, a half-space at most)
      const double yfov = src.perspective.yfov;
      char value[32];
      std::snprintf(value, sizeof value, "%g", yfov);
      if (!(yfov > 0.0 && yfov < glm::pi<double>()))
        return fail(name + ": perspective.yfov " + value + " must be in (0, pi) radians");
      if (!validFovYDegrees(glm::degrees(yfov)))
        return fail(name + ": perspective.yfov " + value + " radians is narrower than " +
                    kMinFovText + " (" + kNarrowFovReason + ")");
      std::snprintf(value, sizeof value, "%g", src.perspective.znear);
      if (!(src.perspective.znear <= kMaxNearPlane))
        return fail(name + ": perspective.znear " + value +
                    " is beyond 1e18 (the projection's 2 far near would overflow single "
                    "precision)");
      if (!placement[i]) problem = "is placed by no node of the scene";
    }
    if (problem.empty()) {
      const glm::dmat4& world = *placement[i];
      const glm::vec3 eye(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
      glm::dvec3 forward = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
      glm::dvec3 up = glm::dmat3(world) * glm::dvec3(0.0, 1.0, 0.0);
      if (!(glm::length(forward) > 0.0) || !(glm::length(up) > 0.0)) {
        problem = "is placed by a node whose transform collapses its view axes";
      } else {
        forward = glm::normalize(forward);
        up = glm::normalize(up);
        camera.eye = eye;
        float depth = glm::dot(bounds.center() - eye, glm::vec3(forward));
        if (!(depth > 1e-6f)) depth = std::max(bounds.radius(), 1.0f);
        camera.target = eye + glm::vec3(forward) * depth;
        camera.up = glm::vec3(up);
        camera.fovYDegrees = static_cast<float>(glm::degrees(src.perspective.yfov));
        camera.zNear = static_cast<float>(std::max(0.0, src.perspective.znear));
        // 0: infinite (fitted); beyond single precision: clamped to maxFarPlane by fitClipPlanes
        camera.zFar = static_cast<float>(std::clamp(
            src.perspective.zfar, 0.0, static_cast<double>(std::numeric_limits<float>::max())));
      }
    }
    if (!problem.empty() && !src.name.empty()) problem = quoteInput(src.name, 40) + " " + problem;
    anyProblem = anyProblem || !problem.empty();
    scene_.cameras.push_back(camera);
  }
  if (anyProblem) scene_.cameraProblems = std::move(problems);
  return {};
}

Result<Scene> GltfSceneBuilder::build() {
  scene_.name = path_;
  for (const std::string& extension : model_.extensionsRequired)  // checkReferences, too
    if (!isImplementedExtension(extension))
      return fail("requires extension " + quoteInput(extension) + ", which mfr does not implement");
  MFR_TRY(readSamplers());
  MFR_TRY(checkExpansion());
  MFR_TRY(visitNodes());
  MFR_TRY(decodeTextures());
  if (!anyUvs_) std::vector<glm::vec2>().swap(scene_.uvs);  // freed, not only emptied
  if (!anyColors_) std::vector<glm::vec4>().swap(scene_.colors);
  MFR_TRY(addCameras());
  MFR_TRY(validateScene(scene_));
  return std::move(scene_);
}

}  // namespace

Result<Scene> loadGltf(const std::string& path, const OpenFile& file, const LoadOptions& options) {
  try {
    GltfFiles files;
    files.path = path;
    files.allowOutside = options.allowOutsideReferences;
    const uint64_t limit = options.memoryLimitBytes.value_or(defaultMemoryLimit());
    // tinygltf takes the file's length and image sizes as 32-bit integers
    files.maxFileBytes = std::min<uint64_t>(limit, std::numeric_limits<int>::max());
    auto bytes = file.read(std::min<uint64_t>(limit, UINT32_MAX));
    if (!bytes) return bytes.error();
    if (bytes->empty()) return makeError(path + ": empty file");
    if (startsWithGlbMagic(*bytes))
      if (auto glb = checkGlb(*bytes); !glb) return makeError(path + ": " + glb.error().message);
    auto doc = gltfJson(*bytes);
    if (!doc) return makeError(path + ": " + doc.error().message);
    if (auto checked = checkReferences(*doc, files); !checked)
      return makeError(path + ": " + checked.error().message);

    tinygltf::Model model;
    EncodedImages images;
    images.model = &model;
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&keepEncodedImage, &images);
    loader.SetFsCallbacks(tinygltf::FsCallbacks{&gltfFileExists, &gltfExpandFilePath,
                                                &gltfReadWholeFile, &gltfWriteWholeFile, &files});
    std::string err, warn;
    const std::string baseDir = baseDirOf(path);
    const auto size = static_cast<unsigned int>(bytes->size());
    const bool ok =
        startsWithGlbMagic(*bytes)
            ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes->data(), size, baseDir)
            : loader.LoadASCIIFromString(
                  &model, &err, &warn, reinterpret_cast<const char*>(bytes->data()), size, baseDir);
    if (!ok) {
      const std::string reason = firstLine(err);
      return makeError(path + ": " + (reason.empty() ? "invalid glTF file" : oneLine(reason, 300)));
    }
    return GltfSceneBuilder(model, images, path, options).build();
  } catch (const std::bad_alloc&) {
    return makeError(path + ": out of memory");
  } catch (const std::exception& e) {
    return makeError(path + ": " + e.what());
  }
}

}  // namespace mfr
