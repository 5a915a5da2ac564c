// Stanford PLY loader (ASCII and binary) on top of assimp, restricted to assimp's PLY importer:
// the file is read into memory and handed to assimp with the "ply" format hint, so no other
// importer ever looks at it. Polygons split by polygon.hpp (assimp's Triangulate step aborted the
// process on some files), identical vertices joined; node transforms applied;
// file normals used when every mesh has them (otherwise computed). PLY has no materials: everything
// gets one material, opaque light grey; with vertex colours (red, green, blue [, alpha]: uchar
// 0-255 or float 0-1, which assimp hands over as floats in [0, 1]) it is white and the colours
// are the surface's: red, green and blue are display values, sRGB-encoded (the convention of
// 8-bit PLY colours from scanners and tools), decoded to linear here; alpha is linear, and any
// alpha below 1 makes the material blended (docs/GLTF.md, "Other formats").
//
// assimp 5.2's PLY importer crashes or spins on malformed files (truncated bodies, corrupted
// headers, huge element counts, out-of-range face indices), so every file is first checked
// against the PLY format (http://paulbourke.net/dataformats/ply/) by PlyChecker below, and
// assimp only ever sees structurally valid files.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "file_loaders.hpp"
#include "mfr/core/color.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/memory_limit.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/scene/load.hpp"
#include "polygon.hpp"

namespace mfr {
namespace {

// ---------------------------------------------------------------------------------------------
// PLY structure check.

enum class PlyFormat { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyType {
  int size = 0;  // bytes; 0: unknown type name
  bool integral = false;
  bool isSigned = false;
};

struct PlyProperty {
  std::string name;
  PlyType type;       // of the scalar, or of each list item
  PlyType countType;  // list properties only (size 0 for scalars)
  bool isList() const { return countType.size > 0; }
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

PlyType plyType(const std::string& name) {
  if (name == "char" || name == "int8") return {1, true, true};
  if (name == "uchar" || name == "uint8") return {1, true, false};
  if (name == "short" || name == "int16") return {2, true, true};
  if (name == "ushort" || name == "uint16") return {2, true, false};
  if (name == "int" || name == "int32") return {4, true, true};
  if (name == "uint" || name == "uint32") return {4, true, false};
  if (name == "float" || name == "float32") return {4, false, true};
  if (name == "double" || name == "float64") return {8, false, true};
  return {};
}

bool isFaceIndexList(const PlyElement& element, const PlyProperty& property) {
  return element.name == "face" && property.isList() &&
         (property.name == "vertex_indices" || property.name == "vertex_index");
}

/// assimp reads triangle strips (element "tristrips", -1 restarts a strip) as faces too, from an
/// integer list of whatever name; an index out of range makes it leak the faces it built.
bool isStripIndexList(const PlyElement& element, const PlyProperty& property) {
  return element.name == "tristrips" && property.isList() && property.type.integral;
}

/// An integer of the given type in the file's byte order, widened to 64 bits.
int64_t readInteger(const unsigned char* p, const PlyType& type, bool bigEndian) {
  uint64_t v = 0;
  for (int i = 0; i < type.size; ++i)
    v |= uint64_t{p[bigEndian ? i : type.size - 1 - i]} << (8 * (type.size - 1 - i));
  const int bits = 8 * type.size;
  if (type.isSigned && bits < 64 && (v >> (bits - 1)) != 0) v |= ~uint64_t{0} << bits;
  return static_cast<int64_t>(v);
}

class PlyChecker {
 public:
  static constexpr size_t kMaxHeaderLines = 10000;

  explicit PlyChecker(std::string_view bytes) : bytes_(bytes) {}

  /// "" when the file is a well-formed PLY file with in-range face indices, else the problem.
  std::string check() {
    if (std::string problem = parseHeader(); !problem.empty()) return problem;
    return format_ == PlyFormat::Ascii ? checkAsciiBody() : checkBinaryBody();
  }

 private:
  bool nextLine(std::string_view& line) {
    if (pos_ >= bytes_.size()) return false;
    const char* begin = bytes_.data() + pos_;
    const void* newline = std::memchr(begin, '\n', bytes_.size() - pos_);
    const size_t length = newline ? static_cast<size_t>(static_cast<const char*>(newline) - begin)
                                  : bytes_.size() - pos_;
    pos_ += length + (newline ? 1 : 0);
    line = std::string_view(begin, length);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return true;
  }

