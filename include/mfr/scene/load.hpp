// Scene sources: a file (glTF 2.0 .gltf/.glb, Wavefront .obj + .mtl, .ply, or a small JSON scene
// file) or a built-in procedural scene named "procedural:NAME[?key=value&...]".
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "mfr/core/result.hpp"
#include "mfr/scene/procedural.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

struct LoadOptions {
  /// KHR_materials_transmission: alpha = max(transmissionAlphaFloor, 1 - transmissionFactor), so
  /// perfectly clear glass (factor 1) stays visible as a faint layer.
  float transmissionAlphaFloor = 0.1f;
  /// Seed for procedural scenes (a `seed=` parameter in the spec overrides it).
  uint64_t seed = 1;
  /// Procedural scenes whose parameters produce more triangles are refused (the fuzzers lower it
  /// to keep every input fast; see makeProceduralScene).
  double maxProceduralTriangles = kMaxProceduralTriangles;
  /// Files named inside a scene file (glTF buffers and images, OBJ mtllib and map_Kd, a JSON
  /// scene's mesh) must be regular files inside the naming file's folder (subfolders allowed):
  /// absolute paths, `..` escapes and symbolic links leading outside are refused before anything
  /// is opened (mfr/core/file_access.hpp). True lifts the folder rule (CLI
  /// `--allow-outside-references`); FIFOs, devices and other non-regular files stay refused.
  bool allowOutsideReferences = false;
  /// Memory pre-flight for what a source makes the loader allocate: decoded textures, and the
  /// scene it expands into (sceneMemoryBytes of its vertices and triangles after glTF node
  /// references, instancing and procedural parameters), checked before it is built; none:
  /// defaultMemoryLimit() (mfr/core/memory_limit.hpp).
  std::optional<uint64_t> memoryLimitBytes;
  /// glTF: which of the file's scenes (`--scene N`); none: the file's `scene`, else its first.
  /// Another format, or an index the file does not have, is an error.
  std::optional<int> sceneIndex;
};

/// Loads a scene from a file path or a procedural spec: "procedural:NAME[?key=value&...]"
/// (procedural.hpp), else by the file's extension (case-insensitive): .gltf / .glb (loadGltf),
/// .obj (loadObj, with its .mtl), .ply (loadPly), .json (loadJsonScene, a scene file naming a
/// mesh). The returned Scene owns all its data (textures decoded, node transforms applied; nothing
/// refers back to the file), has Scene::name = `source`, and has passed validateScene. Errors (one
/// line naming `source`): a missing, unreadable or non-regular file (a FIFO or device is refused
/// without being opened), a refused reference (see allowOutsideReferences), a texture larger than
/// kMaxImageDimension (file_access.hpp), an unsupported extension, a malformed file, an unknown
/// procedural scene or parameter, a scene without triangles, non-finite vertices or out-of-range
/// indices. Reentrant: scenes may be loaded on several threads at once.
Result<Scene> loadScene(const std::string& source, const LoadOptions& options = {});

// Individual loaders (dispatched on by loadScene from the file extension), with loadScene's
// guarantees and errors for their format.
Result<Scene> loadGltf(const std::string& path, const LoadOptions& options);
Result<Scene> loadObj(const std::string& path, const LoadOptions& options);
Result<Scene> loadPly(const std::string& path, const LoadOptions& options);
Result<Scene> loadJsonScene(const std::string& path, const LoadOptions& options);

}  // namespace mfr
