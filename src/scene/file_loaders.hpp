// The file loaders on a file opened once (mfr/core/file_access.hpp: every check on its
// descriptor, the bytes read from it). loadScene opens the file the user named, a JSON scene
// opens its mesh relative to its own folder; both hand the open file to loadOpenFile, which
// dispatches on the extension of `path` (the name errors use).
#pragma once

#include <string>

#include "mfr/core/file_access.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {

Result<Scene> loadOpenFile(const std::string& path, const OpenFile& file,
                           const LoadOptions& options);

Result<Scene> loadGltf(const std::string& path, const OpenFile& file, const LoadOptions& options);
Result<Scene> loadObj(const std::string& path, const OpenFile& file, const LoadOptions& options);
Result<Scene> loadPly(const std::string& path, const OpenFile& file, const LoadOptions& options);
Result<Scene> loadJsonScene(const std::string& path, const OpenFile& file,
                            const LoadOptions& options);

/// nlohmann::json's parse error as "JSON error: parse error at line L, column C: ...", without
/// its "[json.exception.parse_error.101] " prefix, on one line of bounded length.
inline std::string jsonErrorText(const std::string& what) {
  const size_t close = what.find("] ");
  const bool prefixed = what.rfind("[json.exception.", 0) == 0 && close != std::string::npos;
  return "JSON error: " + oneLine(prefixed ? what.substr(close + 2) : what, 200);
}

}  // namespace mfr
