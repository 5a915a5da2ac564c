// Reading files that other people made. Every file mfr reads is first checked, without opening it,
// to be a regular file (a FIFO would block the open forever, a device can be endless), and files
// named from inside a scene file (glTF buffers and images, OBJ mtllib and texture maps, a JSON
// scene's mesh) must resolve to regular files inside the referencing file's folder: absolute
// paths, `..` escapes and symbolic links leading outside are refused before anything is opened,
// unless the caller allows references outside the folder (LoadOptions::allowOutsideReferences,
// `--allow-outside-references`), which never allows non-regular files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"

namespace mfr {

/// Images read from any file (textures, `mfr metrics` inputs) are refused when their header
/// declares more than this many pixels per side, or more than kMaxImagePixels in all, before
/// they are decoded.
inline constexpr int kMaxImageDimension = 16384;
inline constexpr uint64_t kMaxImagePixels = uint64_t{kMaxImageDimension} * kMaxImageDimension;

/// Checks with stat (not open) that `path` is a regular file, symbolic links followed, and returns
/// its size. Errors name `what`: "<what>: no such file", "... is a directory", "... is a FIFO
/// (named pipe), not a regular file", "... is a device, not a regular file", "... is a socket,
/// ...".
Result<uint64_t> checkRegularFile(const std::filesystem::path& path, const std::string& what);

/// Reads a whole regular file: checkRegularFile first, then the file is opened non-blocking and
/// checked again on the open descriptor (so a file swapped for a FIFO in between cannot block),
/// and refused before reading when it is larger than `maxBytes`.
Result<std::string> readRegularFile(const std::filesystem::path& path, const std::string& what,
                                    uint64_t maxBytes = std::numeric_limits<uint64_t>::max());
Result<std::vector<unsigned char>> readRegularFileBytes(
    const std::filesystem::path& path, const std::string& what,
    uint64_t maxBytes = std::numeric_limits<uint64_t>::max());

/// Resolves `reference`, a file named inside `referencingFile`, to the canonical path of a
/// regular file. Relative references resolve against the referencing file's folder. Unless
/// `allowOutside`: an absolute reference, a reference that leaves the folder lexically (`..`),
/// and one whose canonical path (symbolic links followed) lies outside the folder's canonical
/// path are refused; the first two without touching the file system. Always: the file must exist
/// and be a regular file (checked with stat before anything opens it).
/// Errors are "<what>: <problem>", `what` naming the reference (e.g. "buffer 0 uri 'a.bin'").
Result<std::filesystem::path> resolveReference(const std::filesystem::path& referencingFile,
                                               const std::string& reference,
                                               const std::string& what, bool allowOutside);

/// Whether an error of checkRegularFile or resolveReference says that the file does not exist
/// (as opposed to a refusal or a read error).
bool isNoSuchFileError(const Error& error);

/// Checks an image header's dimensions against kMaxImageDimension and kMaxImagePixels.
Result<void> checkImageDimensions(int width, int height, const std::string& what);

}  // namespace mfr
