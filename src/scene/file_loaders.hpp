// The file loaders on a file opened once (mfr/core/file_access.hpp: every check on its
// descriptor, the bytes read from it). loadScene opens the file the user named, a JSON scene
// opens its mesh relative to its own folder; both hand the open file to loadOpenFile, which
// dispatches on the extension of `path` (the name errors use).
#pragma once

#include <string>

#include "mfr/core/file_access.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {

Result<Scene> loadOpenFile(const std::string& path, const OpenFile& file,
                           const LoadOptions& options);

Result<Scene> loadGltf(const std::string& path, const OpenFile& file, const LoadOptions& options);
Result<Scene> loadObj(const std::string& path, const OpenFile& file, const LoadOptions& options);
Result<Scene> loadPly(const std::string& path, const OpenFile& file, const LoadOptions& options);
Result<Scene> loadJsonScene(const std::string& path, const OpenFile& file,
                            const LoadOptions& options);

}  // namespace mfr
