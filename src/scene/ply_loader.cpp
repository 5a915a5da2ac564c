// Stanford PLY loader (ASCII and binary) on top of assimp, restricted to assimp's PLY importer:
// the file is read into memory and handed to assimp with the "ply" format hint, so no other
// importer ever looks at it. Triangulated, identical vertices joined; node transforms applied;
// file normals used when every mesh has them (otherwise computed); vertex colours ignored.
// PLY has no materials: everything gets one opaque light-grey material.
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

glm::mat4 toGlm(const aiMatrix4x4& m) {
  return glm::transpose(glm::make_mat4(&m.a1));  // assimp matrices are row-major
}

struct PlyBuilder {
  const aiScene& ai;
  Scene scene;
  bool allNormals = true;

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
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      scene.positions.emplace_back(world * glm::vec4(p.x, p.y, p.z, 1.0f));
      if (mesh.mNormals) {
        const aiVector3D& n = mesh.mNormals[v];
        const glm::vec3 normal = normalMatrix * glm::vec3(n.x, n.y, n.z);
        const float length = glm::length(normal);
        scene.normals.push_back(length > 0.0f ? normal / length : normal);
      }
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      bool valid = true;
      for (unsigned k = 0; k < 3; ++k) valid = valid && face.mIndices[k] < mesh.mNumVertices;
      if (!valid) continue;
      for (unsigned k = 0; k < 3; ++k) scene.indices.push_back(base + face.mIndices[k]);
      scene.triangleMaterial.push_back(0);
    }
  }
};

}  // namespace

Result<Scene> loadPly(const std::string& path, const LoadOptions& /*options*/) {
  try {
    std::ifstream in(path, std::ios::binary);
    if (!in) return makeError(path + ": cannot be read");
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
    if (bytes.empty()) return makeError(path + ": empty file");

    Assimp::Importer importer;
    // assimp's PLY importer does not check face indices against the vertex count (a truncated
    // binary file yields garbage indices), so the data structure is validated before any other
    // post-processing step touches it.
    const aiScene* ai = importer.ReadFileFromMemory(
        bytes.data(), bytes.size(),
        aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices,
        "ply");
    if (!ai || !ai->mRootNode) {
      const std::string reason = importer.GetErrorString();
      return makeError(path + ": " + (reason.empty() ? "invalid PLY file" : reason));
    }

    PlyBuilder builder{*ai, {}};
    builder.scene.name = path;
    uint64_t vertices = 0;
    for (unsigned m = 0; m < ai->mNumMeshes; ++m)
      if (ai->mMeshes[m]) vertices += ai->mMeshes[m]->mNumVertices;
    if (vertices > std::numeric_limits<uint32_t>::max())
      return makeError(path + ": more than 2^32 vertices");
    builder.visit(*ai->mRootNode, glm::mat4(1.0f), 0);
    Scene& scene = builder.scene;
    if (!builder.allNormals) scene.normals.clear();

    Material material;
    material.name = "default";
    material.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    material.alphaMode = AlphaMode::Opaque;
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
