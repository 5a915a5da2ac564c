// Confined, non-blocking file access (see mfr/core/file_access.hpp).
#include "mfr/core/file_access.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

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

Error readError(const std::string& what, int err) {
  return makeError(what + ": cannot be read (" + std::strerror(err) + ")");
}

/// An open() error as the checks would have said it.
Error openError(const std::string& what, int err) {
  if (err == ENOENT || err == ENOTDIR) return makeError(what + ": no such file");
  return readError(what, err);
}

/// The path of an open descriptor as the kernel resolved it (symbolic links followed), from
/// /proc/self/fd; empty when /proc cannot tell.
fs::path descriptorPath(int fd) {
  std::error_code ec;
  fs::path path = fs::read_symlink("/proc/self/fd/" + std::to_string(fd), ec);
  if (ec || !path.is_absolute()) return {};
  return path;
}

/// The checks on an open descriptor: a regular file; its size.
Result<OpenFile> checkedOpenFile(int fd, fs::path path, const std::string& what) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    return readError(what, err);
  }
  if (const std::string problem = notRegular(st); !problem.empty()) {
    ::close(fd);
    return makeError(what + ": " + problem);
  }
  return OpenFile(fd, std::move(path), static_cast<uint64_t>(st.st_size), what);
}

template <class Buffer>
Result<Buffer> readDescriptor(int fd, uint64_t size, const std::string& what, uint64_t maxBytes) {
  if (size > maxBytes)
    return makeError(what + ": " + std::to_string(size) + " bytes, more than the " +
                     std::to_string(maxBytes) + " bytes allowed for it");
  Buffer out(static_cast<size_t>(size), 0);
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t got = ::pread(fd, out.data() + done, out.size() - done, static_cast<off_t>(done));
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

OpenFile::OpenFile(OpenFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      path_(std::move(other.path_)),
      size_(other.size_),
      what_(std::move(other.what_)) {}

OpenFile::~OpenFile() {
  if (fd_ >= 0) ::close(fd_);
}

Result<std::vector<unsigned char>> OpenFile::read(uint64_t maxBytes) const {
  return readDescriptor<std::vector<unsigned char>>(fd_, size_, what_, maxBytes);
}

Result<std::string> OpenFile::readText(uint64_t maxBytes) const {
  return readDescriptor<std::string>(fd_, size_, what_, maxBytes);
}

Result<OpenFile> openRegularFile(const fs::path& path, const std::string& what) {
  // O_NONBLOCK: a FIFO opens at once (and the fstat refuses it) instead of blocking the open
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return openError(what, errno);
  return checkedOpenFile(fd, path, what);
}

Result<std::string> readRegularFile(const fs::path& path, const std::string& what,
                                    uint64_t maxBytes) {
  auto file = openRegularFile(path, what);
  if (!file) return file.error();
  return file->readText(maxBytes);
}

Result<std::vector<unsigned char>> readRegularFileBytes(const fs::path& path,
                                                        const std::string& what,
                                                        uint64_t maxBytes) {
  auto file = openRegularFile(path, what);
  if (!file) return file.error();
  return file->read(maxBytes);
}

Result<OpenFile> openReference(const fs::path& referencingFile, const std::string& reference,
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
  // The folder is opened once; the reference is opened relative to that descriptor, and where
  // the kernel resolved both is read back from the descriptors, so the check below is about the
  // very file that is then read.
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir < 0)
    return makeError(what + ": cannot open the folder of the file naming it (" +
                     std::strerror(errno) + ")");
  const int fd = ::openat(dir, ref.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  const int openErrno = errno;
  const fs::path root = descriptorPath(dir);
  ::close(dir);
  if (fd < 0) return openError(what, openErrno);
  const fs::path target = descriptorPath(fd);
  if (!allowOutside) {
    if (root.empty() || target.empty()) {
      ::close(fd);
      return makeError(what + ": refused: where it leads cannot be checked (no /proc/self/fd)");
    }
    if (!isInside(target, root)) {
      ::close(fd);
      return makeError(what +
                       ": refused: it resolves (through a symbolic link) outside the folder of "
                       "the file naming it" +
                       kHint);
    }
  }
  return checkedOpenFile(fd, target.empty() ? folder / ref : target, what);
}

std::string lowercaseExtension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
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
