// Atomic file replacement (see mfr/core/atomic_file.hpp).
#include "mfr/core/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

#include "mfr/core/quote.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

constexpr size_t kChunkBytes = size_t{1} << 20;

WriteFailureInjection& injection() {
  static WriteFailureInjection hook;
  return hook;
}

Error ioError(const std::string& path, const char* what, int err) {
  return makeError(echoPath(path) + ": " + what + " (" + std::strerror(err) + ")");
}

/// Writes all of `bytes` to `fd` in chunks (the test hook may fail it after any chunk).
Result<void> writeAll(int fd, const std::string& path, std::string_view bytes) {
  uint64_t done = 0;
  do {
    const size_t n = std::min(kChunkBytes, bytes.size() - static_cast<size_t>(done));
    if (n > 0) {
      const ssize_t w = ::write(fd, bytes.data() + done, n);
      if (w < 0 && errno == EINTR) continue;
      if (w < 0) return ioError(path, "write error", errno);
      done += static_cast<uint64_t>(w);
    }
    if (injection() && injection()(path, done))
      return makeError(echoPath(path) + ": write error (injected after " + std::to_string(done) +
                       " bytes)");
  } while (done < bytes.size());
  return {};
}

/// The destination's name as the head of its temporary name: at most kMaxNameHead bytes, cut at a
/// UTF-8 character boundary.
constexpr size_t kMaxNameHead = 128;

std::string nameHead(const std::string& name) {
  if (name.size() <= kMaxNameHead) return name;
  size_t cut = kMaxNameHead;
  while (cut > 0 && (static_cast<unsigned char>(name[cut]) & 0xC0) == 0x80) --cut;
  return name.substr(0, cut);
}

/// A fresh temporary name next to the destination: ".NAME.tmp.PID.N.TICK", NAME cut to
/// kMaxNameHead bytes, so that it fits wherever the destination's own name does (NAME_MAX, 255
/// bytes on Linux, for a destination of any legal name): at most 1 + 128 + 5 + 10 + 1 + 20 + 1 + 8
/// = 174 bytes; PID and the counter keep it unique.
fs::path temporaryName(const fs::path& target) {
  static std::atomic<uint64_t> counter{0};
  const auto tick =
      static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count() & 0xffffff);
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::string name = ".";  // appended piece by piece (GCC 12 warns on "." + string, PR 105329)
  name += nameHead(target.filename().string());
  name += ".tmp.";
  name += std::to_string(::getpid());
  name += '.';
  name += std::to_string(counter++);
  name += '.';
  name += std::to_string(tick);
  return dir / name;
}

/// Writes into an already open temporary file, syncs it and gives it the target's permissions.
Result<void> fillTemporary(int fd, const std::string& path, std::string_view bytes,
                           std::optional<mode_t> mode) {
  MFR_TRY(writeAll(fd, path, bytes));
  if (mode) ::fchmod(fd, *mode);
  if (::fsync(fd) != 0) return ioError(path, "write error", errno);
  return {};
}

Result<void> renameIntoPlace(const fs::path& temporary, const std::string& path) {
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(temporary.c_str());
    return ioError(path, "cannot replace the file", err);
  }
  syncFolder(fs::path(path).parent_path().string());
  return {};
}

/// Linux O_TMPFILE: the data is written to an unnamed file that only gets a name (and then the
/// destination's) once complete. nullopt: not available here (fall back to a named file).
std::optional<Result<void>> writeUnnamed(const fs::path& dir, const std::string& path,
                                         std::string_view bytes, std::optional<mode_t> mode) {
#ifdef O_TMPFILE
  const int fd = ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
  if (fd < 0) return std::nullopt;  // file system without O_TMPFILE, or no such folder
  auto filled = fillTemporary(fd, path, bytes, mode);
  if (!filled) {
    ::close(fd);  // the unnamed file disappears with its descriptor
    return Result<void>(filled.error());
  }
  const std::string self = "/proc/self/fd/" + std::to_string(fd);
  for (int attempt = 0; attempt < 8; ++attempt) {
    const fs::path temporary = temporaryName(fs::path(path));
    if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, temporary.c_str(), AT_SYMLINK_FOLLOW) == 0) {
      ::close(fd);
      return renameIntoPlace(temporary, path);
    }
    if (errno != EEXIST) break;
  }
  ::close(fd);
  return std::nullopt;  // e.g. no /proc: write again through a named temporary file
#else
  (void)dir, (void)path, (void)bytes, (void)mode;
  return std::nullopt;
#endif
}

Result<void> writeNamed(const std::string& path, std::string_view bytes,
                        std::optional<mode_t> mode) {
  for (int attempt = 0; attempt < 8; ++attempt) {
    const fs::path temporary = temporaryName(fs::path(path));
    const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno == EEXIST) continue;
    if (fd < 0) return ioError(path, "cannot open for writing", errno);
    auto filled = fillTemporary(fd, path, bytes, mode);
    if (::close(fd) != 0 && filled) filled = ioError(path, "write error", errno);
    if (!filled) {
      ::unlink(temporary.c_str());
      return filled.error();
    }
    return renameIntoPlace(temporary, path);
  }
  return makeError(echoPath(path) + ": cannot create a temporary file next to it");
}

/// Special files (a terminal, /dev/stdout, a pipe) have nothing to replace: written directly.
Result<void> writeSpecial(const std::string& path, std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return ioError(path, "cannot open for writing", errno);
  auto written = writeAll(fd, path, bytes);
  ::close(fd);
  return written;
}

}  // namespace

Result<void> writeFileAtomically(const std::string& path, std::string_view bytes) {
  if (path.empty()) return makeError("cannot write a file with an empty name");
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  // a missing folder is made, for every output alike (a file in its way fails the open below)
  if (std::error_code ec; !fs::is_directory(dir, ec)) fs::create_directories(dir, ec);
  std::optional<mode_t> mode;  // an existing file keeps its permissions
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) return makeError(echoPath(path) + ": is a directory");
    if (!S_ISREG(st.st_mode)) return writeSpecial(path, bytes);
    mode = st.st_mode & 07777;
  }
  if (auto unnamed = writeUnnamed(dir, path, bytes, mode)) return *unnamed;
  return writeNamed(path, bytes, mode);
}

void syncFolder(const std::string& dir) {
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

void setWriteFailureInjectionForTests(WriteFailureInjection hook) {
  injection() = std::move(hook);
}

}  // namespace mfr