  static bool startsLikeAName(const std::string& word) {
    const unsigned char c = word.empty() ? 0 : static_cast<unsigned char>(word[0]);
    return std::isalpha(c) || c == '_';
  }

  static std::vector<std::string> words(std::string_view line) {
    std::istringstream in{std::string(line)};
    std::vector<std::string> out;
    for (std::string word; in >> word;) out.push_back(word);
    return out;
  }

  std::string parseHeader() {
    std::string_view line;
    if (!nextLine(line) || line != "ply") return "not a PLY file (no 'ply' magic line)";
    bool haveFormat = false;
    for (size_t lines = 1;; ++lines) {
      if (!nextLine(line)) return "PLY header has no end_header line";
      // assimp moves the rest of the header for every line it reads (quadratic): 200,000 lines
      // take it 11 s; real headers have a few dozen
      if (lines > kMaxHeaderLines)
        return "PLY header has more than " + std::to_string(kMaxHeaderLines) + " lines";
      // assimp's tokenizer stops at a NUL and splits words differently on other control
      // characters: a header it would read otherwise than this check is refused
      for (char c : line)
        if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f)
          return "PLY header line " + quoteInput(line, 40) + " has a control character";
      const std::vector<std::string> w = words(line);
      if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
      if (w[0] == "end_header") break;
      if (w[0] == "format") {
        // assimp and this check would read different formats (and assimp leaks on it)
        if (haveFormat) return "PLY header has a second format line";
        if (w.size() != 3 || w[2] != "1.0") return "bad PLY format line";
        if (w[1] == "ascii")
          format_ = PlyFormat::Ascii;
        else if (w[1] == "binary_little_endian")
          format_ = PlyFormat::BinaryLittleEndian;
        else if (w[1] == "binary_big_endian")
          format_ = PlyFormat::BinaryBigEndian;
        else
          return "unknown PLY format " + quoteInput(w[1], 40);
        haveFormat = true;
      } else if (w[0] == "element") {
        char* end = nullptr;
        if (w.size() != 3) return "bad PLY element line";
        if (!startsLikeAName(w[1]))  // assimp reads a long name of digits as a count (45 GB)
          return "PLY element name " + quoteInput(w[1], 40) + " must start with a letter or '_'";
        const unsigned long long count = std::strtoull(w[2].c_str(), &end, 10);
        if (*end != '\0' || w[2][0] == '-' || count > std::numeric_limits<uint32_t>::max())
          return "bad PLY element count " + quoteInput(w[2], 40);
        // assimp fills the first element of a name with the data of all of them (a heap
        // overflow when a later "vertex" element is larger): names must be unique
        if (!elementNames_.insert(w[1]).second)  // a hash set: linear in the header
          return "PLY element " + quoteInput(w[1]) + " is declared twice";
        elements_.push_back({w[1], count, {}});
      } else if (w[0] == "property") {
        if (elements_.empty()) return "PLY property before any element";
        PlyProperty property;
        if (w.size() == 5 && w[1] == "list") {
          property = {w[4], plyType(w[3]), plyType(w[2])};
          if (!property.countType.integral || property.type.size == 0)
            return "bad PLY list property";
        } else if (w.size() == 3) {
          property = {w[2], plyType(w[1]), {}};
          if (property.type.size == 0) return "unknown PLY property type " + quoteInput(w[1], 40);
        } else {
          return "bad PLY property line";
        }
        if (!startsLikeAName(property.name))
          return "PLY property name " + quoteInput(property.name, 40) +
                 " must start with a letter or '_'";
        elements_.back().properties.push_back(property);
      } else {
        return "unknown PLY header line " + quoteInput(line, 40);
      }
    }
    if (!haveFormat) return "PLY header has no format line";
    bool x = false, y = false, z = false;
    for (const PlyElement& element : elements_) {
      if (element.name == "vertex") {
        vertexCount_ = element.count;
        for (const PlyProperty& p : element.properties) {
          x = x || (p.name == "x" && !p.isList());
          y = y || (p.name == "y" && !p.isList());
          z = z || (p.name == "z" && !p.isList());
        }
      }
      if (element.name == "face")
        for (const PlyProperty& p : element.properties)
          if (isFaceIndexList(element, p) && !p.type.integral)
            return "PLY face indices are not integers";
    }
    if (!(x && y && z)) return "PLY file has no vertex element with x, y, z";
    return {};
  }

