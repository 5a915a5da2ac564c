// Scene source dispatch (include/mfr/scene/load.hpp): "procedural:SPEC" goes to the procedural
// scenes, files go to the loader for their (case-insensitive) extension. Every scene handed out
// has vertex normals, passes validateScene and is named after the source string.
#include "mfr/scene/load.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "mfr/core/file_access.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/scene/procedural.hpp"

namespace mfr {

namespace {

constexpr const char* kProceduralPrefix = "procedural:";

std::string lowercaseExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

Result<Scene> loadFile(const std::string& path, const LoadOptions& options) {
  // stat, not open: a FIFO or device named as the scene is refused instead of blocking the open
  if (auto regular = checkRegularFile(path, path); !regular) return regular.error();
  if (::access(path.c_str(), R_OK) != 0) return makeError(path + ": cannot be read");

  const std::string extension = lowercaseExtension(path);
  if (extension == ".gltf" || extension == ".glb") return loadGltf(path, options);
  if (extension == ".obj") return loadObj(path, options);
  if (extension == ".ply") return loadPly(path, options);
  if (extension == ".json") return loadJsonScene(path, options);
  return makeError(path + ": unsupported scene format " +
                   (extension.empty() ? "(no extension)" : "'" + extension + "'") +
                   " (expected .gltf, .glb, .obj, .ply, .json)");
}

}  // namespace

Result<Scene> loadScene(const std::string& source, const LoadOptions& options) {
  const std::string prefix = kProceduralPrefix;
  Result<Scene> loaded = source.rfind(prefix, 0) == 0
                             ? makeProceduralScene(source.substr(prefix.size()), options.seed,
                                                   options.maxProceduralTriangles)
                             : loadFile(source, options);
  if (!loaded) {  // make sure the message names the source (procedural errors may not)
    const std::string& message = loaded.error().message;
    // one line whatever the source and the file hold (a name or a key may contain newlines)
    if (message.find(source) == std::string::npos)
      return makeError(oneLine(source, 200) + ": " + oneLine(message));
    return makeError(oneLine(message));
  }
  Scene scene = std::move(*loaded);
  scene.name = source;
  computeVertexNormals(scene);
  MFR_TRY(validateScene(scene));
  return scene;
}

}  // namespace mfr
