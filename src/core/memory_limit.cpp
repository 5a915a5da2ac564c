// Memory pre-flight (see mfr/core/memory_limit.hpp).
#include "mfr/core/memory_limit.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mfr/core/units.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

/// The first line of a small kernel file ("" when it cannot be read).
std::string firstLine(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

/// The smaller of two limits, 0 meaning none.
uint64_t tighter(uint64_t a, uint64_t b) {
  return a == 0 ? b : b == 0 ? a : std::min(a, b);
}

/// The tightest limit in `file` of the cgroup `cgroupPath` ("/a/b") under `root` and of each
/// cgroup above it (a parent's limit holds its children too).
uint64_t tightestUpwards(const fs::path& root, const std::string& cgroupPath, const char* file) {
  uint64_t tightest = 0;
  for (fs::path relative = fs::path(cgroupPath).relative_path();;
       relative = relative.parent_path()) {
    tightest = tighter(tightest, parseCgroupMemoryLimit(firstLine(root / relative / file)));
    if (relative.empty()) return tightest;
  }
}

/// The cgroup memory limit of this process: v2's memory.max and v1's memory.limit_in_bytes along
/// the paths /proc/self/cgroup names ("0::/a/b" for v2, "4:memory:/a/b" for v1).
uint64_t cgroupMemoryLimit() {
  const fs::path v2Root = "/sys/fs/cgroup", v1Root = "/sys/fs/cgroup/memory";
  // the mounted roots: inside a container, its own cgroup
  uint64_t tightest = tighter(parseCgroupMemoryLimit(firstLine(v2Root / "memory.max")),
                              parseCgroupMemoryLimit(firstLine(v1Root / "memory.limit_in_bytes")));
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    const size_t first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1);
    const std::string path = line.substr(second + 1);
    if (path.empty() || path[0] != '/') continue;
    if (controllers.empty()) {  // v2: "0::/a/b"
      tightest = tighter(tightest, tightestUpwards(v2Root, path, "memory.max"));
      continue;
    }
    std::stringstream list(controllers);  // v1: "4:memory:/a/b"
    for (std::string c; std::getline(list, c, ',');)
      if (c == "memory")
        tightest = tighter(tightest, tightestUpwards(v1Root, path, "memory.limit_in_bytes"));
  }
  return tightest;
}

}  // namespace

uint64_t physicalMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long pageSize = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return 0;
  return saturatingMul(static_cast<uint64_t>(pages), static_cast<uint64_t>(pageSize));
}

uint64_t parseCgroupMemoryLimit(std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.remove_suffix(1);
  uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) return 0;
  // cgroup v1 writes "no limit" as the largest page count in bytes, about 2^63
  return value >= (uint64_t{1} << 62) ? 0 : value;
}

MemoryBounds memoryBounds() {
  MemoryBounds bounds;
  bounds.physical = physicalMemoryBytes();
  rlimit as{};
  if (::getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY)
    bounds.addressSpace = static_cast<uint64_t>(as.rlim_cur);
  bounds.cgroup = cgroupMemoryLimit();
  return bounds;
}

uint64_t defaultMemoryLimit(const MemoryBounds& bounds) {
  const uint64_t smallest = tighter(tighter(bounds.physical, bounds.addressSpace), bounds.cgroup);
  if (smallest == 0) return UINT64_MAX;
  return static_cast<uint64_t>(static_cast<double>(smallest) * kDefaultMemoryShare);
}

uint64_t defaultMemoryLimit() {
  return defaultMemoryLimit(memoryBounds());
}

Result<void> checkMemory(uint64_t bytes, uint64_t limit, const std::string& what) {
  if (bytes <= limit) return {};
  const std::string needed = bytes == UINT64_MAX
                                 ? std::string("more than 2^64 bytes")
                                 : formatBytes(bytes) + " (" + std::to_string(bytes) + " bytes)";
  return makeError(what + " need " + needed + ", more than the memory limit of " +
                   formatBytes(limit) + " (" + std::to_string(limit) + " bytes; --memory-limit)");
}

}  // namespace mfr