  std::string faceProblem(int64_t count, const std::vector<int64_t>& indices) const {
    if (count < 3) return "PLY face with fewer than 3 vertices";
    for (int64_t index : indices)
      if (index < 0 || static_cast<uint64_t>(index) >= vertexCount_)
        return "PLY face index " + std::to_string(index) + " out of range (" +
               std::to_string(vertexCount_) + " vertices)";
    return {};
  }

  std::string stripProblem(const std::vector<int64_t>& indices) const {
    for (int64_t index : indices)
      if (index < -1 || (index >= 0 && static_cast<uint64_t>(index) >= vertexCount_))
        return "PLY triangle strip index " + std::to_string(index) + " out of range (" +
               std::to_string(vertexCount_) + " vertices, -1 restarts a strip)";
    return {};
  }

  /// What is wrong with the indices of a face or strip list ("" for other lists, and valid ones).
  std::string indexProblem(const PlyElement& element, const PlyProperty& property, int64_t count,
                           const std::vector<int64_t>& indices) const {
    if (isFaceIndexList(element, property)) return faceProblem(count, indices);
    if (isStripIndexList(element, property)) return stripProblem(indices);
    return {};
  }

  std::string checkBinaryBody() {
    const bool bigEndian = format_ == PlyFormat::BinaryBigEndian;
    const auto* data = reinterpret_cast<const unsigned char*>(bytes_.data());
    const size_t size = bytes_.size();
    const std::string truncated = "PLY file is truncated";
    std::vector<int64_t> indices;
    for (const PlyElement& element : elements_) {
      for (uint64_t item = 0; item < element.count; ++item) {
        for (const PlyProperty& property : element.properties) {
          const auto itemSize = static_cast<size_t>(property.type.size);
          if (!property.isList()) {
            if (size - pos_ < itemSize) return truncated;
            pos_ += itemSize;
            continue;
          }
          const auto countSize = static_cast<size_t>(property.countType.size);
          if (size - pos_ < countSize) return truncated;
          const int64_t count = readInteger(data + pos_, property.countType, bigEndian);
          pos_ += countSize;
          if (count < 0) return "negative PLY list count";
          if (static_cast<uint64_t>(count) > (size - pos_) / itemSize) return truncated;
          if (isFaceIndexList(element, property) || isStripIndexList(element, property)) {
            indices.clear();
            for (size_t i = 0; i < static_cast<size_t>(count); ++i)
              indices.push_back(readInteger(data + pos_ + i * itemSize, property.type, bigEndian));
            if (std::string problem = indexProblem(element, property, count, indices);
                !problem.empty())
              return problem;
          }
          pos_ += static_cast<size_t>(count) * itemSize;
        }
      }
    }
    return {};
  }

  std::string checkAsciiBody() {
    std::string_view line;
    std::vector<int64_t> indices;
    for (const PlyElement& element : elements_) {
      for (uint64_t item = 0; item < element.count; ++item) {
        do {
          if (!nextLine(line)) return "PLY file is truncated (element '" + element.name + "')";
        } while (line.find_first_not_of(" \t") == std::string_view::npos);
        size_t next = 0;  // cursor in `line`
        // The next whitespace-separated token of the line, parsed as a number.
        auto number = [&](double* value) {
          next = line.find_first_not_of(" \t", next);
          if (next == std::string_view::npos) return false;
          size_t end = line.find_first_of(" \t", next);
          if (end == std::string_view::npos) end = line.size();
          const char* first = line.data() + next + (line[next] == '+' ? 1 : 0);
          const char* last = line.data() + end;
          next = end;
          const auto [ptr, ec] = std::from_chars(first, last, *value);
          return ec == std::errc() && ptr == last;
        };
        for (const PlyProperty& property : element.properties) {
          double value = 0.0;
          if (!property.isList()) {
            if (!number(&value)) return "bad PLY " + element.name + " line";
            continue;
          }
          if (!number(&value) || value < 0 || value != std::floor(value) || value > 1e6)
            return "bad PLY list count in " + element.name + " line";
          const auto count = static_cast<int64_t>(value);
          indices.clear();
          for (int64_t i = 0; i < count; ++i) {
            if (!number(&value)) return "bad PLY " + element.name + " line";
            indices.push_back(value == std::floor(value) && std::abs(value) < 1e18
                                  ? static_cast<int64_t>(value)
                                  : std::numeric_limits<int64_t>::min());  // never valid
          }
          if (std::string problem = indexProblem(element, property, count, indices);
              !problem.empty())
            return problem;
        }
        if (line.find_first_not_of(" \t", next) != std::string_view::npos)
          return "bad PLY " + element.name + " line (extra values)";
      }
    }
    return {};
  }

