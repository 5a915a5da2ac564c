// Shared pieces of the fuzz targets (fuzz/fuzz_*.cpp): a private work folder for the loaders that
// read files, the properties every target checks (errors are one non-empty line naming the input,
// a loaded scene renders, budgets hold, fragments add up), and FUZZ_CHECK, which aborts so that
// libFuzzer (or the standalone driver under ctest) reports the input.
//
// Each target is built twice: with clang + libFuzzer (scripts/fuzz.sh, build-fuzz) and with the
// project's compiler + fuzz/standalone_main.cpp (ctest FuzzRegression.*), both with ASan + UBSan.
#pragma once

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include "mfr/core/result.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/scene.hpp"

/// Aborts with the failed condition and a note (libFuzzer saves the input as a crash).
#define FUZZ_CHECK(cond, note)                                                                   \
  do {                                                                                           \
    if (!(cond)) {                                                                               \
      std::fprintf(stderr, "%s:%d: fuzz property failed: %s\n  %s\n", __FILE__, __LINE__, #cond, \
                   std::string(note).c_str());                                                   \
      std::fflush(stderr);                                                                       \
      std::abort();                                                                              \
    }                                                                                            \
  } while (0)

namespace mfr::fuzz {

/// Procedural scenes (procedural: specs, JSON scenes naming one) are capped far below the default
/// so that every input stays fast; the parameter parsing and range checks are the same.
inline constexpr double kMaxFuzzTriangles = 5000.0;

/// Scene files are held to a memory limit far below the default for the same reason: a glTF of
/// 451 bytes may legally declare 4 M vertices (an accessor without a buffer view reads as zeros),
/// which loads in seconds under ASan. The expansion check that refuses it is the one the CLI
/// applies to --memory-limit, so the fuzzer still reaches it, in microseconds.
inline constexpr uint64_t kFuzzMemoryLimitBytes = uint64_t{32} << 20;

/// A folder of this process, removed at exit: loaders that only read files get their input here.
class WorkDir {
 public:
  /// In /dev/shm when there is one: rewriting a file on a disk file system costs a flush per
  /// input (ext4 flushes a truncated file on close), in memory it does not.
  WorkDir() {
    const char* tmp = std::getenv("TMPDIR");
    std::string base = tmp && *tmp ? tmp : "/tmp";
    if (access("/dev/shm", W_OK | X_OK) == 0) base = "/dev/shm";
    std::string pattern = base + "/mfr-fuzz-XXXXXX";
    if (!mkdtemp(pattern.data())) {
      std::perror("mkdtemp");
      std::abort();
    }
    path_ = pattern;
  }
  ~WorkDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  WorkDir(const WorkDir&) = delete;
  WorkDir& operator=(const WorkDir&) = delete;

  /// Writes `size` bytes to NAME in the folder and returns its path.
  std::string write(const std::string& name, const void* data, size_t size) const {
    const std::string path = (path_ / name).string();
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) {
      std::fprintf(stderr, "cannot write %s\n", path.c_str());
      std::abort();
    }
    return path;
  }
  std::string write(const std::string& name, std::string_view text) const {
    return write(name, text.data(), text.size());
  }
  void remove(const std::string& name) const {
    std::error_code ec;
    std::filesystem::remove(path_ / name, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline WorkDir& workDir() {
  static WorkDir dir;
  return dir;
}

/// The message with control characters made visible, for FUZZ_CHECK notes.
inline std::string printable(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned char>(c));
      out += hex;
    } else {
      out += c;
    }
  }
  return out;
}

/// Errors are one non-empty line (the command line prints "mfr: error: <message>\n"); when
/// `mustName` is given, the message names it (the input's path or name).
inline void checkError(const Error& error, std::string_view mustName = {}) {
  const std::string& m = error.message;
  FUZZ_CHECK(!m.empty(), "empty error message");
  FUZZ_CHECK(m.find('\n') == std::string::npos && m.find('\r') == std::string::npos,
             "error message is not one line: " + printable(m));
  if (!mustName.empty())
    FUZZ_CHECK(m.find(mustName) != std::string::npos,
               "error does not name '" + std::string(mustName) + "': " + printable(m));
}

