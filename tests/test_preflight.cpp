// Memory pre-flight (mfr/core/memory_limit.hpp, RenderOptions::memoryLimitBytes, --memory-limit):
// render() computes the bytes of its buffers before allocating them and fails with one line naming
// the input, the bytes needed and the limit; std::bad_alloc never reaches the user as such; small
// hostile files never make mfr allocate gigabytes (run under a virtual-memory cap).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_timeout.hpp"
#include "error_assertions.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/memory_limit.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/load.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::cleanError;
using mfr::test::CliRun;
using mfr::test::contains;

fs::path scratch() {
  static const fs::path dir = mfr::test::processTempDir("mfr_preflight_test");
  return dir;
}

std::string write(const std::string& name, const std::string& bytes) {
  return mfr::test::writeFile(scratch() / name, bytes);
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The bytes an error says are needed ("... need 8.25 GiB (8858370048 bytes), ...").
uint64_t neededBytes(const std::string& message) {
  const size_t need = message.find(" need ");
  const size_t open = message.find('(', need);
  if (need == std::string::npos || open == std::string::npos) return 0;
  return std::stoull(message.substr(open + 1));
}

// ---------------------------------------------------------------------------------------------
// The issue's case and the option

TEST(Preflight, AbufferAt16384SquaredUnderA64MBLimitIsOneFastLine) {
  const auto start = std::chrono::steady_clock::now();
  // under a 1 GiB address-space cap: the refusal comes before any large allocation
  const CliRun r = mfr::test::runCliTimed(
      "render procedural:spheres --width 16384 --height 16384 --method abuffer --memory-limit "
      "64MB -o " +
          (scratch() / "never.png").string(),
      scratch(), mfr::test::capped(30, 1u << 20));
  const double seconds = secondsSince(start);
  EXPECT_TRUE(cleanError(r, {"procedural:spheres", "abuffer at 16384 x 16384 pixels",
                             "more than the memory limit of 64.00 MiB (67108864 bytes"}));
  // the bytes needed: at least the 4-byte counter, 8-byte offset and 12-byte colour per pixel
  EXPECT_GE(neededBytes(r.err), uint64_t{16384} * 16384 * 24) << r.err;
  EXPECT_LT(seconds, 10.0);
  EXPECT_FALSE(fs::exists(scratch() / "never.png"));
}

TEST(Preflight, MemoryLimitOptionIsParsedAndDocumented) {
  EXPECT_TRUE(cleanError(
      mfr::test::runCliTimed("render procedural:layers --memory-limit lots -q", scratch()),
      {"--memory-limit 'lots'"}));
  for (const char* command : {"render", "info", "compare", "dataset"}) {
    const CliRun help = mfr::test::runCliTimed(std::string(command) + " --help", scratch());
    EXPECT_TRUE(contains(help.out, "--memory-limit") && contains(help.out, "75% of the physical") &&
                contains(help.out, "--allow-outside-references"))
        << command << ": " << help.out;
  }
  // the default: 75% of the least of sysconf(_SC_PHYS_PAGES) * sysconf(_SC_PAGE_SIZE), RLIMIT_AS
  // and the cgroup's limit
  const mfr::MemoryBounds bounds = mfr::memoryBounds();
  ASSERT_GT(bounds.physical, 0u);
  EXPECT_EQ(bounds.physical, mfr::physicalMemoryBytes());
  EXPECT_EQ(mfr::defaultMemoryLimit(), mfr::defaultMemoryLimit(bounds));
  EXPECT_LE(mfr::defaultMemoryLimit(),
            static_cast<uint64_t>(static_cast<double>(bounds.physical) * 0.75));
  // a limit that fits renders
  const CliRun fits = mfr::test::runCliTimed(
      "render procedural:spheres --width 64 --height 64 --memory-limit 128MB -q -o " +
          (scratch() / "fits.png").string(),
      scratch());
  EXPECT_EQ(fits.exitCode, 0) << fits.err;
}

TEST(Preflight, DefaultLimitIsTheShareOfTheSmallestOfPhysicalAddressSpaceAndCgroup) {
  const auto limit = [](uint64_t physical, uint64_t addressSpace, uint64_t cgroup) {
    return mfr::defaultMemoryLimit(mfr::MemoryBounds{physical, addressSpace, cgroup});
  };
  const uint64_t gib = uint64_t{1} << 30;
  EXPECT_EQ(limit(16 * gib, 0, 0), 12 * gib);       // physical only (0: unlimited)
  EXPECT_EQ(limit(16 * gib, 8 * gib, 0), 6 * gib);  // ulimit -v below the memory
  EXPECT_EQ(limit(16 * gib, 0, 4 * gib), 3 * gib);  // a cgroup below the memory
  EXPECT_EQ(limit(16 * gib, 8 * gib, 4 * gib), 3 * gib);
  EXPECT_EQ(limit(16 * gib, 2 * gib, 4 * gib), 3 * gib / 2);
  EXPECT_EQ(limit(4 * gib, 64 * gib, 32 * gib), 3 * gib);  // larger bounds change nothing
  EXPECT_EQ(limit(0, 8 * gib, 0), 6 * gib);                // physical memory unknown
  EXPECT_EQ(limit(0, 0, 0), UINT64_MAX);                   // nothing known: no limit
  // the process's own RLIMIT_AS is read: under ulimit -v 4000000 (KiB) the default is 75% of it
  // (2.86 GiB) unless the memory or the cgroup is smaller still
  mfr::MemoryBounds capped = mfr::memoryBounds();
  capped.addressSpace = uint64_t{4000000} * 1024;
  const CliRun r = mfr::test::runCliTimed("render procedural:spheres --help", scratch(),
                                          mfr::test::capped(10, 4000000));
  EXPECT_TRUE(contains(
      r.out, "whichever is least: " + mfr::formatBytes(mfr::defaultMemoryLimit(capped)) + ")"))
      << r.out;
}

TEST(Preflight, CgroupLimitFilesAreParsed) {
  EXPECT_EQ(mfr::parseCgroupMemoryLimit("max\n"), 0u);                  // v2 without a limit
  EXPECT_EQ(mfr::parseCgroupMemoryLimit("9223372036854771712\n"), 0u);  // v1 without a limit
  EXPECT_EQ(mfr::parseCgroupMemoryLimit("1073741824\n"), uint64_t{1} << 30);
  EXPECT_EQ(mfr::parseCgroupMemoryLimit("536870912"), uint64_t{1} << 29);
  EXPECT_EQ(mfr::parseCgroupMemoryLimit(""), 0u);  // no such file
  EXPECT_EQ(mfr::parseCgroupMemoryLimit("12 apples"), 0u);
  EXPECT_EQ(mfr::parseCgroupMemoryLimit("-5"), 0u);
}

// The per-pixel buffers, which the image size alone decides, are refused before the scene is set
// up: at 16384 x 16384 building the hairball's frame alone takes about 20 s.
TEST(Preflight, ImageSizeAloneIsRefusedBeforeTheFrameIsBuilt) {
  const std::string big = "procedural:hairball --width 16384 --height 16384 --memory-limit 1GB ";
  for (const std::string& command :
       {"render " + big + "-q -o " + (scratch() / "never.png").string(),
        "compare " + big + "--budget 10MB --methods fkb -q --out " +
            (scratch() / "never_compare").string()}) {
    const auto start = std::chrono::steady_clock::now();
    const CliRun r = mfr::test::runCliTimed(command, scratch(), mfr::test::capped(30, 0));
    EXPECT_TRUE(cleanError(r, {"procedural:hairball: ",
                               "abuffer at 16384 x 16384 pixels: its "
                               "per-pixel buffers need 8.25 GiB (8858370048 bytes), more than "
                               "the memory limit of 1.00 GiB (1073741824 bytes"}))
        << command;
    EXPECT_LT(secondsSince(start), 5.0) << command;
  }
  EXPECT_FALSE(fs::exists(scratch() / "never.png"));
  // the library's check is the one render() makes first
  mfr::RenderOptions options;
  options.memoryLimitBytes = uint64_t{1} << 30;
  const auto abuffer = mfr::methodPreset("abuffer").value();
  auto refused = mfr::checkPixelBuffers(16384, 16384, abuffer, options);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(neededBytes(refused.error().message), 8858370048u);
  EXPECT_TRUE(mfr::checkPixelBuffers(1024, 1024, abuffer, options).ok());
  EXPECT_TRUE(mfr::checkPixelBuffers(0, 16384, abuffer, options).ok());  // the frame names it
}

// Under `ulimit -v` the default limit is the address space's share: the issue's case fails fast,
// naming the bytes needed and that limit.
TEST(Preflight, AddressSpaceLimitLowersTheDefaultAndFailsFast) {
  const uint64_t capKiB = 8000000;
  mfr::MemoryBounds bounds = mfr::memoryBounds();
  bounds.addressSpace = capKiB * 1024;
  std::string limitText = "(";  // appended piece by piece (GCC 12 warns on "(" + string)
  limitText += std::to_string(mfr::defaultMemoryLimit(bounds));
  limitText += " bytes; --memory-limit)";
  const auto start = std::chrono::steady_clock::now();
  const CliRun r =
      mfr::test::runCliTimed("render procedural:hairball --width 16384 --height 16384 -q -o " +
                                 (scratch() / "never.png").string(),
                             scratch(), mfr::test::capped(30, capKiB));
  EXPECT_TRUE(cleanError(r, {"procedural:hairball: abuffer at 16384 x 16384 pixels",
                             "(8858370048 bytes), more than the memory limit of", limitText}));
  EXPECT_LT(secondsSince(start), 5.0);
  EXPECT_FALSE(fs::exists(scratch() / "never.png"));
}

TEST(Preflight, CheckMemoryNamesWhatTheBytesAndTheLimit) {
  EXPECT_TRUE(mfr::checkMemory(100, 100, "x").ok());
  auto over = mfr::checkMemory(3u << 20, 1u << 20, "the things");
  ASSERT_FALSE(over.ok());
  EXPECT_EQ(over.error().message,
            "the things need 3.00 MiB (3145728 bytes), more than the memory limit of 1.00 MiB "
            "(1048576 bytes; --memory-limit)");
  EXPECT_EQ(mfr::saturatingMul(UINT64_MAX / 2, 3), UINT64_MAX);
  EXPECT_EQ(mfr::saturatingAdd(UINT64_MAX, 1), UINT64_MAX);
  EXPECT_TRUE(contains(mfr::checkMemory(UINT64_MAX, 1, "n").error().message, "more than 2^64"));
}

// ---------------------------------------------------------------------------------------------
// Every check inside render(): the bytes it reports are exactly its threshold

struct Stage {
  std::string message;
  uint64_t needed = 0;
};

/// Renders with a limit raised to each reported need in turn, until the render succeeds: the
/// checks met on the way, in order.
std::vector<Stage> climbLimits(const mfr::RasterFrame& frame, const std::string& preset,
                               std::optional<uint64_t> budget) {
  std::vector<Stage> stages;
  mfr::RenderOptions options;
  options.budgetBytes = budget;
  options.memoryLimitBytes = 1;
  for (int attempt = 0; attempt < 10; ++attempt) {
    auto out = mfr::render(frame, mfr::methodPreset(preset).value(), options);
    if (out.ok()) return stages;
    const std::string& m = out.error().message;
    EXPECT_TRUE(contains(m, "memory limit of")) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    const uint64_t needed = neededBytes(m);
    EXPECT_GT(needed, *options.memoryLimitBytes) << m;  // each check's need is above the limit
    if (needed <= *options.memoryLimitBytes) return stages;
    // one byte short still fails at the same check
    options.memoryLimitBytes = needed - 1;
    auto shortBy1 = mfr::render(frame, mfr::methodPreset(preset).value(), options);
    EXPECT_FALSE(shortBy1.ok());
    if (!shortBy1.ok()) {  // the same check: the same message up to the limit
      EXPECT_EQ(shortBy1.error().message.substr(0, m.find(", more than")),
                m.substr(0, m.find(", more than")));
    }
    stages.push_back({m, needed});
    options.memoryLimitBytes = needed;
  }
  ADD_FAILURE() << preset << " did not render with any limit";
  return stages;
}

mfr::RasterFrame frameOf(const std::string& source, int size) {
  auto scene = mfr::loadScene(source);
  EXPECT_TRUE(scene.ok());
  mfr::RasterOptions ro;
  ro.width = ro.height = size;
  auto frame = mfr::RasterFrame::build(
      scene.value(), scene->defaultCamera.value_or(mfr::frameBounds(mfr::sceneBounds(*scene))), ro);
  EXPECT_TRUE(frame.ok());
  return std::move(frame.value());
}

TEST(Preflight, AbufferChecksItsPerPixelBuffersThenItsNodePool) {
  const mfr::RasterFrame frame = frameOf("procedural:spheres?count=20", 64);
  const std::vector<Stage> stages = climbLimits(frame, "abuffer", std::nullopt);
  ASSERT_EQ(stages.size(), 2u);
  EXPECT_TRUE(contains(stages[0].message, "abuffer at 64 x 64 pixels: its per-pixel buffers"))
      << stages[0].message;
  EXPECT_TRUE(contains(stages[1].message, "fragment slots and buffers")) << stages[1].message;
  // the node pool: 8 bytes a fragment on top of the per-pixel buffers
  uint64_t fragments = 0;
  for (uint32_t c : mfr::countFragments(frame)) fragments += c;
  ASSERT_GT(fragments, 1000u);
  EXPECT_GE(stages[1].needed, stages[0].needed + 8 * fragments);
  EXPECT_TRUE(contains(stages[1].message, "its " + std::to_string(fragments) + " fragment slots"))
      << stages[1].message;
}

TEST(Preflight, OptimalOracleChecksItsErrorCurvesAfterThePerPixelBuffers) {
  // the pre-pass's A-buffer is tile-local: its whole-frame memory is n(p) and the curves
  const mfr::RasterFrame frame = frameOf("procedural:spheres?count=20", 64);
  const std::vector<Stage> stages = climbLimits(frame, "optimal", 200u << 10);
  bool curves = false, perPixel = false;
  uint64_t fragments = 0;
  for (uint32_t c : mfr::countFragments(frame)) fragments += c;
  for (const Stage& s : stages) {
    perPixel = perPixel || contains(s.message, "optimal at 64 x 64 pixels: its per-pixel buffers");
    if (contains(s.message, "optimal: the oracle's pre-pass: the error curves of " +
                                std::to_string(fragments) + " fragments")) {
      curves = true;
      EXPECT_GE(s.needed, 8 * fragments) << s.message;  // a double per fragment at least
    }
  }
  EXPECT_TRUE(curves && perPixel) << "stages: " << stages.size();
  for (size_t i = 1; i < stages.size(); ++i) EXPECT_GT(stages[i].needed, stages[i - 1].needed);
}

TEST(Preflight, OutOfMemoryIsNamedNeverStdBadAlloc) {
  // a limit far above what the address-space cap lets the process have: the pre-flight lets the
  // run through, the allocation fails, and the message names the input and the pass
  const CliRun r = mfr::test::runCliTimed(
      "render 'procedural:spheres?count=1' --width 8192 --height 8192 --method abuffer "
      "--threads 1 --memory-limit 1000GB -q -o " +
          (scratch() / "never.png").string(),
      scratch(), mfr::test::capped(60, 600u << 10));
  EXPECT_TRUE(cleanError(r, {"procedural:spheres?count=1", "abuffer at 8192 x 8192 pixels",
                             "out of memory allocating the buffers of the", "pass"}));
  EXPECT_FALSE(contains(r.err, "bad_alloc")) << r.err;
}

// ---------------------------------------------------------------------------------------------
// Small hostile files never make mfr allocate gigabytes: each fails with one line, fast, under a
// 1 GiB address-space cap, by a check (not by running out of memory)

TEST(Preflight, SmallHostileFilesFailBeforeAllocating) {
  const auto gltf = [](const std::string& accessor, const std::string& buffer) {
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
           R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"accessors":[)" +
           accessor + R"(],"bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[)" + buffer +
           "]}";
  };
  write("tri.bin", std::string(36, '\0'));
  const std::vector<std::pair<std::string, std::string>> cases = {
      // PLY: four billion vertices declared, none present
      {write("huge.ply",
             "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
             "property float x\nproperty float y\nproperty float z\nend_header\n"),
       "truncated"},
      // OBJ: a face naming vertex four billion
      {write("huge_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4000000000\n"), "huge_index.obj"},
      // glTF: a buffer declaring a terabyte, backed by 36 bytes
      {write("huge_buffer.gltf",
             gltf(R"({"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"})",
                  R"({"byteLength":1000000000000,"uri":"tri.bin"})")),
       "byteLength 1000000000000"},
      // glTF: an accessor of two billion elements in a 36-byte view
      {write("huge_count.gltf",
             gltf(R"({"bufferView":0,"componentType":5126,"count":2000000000,"type":"VEC3"})",
                  R"({"byteLength":36,"uri":"tri.bin"})")),
       "past the end"},
      // glTF: the same without a bufferView (zeros: nothing in the file bounds the count)
      {write("huge_zeros.gltf", gltf(R"({"componentType":5126,"count":2000000000,"type":"VEC3"})",
                                     R"({"byteLength":36,"uri":"tri.bin"})")),
       "count too large"},
  };
  for (const auto& [file, expected] : cases) {
    const auto start = std::chrono::steady_clock::now();
    const CliRun r = mfr::test::runCliTimed("info " + file + " --width 64 --height 64 -q",
                                            scratch(), mfr::test::capped(30, 1u << 20));
    EXPECT_TRUE(cleanError(r, {file, expected})) << file;
    EXPECT_FALSE(contains(r.err, "out of memory")) << r.err;
    EXPECT_LT(secondsSince(start), 5.0) << file;
  }
}

TEST(Preflight, PngInputsAreCheckedFromTheirHeaderAndMustBeRegularFiles) {
  // `mfr metrics` reads PNGs: a header claiming 20000 x 16 is refused before decoding, a FIFO
  // is refused without waiting for a writer
  std::string png("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16);
  for (uint32_t v : {20000u, 16u})
    for (int s = 24; s >= 0; s -= 8) png += static_cast<char>((v >> s) & 0xff);
  png += std::string("\x08\x06\0\0\0\0\0\0\0", 9);
  const std::string wide = write("wide.png", png);
  auto read = mfr::readPng(wide);
  ASSERT_FALSE(read.ok());
  EXPECT_TRUE(contains(read.error().message, wide) &&
              contains(read.error().message, "20000 x 16 pixels refused"))
      << read.error().message;
  const fs::path fifo = scratch() / "pipe.png";
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const CliRun r = mfr::test::runCliTimed("metrics " + fifo.string() + " " + wide, scratch());
  EXPECT_TRUE(cleanError(r, {"pipe.png", "FIFO"}));
}

}  // namespace