  std::string_view bytes_;
  size_t pos_ = 0;
  PlyFormat format_ = PlyFormat::Ascii;
  std::vector<PlyElement> elements_;
  std::unordered_set<std::string> elementNames_;
  uint64_t vertexCount_ = 0;
};

/// Moves the header's comment and obj_info lines up to just after the format line, in place (the
/// header keeps its length, the body its offset). PLY allows them anywhere in the header, but
/// assimp's reader ends an element's property list at a comment and then refuses the file for the
/// wrong reason ("Vertices should be declared before faces"). Only for a file PlyChecker passed:
/// "ply" first, one format line, an end_header line within kMaxHeaderLines.
void hoistHeaderComments(std::string& bytes) {
  std::string_view format;  // every line with its line end
  std::vector<std::string_view> comments, others;
  bool elementSeen = false, commentAfterElement = false;
  for (size_t pos = 0; pos < bytes.size();) {
    const size_t newline = bytes.find('\n', pos);
    const size_t end = newline == std::string::npos ? bytes.size() : newline + 1;
    const std::string_view line(bytes.data() + pos, end - pos);
    pos = end;
    const size_t first = line.find_first_not_of(" \t");
    const std::string_view word =
        first == std::string_view::npos
            ? std::string_view()
            : line.substr(first, line.find_first_of(" \t\r\n", first) - first);
    if (others.empty()) {
      others.push_back(line);  // "ply"
    } else if (word == "comment" || word == "obj_info") {
      comments.push_back(line);
      commentAfterElement = commentAfterElement || elementSeen;
    } else if (word == "format" && format.empty()) {
      format = line;
    } else {
      elementSeen = elementSeen || word == "element";
      others.push_back(line);
    }
    if (word == "end_header") break;
  }
  if (!commentAfterElement) return;
  std::string header;
  header.append(others.front()).append(format);
  for (std::string_view line : comments) header.append(line);
  for (size_t i = 1; i < others.size(); ++i) header.append(others[i]);
  std::memcpy(bytes.data(), header.data(), header.size());  // the same lines: the same length
}

// ---------------------------------------------------------------------------------------------

glm::mat4 toGlm(const aiMatrix4x4& m) {
  return glm::transpose(glm::make_mat4(&m.a1));  // assimp matrices are row-major
}

/// A PLY vertex colour as assimp delivers it (uchar / 255 or the file's float) to linear RGBA:
/// RGB sRGB-decoded (8-bit codes exactly by the decode table), alpha as stored.
glm::vec4 plyColor(const aiColor4D& c) {
  auto channel = [](float v) {
    const float clamped = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    const float code = clamped * 255.0f;
    if (std::abs(code - std::round(code)) < 1e-3f)
      return decodeSrgb8(static_cast<uint8_t>(std::lround(code)));
    return srgbToLinear(clamped);
  };
  const float alpha = std::isfinite(c.a) ? std::clamp(c.a, 0.0f, 1.0f) : 1.0f;
  return {channel(c.r), channel(c.g), channel(c.b), alpha};
}

struct PlyBuilder {
  const aiScene& ai;
  Scene scene;
  bool allNormals = true;
  bool anyColors = false;
  std::string error;  // the first face that cannot be triangulated

  void visit(const aiNode& node, const glm::mat4& parent, unsigned depth) {
    const glm::mat4 world = parent * toGlm(node.mTransformation);
    const glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(world)));
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      if (node.mMeshes[i] >= ai.mNumMeshes || !ai.mMeshes[node.mMeshes[i]]) continue;
      addMesh(*ai.mMeshes[node.mMeshes[i]], world, normalMatrix);
    }
    if (depth > 64) return;  // assimp's PLY importer makes a single node; never deep
    for (unsigned i = 0; i < node.mNumChildren; ++i)
      if (node.mChildren[i]) visit(*node.mChildren[i], world, depth + 1);
  }