/// A fixed small transparent scene (4 overlapping quads) for targets that fuzz something else
/// than the scene (cameras, models).
inline const Scene& smallScene() {
  static const Scene scene = [] {
    auto made = makeProceduralScene("layers?k=4&r=1&pd=1&alpha=0.5", 1);
    FUZZ_CHECK(made.ok(), made.ok() ? "" : made.error().message);
    return std::move(made.value());
  }();
  return scene;
}

/// Renders `method` (budget optional) at size x size with one worker and checks the statistics:
/// fragments add up, the budget holds, the image is finite. Errors must be one line.
inline void renderChecked(const Scene& scene, const Camera& camera, int size,
                          const MethodDesc& method, std::optional<uint64_t> budget = {}) {
  RasterOptions ro;
  ro.width = size;
  ro.height = size;
  ro.threads = 1;
  auto frame = RasterFrame::build(scene, camera, ro);
  if (!frame) {
    checkError(frame.error());
    return;
  }
  RenderOptions options;
  options.budgetBytes = budget;
  auto out = render(frame.value(), method, options);
  if (!out) {
    checkError(out.error());
    return;
  }
  const RenderStats& s = out->stats;
  FUZZ_CHECK(s.fragmentsGenerated == s.captured + s.lost,
             method.name + ": generated " + std::to_string(s.fragmentsGenerated) + " != captured " +
                 std::to_string(s.captured) + " + lost " + std::to_string(s.lost));
  if (budget)
    FUZZ_CHECK(s.bytesUsed <= *budget, method.name + ": bytes_used " + std::to_string(s.bytesUsed) +
                                           " > budget " + std::to_string(*budget));
  if (method.allocation == AllocationPolicy::Unbounded)
    FUZZ_CHECK(s.lost == 0, method.name + " lost fragments");
  for (const glm::vec3& p : out->image.pixels)
    FUZZ_CHECK(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b),
               method.name + ": non-finite pixel");
}

/// What every consumer does with a loaded scene: the exact A-buffer and a hybrid fixed-k buffer
/// from the default camera (scenes frame themselves), and a count pass from up to two of the
/// file's cameras. 12 x 12 pixels: the point is the set-up and clipping of hostile geometry.
inline void exerciseScene(const Scene& scene) {
  FUZZ_CHECK(validateScene(scene).ok(), "a loaded scene fails validateScene");
  const Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
  static const MethodDesc abuffer = methodPreset("abuffer").value();
  static const MethodDesc hybridFkb = [] {
    MethodDesc m = methodPreset("kplus-array").value();
    m.k = 2;
    m.compositing = Compositing::Hybrid;
    return m;
  }();
  renderChecked(scene, camera, 12, abuffer);
  renderChecked(scene, camera, 12, hybridFkb);
  for (size_t i = 0; i < scene.cameras.size() && i < 2; ++i) {
    RasterOptions ro;
    ro.width = ro.height = 8;
    ro.threads = 1;
    auto frame = RasterFrame::build(scene, scene.cameras[i], ro);
    if (!frame) {
      checkError(frame.error());
      continue;
    }
    const std::vector<uint32_t> counts = countFragments(frame.value());
    FUZZ_CHECK(counts.size() == 64, "count pass size");
  }
}

/// Loads a scene file written to the work folder: an error is one line naming the file, a scene
/// is exercised.
inline void loadAndExercise(const std::string& path) {
  LoadOptions options;
  options.maxProceduralTriangles = kMaxFuzzTriangles;
  options.memoryLimitBytes = kFuzzMemoryLimitBytes;
  auto scene = loadScene(path, options);
  if (!scene) {
    checkError(scene.error(), path);
    return;
  }
  exerciseScene(scene.value());
}

}  // namespace mfr::fuzz
