// Writing a comparison's folder (see mfr/compare/compare_output.hpp).
#include "mfr/compare/compare_output.hpp"
#include "mfr/core/json_limits.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <utility>
#include <vector>

#include "mfr/core/atomic_file.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/quote.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

// a temporary file renamed into place (core/atomic_file.hpp): never a truncated file
Result<void> writeText(const fs::path& path, const std::string& text) {
  return writeFileAtomically(path.string(), text);
}

bool endsWith(const std::string& s, const char* suffix) {
  const size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

/// The first entry of `dir` that a comparison does not write ("" when none): a comparison writes
/// PNG, JSON, CSV and HTML files and frame_NNN folders of them (older versions also left hidden
/// temporary and probe files).
std::string foreignEntry(const fs::path& dir, int depth = 0) {
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const fs::file_status st = e.symlink_status(ec);
    if (fs::is_regular_file(st) &&
        (endsWith(name, ".png") || endsWith(name, ".json") || endsWith(name, ".csv") ||
         endsWith(name, ".html") || name == ".mfr_compare_write_test" ||
         (name[0] == '.' && name.find(".tmp.") != std::string::npos)))
      continue;
    const bool frame = name.size() > 6 && name.rfind("frame_", 0) == 0 &&
                       name.find_first_not_of("0123456789", 6) == std::string::npos;
    if (fs::is_directory(st) && frame && depth == 0) {
      const std::string inner = foreignEntry(e.path(), depth + 1);
      if (inner.empty()) continue;
      return name + "/" + inner;
    }
    return name;
  }
  if (ec) return "?";  // unreadable: not known to be a comparison
  return "";
}

/// ".NAME.compare-tmp." (+ PID.N): the staging folders of `destination`, NAME cut to 128 bytes
/// (at a UTF-8 boundary) so that the staging name (at most 1 + 128 + 13 + 10 + 1 + 20 + 4 for
/// ".old" = 177 bytes) fits wherever the destination's own name does (NAME_MAX, 255).
std::string stagingPrefix(const fs::path& destination) {
  constexpr size_t kMaxNameHead = 128;
  std::string name = destination.filename().string();
  if (name.size() > kMaxNameHead) {
    size_t cut = kMaxNameHead;
    while (cut > 0 && (static_cast<unsigned char>(name[cut]) & 0xC0) == 0x80) --cut;
    name.resize(cut);
  }
  std::string prefix = ".";  // appended piece by piece (GCC 12 warns on "." + string, PR 105329)
  prefix += name;
  prefix += ".compare-tmp.";
  return prefix;
}

/// Removes the staging folders of `destination` whose process is gone (killed mid-comparison).
void removeStaleStaging(const fs::path& destination) {
  const std::string prefix = stagingPrefix(destination);
  std::error_code ec;
  std::vector<fs::path> stale;
  for (const fs::directory_entry& e : fs::directory_iterator(destination.parent_path(), ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && pid != ::getpid() && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
      stale.push_back(e.path());
  }
  for (const fs::path& p : stale) fs::remove_all(p, ec);
}

/// "DIR: holds 'NAME', which a comparison does not write: ...": never replaced.
Error foreignRefusal(const std::string& dir, const std::string& foreign) {
  return makeError(echoPath(dir) + ": holds " + quoteInput(foreign) +
                   ", which a comparison does not write: not replacing it (choose another "
                   "folder)");
}

/// Swaps two folders in one step; false with errno where the file system cannot.
bool exchange(const fs::path& a, const fs::path& b) {
#ifdef RENAME_EXCHANGE
  return ::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0;
#else
  errno = ENOSYS;
  return false;
#endif
}

}  // namespace

OutputFolder::OutputFolder(std::string name, std::string destination, std::string staging)
    : name_(std::move(name)), destination_(std::move(destination)), staging_(std::move(staging)) {}

OutputFolder::OutputFolder(OutputFolder&& other) noexcept
    : name_(std::move(other.name_)),
      destination_(std::move(other.destination_)),
      staging_(std::exchange(other.staging_, std::string())) {}

OutputFolder::~OutputFolder() {
  std::error_code ec;
  if (!staging_.empty()) fs::remove_all(staging_, ec);
}