  void addMesh(const aiMesh& mesh, const glm::mat4& world, const glm::mat3& normalMatrix) {
    const auto base = static_cast<uint32_t>(scene.positions.size());
    allNormals = allNormals && mesh.mNormals != nullptr;
    const aiColor4D* colors = mesh.mColors[0];
    if (colors && !anyColors) scene.colors.assign(base, glm::vec4(1.0f));
    anyColors = anyColors || colors != nullptr;
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      scene.positions.emplace_back(world * glm::vec4(p.x, p.y, p.z, 1.0f));
      if (anyColors) scene.colors.push_back(colors ? plyColor(colors[v]) : glm::vec4(1.0f));
      if (mesh.mNormals) {
        const aiVector3D& n = mesh.mNormals[v];
        const glm::vec3 normal = normalMatrix * glm::vec3(n.x, n.y, n.z);
        const float length = glm::length(normal);
        scene.normals.push_back(length > 0.0f ? normal / length : normal);
      }
    }
    // Polygons are split here (polygon.hpp), not by assimp's Triangulate step, which aborts the
    // process on some files (an ai_assert in TriangulateProcess.cpp, found by fuzz_ply).
    std::vector<glm::vec3> corners;
    std::vector<uint32_t> triangles;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices < 3 || !face.mIndices) continue;  // points and lines
      bool valid = true;
      corners.clear();
      for (unsigned k = 0; k < face.mNumIndices && valid; ++k) {
        valid = face.mIndices[k] < mesh.mNumVertices;
        if (valid) corners.push_back(scene.positions[base + face.mIndices[k]]);
      }
      if (!valid) continue;
      triangles.clear();
      if (auto split = triangulatePolygon(corners, triangles); !split) {
        if (error.empty()) error = "face " + std::to_string(f) + ": " + split.error().message;
        continue;
      }
      for (size_t t = 0; t < triangles.size(); ++t) {
        scene.indices.push_back(base + face.mIndices[triangles[t]]);
        if (t % 3 == 2) scene.triangleMaterial.push_back(0);
      }
    }
  }
};

}  // namespace

Result<Scene> loadPly(const std::string& path, const OpenFile& file, const LoadOptions& options) {
  try {
    auto read = file.readText(options.memoryLimitBytes.value_or(defaultMemoryLimit()));
    if (!read) return read.error();
    std::string& bytes = *read;
    if (bytes.empty()) return makeError(path + ": empty file");
    if (std::string problem = PlyChecker(bytes).check(); !problem.empty())
      return makeError(path + ": " + problem);
    hoistHeaderComments(bytes);

    Assimp::Importer importer;
    // Belt and braces: assimp validates its own output before the other post-processing steps.
    const aiScene* ai = importer.ReadFileFromMemory(
        bytes.data(), bytes.size(),
        aiProcess_ValidateDataStructure | aiProcess_JoinIdenticalVertices, "ply");
    if (!ai || !ai->mRootNode) {
      std::string reason = importer.GetErrorString();
      if (reason.find("bad_alloc") != std::string::npos) reason = "out of memory";  // assimp's
      return makeError(path + ": " + (reason.empty() ? "invalid PLY file" : reason));
    }

    PlyBuilder builder{*ai, {}, true, false, {}};
    builder.scene.name = path;
    uint64_t vertices = 0;
    for (unsigned m = 0; m < ai->mNumMeshes; ++m)
      if (ai->mMeshes[m]) vertices += ai->mMeshes[m]->mNumVertices;
    if (vertices > std::numeric_limits<uint32_t>::max())
      return makeError(path + ": more than 2^32 vertices");
    builder.visit(*ai->mRootNode, glm::mat4(1.0f), 0);
    if (!builder.error.empty()) return makeError(path + ": " + builder.error);
    Scene& scene = builder.scene;
    if (!builder.allNormals) scene.normals.clear();

    Material material;
    material.name = "default";
    material.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    material.alphaMode = AlphaMode::Opaque;
    if (builder.anyColors) {  // the vertex colours are the surface's colour
      material.baseColor = glm::vec4(1.0f);
      for (const glm::vec4& c : scene.colors)
        if (c.a < 1.0f) material.alphaMode = AlphaMode::Blend;
    }
    scene.materials.push_back(material);

    computeVertexNormals(scene);
    MFR_TRY(validateScene(scene));
    return std::move(scene);
  } catch (const std::bad_alloc&) {
    return makeError(path + ": out of memory");
  } catch (const std::exception& e) {
    return makeError(path + ": " + e.what());
  }
}

}  // namespace mfr
