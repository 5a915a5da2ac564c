// Confined, non-blocking file access (see mfr/core/file_access.hpp).
#include "mfr/core/file_access.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace mfr {
namespace {

namespace fs = std::filesystem;

/// Why a stat result is not a regular file ("" when it is one).
std::string notRegular(const struct stat& st) {
  if (S_ISREG(st.st_mode)) return {};
  if (S_ISDIR(st.st_mode)) return "is a directory";
  if (S_ISFIFO(st.st_mode)) return "is a FIFO (named pipe), not a regular file";
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) return "is a device, not a regular file";
  if (S_ISSOCK(st.st_mode)) return "is a socket, not a regular file";
  return "is not a regular file";
}

template <class Buffer>
Result<Buffer> readWhole(const fs::path& path, const std::string& what, uint64_t maxBytes) {
  auto size = checkRegularFile(path, what);
  if (!size) return size.error();
  // O_NONBLOCK: should the path have become a FIFO since the stat, the open returns at once and
  // the fstat below refuses it.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return makeError(what + ": cannot be read (" + std::strerror(errno) + ")");
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    return makeError(what + ": cannot be read (" + std::strerror(errno) + ")");
  if (const std::string problem = notRegular(st); !problem.empty())
    return makeError(what + ": " + problem);
  const auto bytes = static_cast<uint64_t>(st.st_size);
  if (bytes > maxBytes)
    return makeError(what + ": " + std::to_string(bytes) + " bytes, more than the " +
                     std::to_string(maxBytes) + " bytes allowed for it");
  Buffer out(static_cast<size_t>(bytes), 0);
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t got = ::read(fd, out.data() + done, out.size() - done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return makeError(what + ": read error (" + std::strerror(errno) + ")");
    if (got == 0) break;  // the file shrank since the fstat
    done += static_cast<size_t>(got);
  }
  out.resize(done);
  return out;
}

/// `path` lexically normal and relative: does it climb out of its base ("..", "../x")?
bool climbsOut(const fs::path& normal) {
  auto it = normal.begin();
  return it != normal.end() && *it == "..";
}

/// Is `inner` (canonical) strictly inside the folder `outer` (canonical)?
bool isInside(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return i != inner.end();
}

}  // namespace

Result<uint64_t> checkRegularFile(const fs::path& path, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) return makeError(what + ": no such file");
    return makeError(what + ": cannot be read (" + std::strerror(errno) + ")");
  }
  if (const std::string problem = notRegular(st); !problem.empty())
    return makeError(what + ": " + problem);
  return static_cast<uint64_t>(st.st_size);
}

Result<std::string> readRegularFile(const fs::path& path, const std::string& what,
                                    uint64_t maxBytes) {
  return readWhole<std::string>(path, what, maxBytes);
}

Result<std::vector<unsigned char>> readRegularFileBytes(const fs::path& path,
                                                        const std::string& what,
                                                        uint64_t maxBytes) {
  return readWhole<std::vector<unsigned char>>(path, what, maxBytes);
}

Result<fs::path> resolveReference(const fs::path& referencingFile, const std::string& reference,
                                  const std::string& what, bool allowOutside) {
  static const std::string kHint = " (--allow-outside-references allows it)";
  if (reference.empty()) return makeError(what + ": empty file name");
  if (reference.find('\0') != std::string::npos)
    return makeError(what + ": refused: the name contains a NUL character");
  const fs::path ref(reference);
  fs::path folder = referencingFile.parent_path();
  if (folder.empty()) folder = ".";
  if (!allowOutside) {
    if (ref.is_absolute() || ref.has_root_name() || ref.has_root_directory())
      return makeError(what + ": refused: absolute paths may not be referenced" + kHint);
    if (climbsOut(ref.lexically_normal()))
      return makeError(what + ": refused: it leads outside the folder of the file naming it" +
                       kHint);
  }
  const fs::path joined = ref.is_absolute() ? ref : folder / ref;
  std::error_code ec;
  const fs::path target = fs::weakly_canonical(joined, ec);
  if (ec) return makeError(what + ": cannot be resolved (" + ec.message() + ")");
  if (!allowOutside) {
    const fs::path root = fs::weakly_canonical(folder, ec);
    if (ec) return makeError(what + ": cannot resolve the folder of the file naming it");
    if (!isInside(target, root))
      return makeError(what +
                       ": refused: it resolves (through a symbolic link) outside the folder of "
                       "the file naming it" +
                       kHint);
  }
  auto size = checkRegularFile(target, what);
  if (!size) return size.error();
  return target;
}

bool isNoSuchFileError(const Error& error) {
  static const std::string kSuffix = ": no such file";
  const std::string& m = error.message;
  return m.size() >= kSuffix.size() &&
         m.compare(m.size() - kSuffix.size(), kSuffix.size(), kSuffix) == 0;
}

Result<void> checkImageDimensions(int width, int height, const std::string& what) {
  if (width <= 0 || height <= 0)
    return makeError(what + ": invalid image size " + std::to_string(width) + " x " +
                     std::to_string(height));
  if (width > kMaxImageDimension || height > kMaxImageDimension ||
      static_cast<uint64_t>(width) * static_cast<uint64_t>(height) > kMaxImagePixels)
    return makeError(what + ": image of " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels refused (at most " + std::to_string(kMaxImageDimension) + " x " +
                     std::to_string(kMaxImageDimension) + ")");
  return {};
}

}  // namespace mfr