Result<OutputFolder> OutputFolder::begin(const std::string& out) {
  if (out.empty()) return makeError("an output folder is required");
  std::error_code ec, ignored;
  fs::path destination = fs::absolute(out, ec).lexically_normal();
  if (!destination.has_filename()) destination = destination.parent_path();  // "DIR/" -> "DIR"
  if (!ec && fs::is_symlink(fs::symlink_status(destination, ignored)))  // its folder is replaced
    destination = fs::canonical(destination, ec);
  if (ec)
    return makeError(echoPath(out) + ": cannot create the output folder (" + ec.message() + ")");
  const fs::file_status st = fs::status(destination, ignored);
  if (fs::exists(st)) {
    if (!fs::is_directory(st))
      return makeError(echoPath(out) + ": cannot create the output folder (not a directory)");
    if (const std::string foreign = foreignEntry(destination); !foreign.empty())
      return foreignRefusal(out, foreign);
  } else {
    fs::create_directories(destination.parent_path(), ec);
    if (ec || !fs::is_directory(destination.parent_path()))
      return makeError(echoPath(out) + ": cannot create the output folder" +
                       (ec ? " (" + ec.message() + ")" : std::string(" (not a directory)")));
  }
  removeStaleStaging(destination);
  static std::atomic<uint64_t> counter{0};
  for (int attempt = 0; attempt < 8; ++attempt) {
    std::string name = stagingPrefix(destination);
    name += std::to_string(::getpid());
    name += '.';
    name += std::to_string(counter++);
    const fs::path staging = destination.parent_path() / name;
    if (::mkdir(staging.c_str(), 0777) == 0)
      return OutputFolder(out, destination.string(), staging.string());
    if (errno != EEXIST)
      return makeError(echoPath(out) + ": output folder is not writable (" + std::strerror(errno) +
                       ")");
  }
  return makeError(echoPath(out) + ": cannot create a staging folder beside it");
}

Result<void> OutputFolder::commit() {
  if (staging_.empty()) return makeError(echoPath(name_) + ": already written");
  const fs::path destination(destination_), staging(staging_);
  const auto failed = [this](const std::string& why) {
    return makeError(echoPath(name_) + ": cannot put the comparison in place (" + why + ")");
  };
  for (int attempt = 0; attempt < 16; ++attempt) {
    // absent or an empty folder: one rename
    if (::rename(staging.c_str(), destination.c_str()) == 0) break;
    if (errno != ENOTEMPTY && errno != EEXIST) return failed(std::strerror(errno));
    // a previous comparison (or one committed meanwhile): swap, then remove the old one
    if (const std::string foreign = foreignEntry(destination); !foreign.empty())
      return foreignRefusal(name_, foreign);
    if (exchange(staging, destination)) {
      std::error_code ec;
      fs::remove_all(staging, ec);  // now the old folder
      break;
    }
    if (errno == ENOENT) continue;  // removed meanwhile: rename again
    if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP) return failed(std::strerror(errno));
    // no exchange on this file system: the old folder aside, the new one in, the old one gone
    const fs::path aside = staging.string() + ".old";
    if (::rename(destination.c_str(), aside.c_str()) != 0 && errno != ENOENT)
      return failed(std::strerror(errno));
    const bool placed = ::rename(staging.c_str(), destination.c_str()) == 0;
    std::error_code ec;
    fs::remove_all(aside, ec);
    if (placed) break;
  }
  std::error_code ec;
  if (fs::exists(staging, ec))  // every attempt lost to a concurrent comparison
    return failed("it keeps changing");
  staging_.clear();
  syncFolder(destination.parent_path().string());
  return {};
}

Result<void> prepareOutputFolder(const std::string& out) {
  const fs::path dir(out);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    return makeError(echoPath(out) + ": cannot create the output folder" +
                     (ec ? " (" + ec.message() + ")" : std::string(" (not a directory)")));
  const fs::path probe = dir / ".mfr_compare_write_test";
  if (!std::ofstream(probe)) return makeError(echoPath(out) + ": output folder is not writable");
  fs::remove(probe, ec);
  return {};
}

Result<std::string> writeComparison(const CompareResult& r, const std::string& out,
                                    const std::string& mfrVersion, const ReportInfo& info) {
  const fs::path dir(out);
  const auto png = [&](const std::string& file, const Image8& image) -> Result<void> {
    if (file.empty()) return {};
    return writePng((dir / file).string(), image);
  };
  std::vector<Result<void>> written;
  written.push_back(png(r.groundTruth.imageFile, r.groundTruth.image));
  written.push_back(png(r.depthComplexityFile, r.depthComplexityMap));
  for (const CompareBudget& cb : r.budgets)
    for (const CompareRun& run : cb.runs) {
      if (!run.ok()) continue;
      written.push_back(png(run.imageFile, run.image));
      written.push_back(png(run.flipFile, run.flipMap));
      written.push_back(png(run.kMapFile, run.kMap));
      written.push_back(png(run.importanceFile, run.importanceMap));
    }
  // a scene or model path need not be UTF-8 (a file name is bytes); JSON text must be: such
  // bytes are written as U+FFFD rather than failing the whole comparison
  const std::string json = jsonText(compareToJson(r, mfrVersion)) + "\n";
  written.push_back(writeText(dir / "results.json", json));
  written.push_back(writeText(dir / "results.csv", compareToCsv(r)));
  written.push_back(writeText(dir / "report.html", compareReportHtml(r, info)));
  for (const Result<void>& w : written)
    if (!w) return w.error();
  return json;
}

std::string utcTimestamp() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buffer[64];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buffer;
}

}  // namespace mfr
