// Scene sources: a file (glTF 2.0 .gltf/.glb, Wavefront .obj + .mtl, .ply, or a small JSON scene
// file) or a built-in procedural scene named "procedural:NAME[?key=value&...]".
#pragma once

#include <cstdint>
#include <string>

#include "mfr/core/result.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

struct LoadOptions {
  /// KHR_materials_transmission: alpha = max(transmissionAlphaFloor, 1 - transmissionFactor), so
  /// perfectly clear glass (factor 1) stays visible as a faint layer.
  float transmissionAlphaFloor = 0.1f;
  /// Seed for procedural scenes (a `seed=` parameter in the spec overrides it).
  uint64_t seed = 1;
};

/// Loads a scene from a file path or a procedural spec. Errors name the input.
Result<Scene> loadScene(const std::string& source, const LoadOptions& options = {});

// Individual loaders (dispatched on by loadScene from the file extension).
Result<Scene> loadGltf(const std::string& path, const LoadOptions& options);
Result<Scene> loadObj(const std::string& path, const LoadOptions& options);
Result<Scene> loadPly(const std::string& path, const LoadOptions& options);
Result<Scene> loadJsonScene(const std::string& path, const LoadOptions& options);

}  // namespace mfr
