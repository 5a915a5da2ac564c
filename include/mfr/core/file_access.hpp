// Reading files that other people made. Every file mfr reads is opened once, non-blocking (a FIFO
// would block the open forever), and checked on the open descriptor to be a regular file (a device
// can be endless); nothing is re-opened by name after a check. Files named from inside a scene
// file (glTF buffers and images, OBJ mtllib and texture maps, a JSON scene's mesh) must be regular
// files inside the referencing file's folder: absolute paths and `..` escapes are refused before
// anything is opened, and a file whose opened path (symbolic links followed) lies outside is
// refused before a byte of it is read, unless the caller allows references outside the folder
// (LoadOptions::allowOutsideReferences, `--allow-outside-references`), which never allows
// non-regular files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
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

/// Reads a whole regular file: openRegularFile, then OpenFile::read (refused before reading when
/// it is larger than `maxBytes`).
Result<std::string> readRegularFile(const std::filesystem::path& path, const std::string& what,
                                    uint64_t maxBytes = std::numeric_limits<uint64_t>::max());
Result<std::vector<unsigned char>> readRegularFileBytes(
    const std::filesystem::path& path, const std::string& what,
    uint64_t maxBytes = std::numeric_limits<uint64_t>::max());

/// A file opened once: every check (regular file, inside the folder, size) is made on this
/// descriptor, and the bytes are read from it, so a name swapped on disk between the check and
/// the read (for a symbolic link, a FIFO, another file) can never be read unchecked.
class OpenFile {
 public:
  OpenFile(int fd, std::filesystem::path path, uint64_t size, std::string what)
      : fd_(fd), path_(std::move(path)), size_(size), what_(std::move(what)) {}
  OpenFile(OpenFile&& other) noexcept;
  OpenFile& operator=(OpenFile&&) = delete;
  OpenFile(const OpenFile&) = delete;
  ~OpenFile();

  /// Where the kernel resolved the name (canonical, symbolic links followed).
  const std::filesystem::path& path() const { return path_; }
  /// The size fstat gave for the open file.
  uint64_t size() const { return size_; }
  /// All of the file; refused before reading when it is larger than `maxBytes`.
  Result<std::vector<unsigned char>> read(
      uint64_t maxBytes = std::numeric_limits<uint64_t>::max()) const;
  Result<std::string> readText(uint64_t maxBytes = std::numeric_limits<uint64_t>::max()) const;

 private:
  int fd_ = -1;
  std::filesystem::path path_;
  uint64_t size_ = 0;
  std::string what_;
};

/// Opens a file the user named (non-blocking, so a FIFO cannot block the open) and checks on the
/// descriptor that it is a regular file. Errors as checkRegularFile's.
Result<OpenFile> openRegularFile(const std::filesystem::path& path, const std::string& what);

/// Opens `reference`, a file named inside `referencingFile`, exactly once. Relative references
/// resolve against the referencing file's folder, opened first as a descriptor: the reference is
/// opened relative to it (openat, non-blocking). Unless `allowOutside`: an absolute reference and
/// one that leaves the folder lexically (`..`) are refused without touching the file system, and
/// the file the kernel opened (its path in /proc/self/fd, symbolic links followed) must lie inside
/// the folder the folder descriptor names. Always: the open file must be a regular file.
/// Errors are "<what>: <problem>", `what` naming the reference (e.g. "buffer 0 uri 'a.bin'").
Result<OpenFile> openReference(const std::filesystem::path& referencingFile,
                               const std::string& reference, const std::string& what,
                               bool allowOutside);

/// Whether an error of checkRegularFile, openRegularFile or openReference says that the file does
/// not exist (as opposed to a refusal or a read error).
bool isNoSuchFileError(const Error& error);

/// The extension of `path`'s file name in lower case, dot included (".gltf" for "Scene.GLTF"),
/// or "" when it has none: what the loaders and the image writers choose a format by.
std::string lowercaseExtension(const std::filesystem::path& path);

/// Checks an image header's dimensions against kMaxImageDimension and kMaxImagePixels.
Result<void> checkImageDimensions(int width, int height, const std::string& what);

}  // namespace mfr
