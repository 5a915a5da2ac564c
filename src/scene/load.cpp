// Scene source dispatch (include/mfr/scene/load.hpp): "procedural:SPEC" goes to the procedural
// scenes, files go to the loader for their (case-insensitive) extension. Every scene handed out
// has vertex normals, passes validateScene and is named after the source string.
#include "mfr/scene/load.hpp"

#include <filesystem>

#include "file_loaders.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/scene/procedural.hpp"

namespace mfr {

namespace {

constexpr const char* kProceduralPrefix = "procedural:";
/// However much of its input a loader or library quotes, an error stays a readable line.
constexpr size_t kMaxMessage = 1000;

Result<Scene> loadFile(const std::string& path, const LoadOptions& options) {
  // opened once, non-blocking: a FIFO or device named as the scene is refused on the descriptor
  auto file = openRegularFile(path, path);
  if (!file) return file.error();
  return loadOpenFile(path, *file, options);
}

}  // namespace

Result<Scene> loadOpenFile(const std::string& path, const OpenFile& file,
                           const LoadOptions& options) {
  const std::string extension = lowercaseExtension(path);
  if (extension == ".gltf" || extension == ".glb") return loadGltf(path, file, options);
  if (options.sceneIndex)
    return makeError(path + ": scene " + std::to_string(*options.sceneIndex) +
                     ": only glTF files hold several scenes");
  if (extension == ".obj") return loadObj(path, file, options);
  if (extension == ".ply") return loadPly(path, file, options);
  if (extension == ".json") return loadJsonScene(path, file, options);
  return makeError(path + ": unsupported scene format " +
                   (extension.empty() ? "(no extension)" : quoteInput(extension, 20)) +
                   " (expected .gltf, .glb, .obj, .ply, .json)");
}

namespace {

/// A public loader: the file opened once, then read from the descriptor by `load`.
template <Result<Scene> (*load)(const std::string&, const OpenFile&, const LoadOptions&)>
Result<Scene> openAndLoad(const std::string& path, const LoadOptions& options) {
  auto file = openRegularFile(path, path);
  return file ? load(path, *file, options) : Result<Scene>(file.error());
}

}  // namespace

Result<Scene> loadGltf(const std::string& path, const LoadOptions& options) {
  return openAndLoad<loadGltf>(path, options);
}
Result<Scene> loadObj(const std::string& path, const LoadOptions& options) {
  return openAndLoad<loadObj>(path, options);
}
Result<Scene> loadPly(const std::string& path, const LoadOptions& options) {
  return openAndLoad<loadPly>(path, options);
}
Result<Scene> loadJsonScene(const std::string& path, const LoadOptions& options) {
  return openAndLoad<loadJsonScene>(path, options);
}

Result<Scene> loadScene(const std::string& source, const LoadOptions& options) {
  const std::string prefix = kProceduralPrefix;
  if (options.sceneIndex && source.rfind(prefix, 0) == 0)
    return makeError(echoPath(source) + ": scene " + std::to_string(*options.sceneIndex) +
                     ": only glTF files hold several scenes");
  Result<Scene> loaded =
      source.rfind(prefix, 0) == 0
          ? makeProceduralScene(source.substr(prefix.size()), options.seed,
                                options.maxProceduralTriangles, options.memoryLimitBytes)
          : loadFile(source, options);
  if (!loaded) {  // make sure the message names the source (procedural errors may not)
    std::string message = loaded.error().message;
    if (message.find(source) == std::string::npos)
      return makeError(echoPath(source) + ": " + oneLine(message, kMaxMessage));
    // a source of any length (a Python string, a generated path) is shortened where the loader
    // echoed it, so that the problem after it survives the cut below
    if (const std::string shortened = echoPath(source); source.size() > 256)
      for (size_t at = message.find(source); at != std::string::npos;
           at = message.find(source, at + shortened.size()))
        message.replace(at, source.size(), shortened);
    // one line whatever the source and the file hold (a name or a key may contain newlines)
    return makeError(oneLine(message, kMaxMessage));
  }
  Scene scene = std::move(*loaded);
  scene.name = source;
  computeVertexNormals(scene);
  MFR_TRY(validateScene(scene));
  return scene;
}

}  // namespace mfr
