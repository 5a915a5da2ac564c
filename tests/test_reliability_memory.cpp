// The memory limit applies to what an input expands into (issue 49, rows 2 and 4-7): a glTF's
// vertices and triangles after node references and EXT_mesh_gpu_instancing, a procedural scene's
// from its parameters and `mfr metrics`' images and FLIP buffers are computed and checked against
// --memory-limit before any of it is built, and refused in one line naming the input, the bytes
// needed and the limit. The CLI runs as a child whose peak resident memory (wait4's ru_maxrss) is
// measured: it stays under the limit plus kRssMarginBytes. FLIP's pixels per degree has a range.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.hpp"
#include "error_assertions.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/procedural.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::contains;

/// What the CLI may hold beyond the memory limit: its code and libraries, thread stacks, the
/// file's bytes and parsed JSON, the per-pixel buffers of a small image (docs/ROBUSTNESS.md).
constexpr uint64_t kRssMarginBytes = uint64_t{64} << 20;

fs::path scratch() {
  static const fs::path dir = mfr::test::processTempDir("mfr_reliability_memory_test");
  return dir;
}

std::string write(const std::string& name, const std::string& bytes) {
  return mfr::test::writeFile(scratch() / name, bytes);
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct MeasuredRun {
  int exitCode = -1;
  bool signaled = false;
  bool timedOut = false;
  std::string err;
  uint64_t peakRssBytes = 0;  // the child's ru_maxrss
  double seconds = 0.0;
};

/// `mfr ARGS...` as a child of this process (no shell): its exit, stderr, wall time and peak
/// resident set size from wait4(), killed after `timeoutSeconds`.
MeasuredRun runMeasured(const std::vector<std::string>& args, int timeoutSeconds = 20) {
  const fs::path errPath = scratch() / "measured_stderr.txt";
  std::vector<std::string> argv = {MFR_CLI_PATH};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> raw;
  for (std::string& a : argv) raw.push_back(a.data());
  raw.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::FILE* err = std::freopen(errPath.c_str(), "w", stderr);
    std::FILE* out = std::freopen("/dev/null", "w", stdout);
    std::FILE* in = std::freopen("/dev/null", "r", stdin);
    if (err && out && in) ::execv(raw[0], raw.data());
    ::_exit(127);
  }
  MeasuredRun r;
  if (pid < 0) return r;
  int status = 0;
  rusage usage{};
  for (;;) {
    const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (r.seconds > timeoutSeconds && !r.timedOut) {
      r.timedOut = true;
      ::kill(pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.signaled = WIFSIGNALED(status);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.peakRssBytes = static_cast<uint64_t>(usage.ru_maxrss) * 1024;  // KiB on Linux
  r.err = readText(errPath);
  return r;
}

/// exit 1 within a few seconds, one "mfr: error:" line containing every part.
::testing::AssertionResult fastOneLine(const MeasuredRun& r,
                                       std::initializer_list<std::string> parts) {
  ::testing::AssertionResult clean =
      mfr::test::oneErrorLine(r.exitCode, r.signaled, r.timedOut, r.err, parts);
  if (!clean) return clean;
  if (r.seconds > 5.0) return ::testing::AssertionFailure() << r.seconds << " s: " << r.err;
  return ::testing::AssertionSuccess();
}

/// The bytes an error says are needed ("... need 8.25 GiB (8858370048 bytes), ...").
uint64_t neededBytes(const std::string& message) {
  const size_t need = message.find(" need ");
  const size_t open = message.find('(', need);
  if (need == std::string::npos || open == std::string::npos) return 0;
  return std::stoull(message.substr(open + 1));
}

// ---------------------------------------------------------------------------------------------
// Row 2: FLIP's pixels per degree

TEST(ReliabilityMemory, FlipPixelsPerDegreeOutsideItsRangeIsOneLineNamingTheRange) {
  for (double ppd : {1e8, 1e9, 1e10, 1e15, 1e30, 1000.5, 1.999, 1.0, 0.0, -3.0, std::nan(""),
                     std::numeric_limits<double>::infinity()}) {
    auto refused = mfr::checkFlipPixelsPerDegree(ppd);
    ASSERT_FALSE(refused.ok()) << ppd;
    EXPECT_EQ(refused.error().message.rfind("--ppd ", 0), 0u) << refused.error().message;
    EXPECT_TRUE(contains(refused.error().message, "must be in [2, 1000]"))
        << refused.error().message;
    auto python = mfr::checkFlipPixelsPerDegree(ppd, mfr::Spelling::Python);
    EXPECT_EQ(python.error().message.rfind("ppd ", 0), 0u) << python.error().message;
  }
  EXPECT_EQ(mfr::checkFlipPixelsPerDegree(1e10).error().message,
            "--ppd 1e+10: FLIP's pixels per degree must be in [2, 1000] (its filters are 0.27 "
            "ppd pixels wide; the default is 67.02)");
  // the library refuses it too, at once, whatever the front end
  mfr::Image8 image;
  image.width = image.height = 8;
  image.rgba.assign(8 * 8 * 4, 128);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(mfr::computeFlip(image, image, 1e15).ok());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  // both ends of the range give a finite map (below 2 the derivative filters were NaN)
  for (double ppd : {mfr::kFlipMinPixelsPerDegree, mfr::kFlipMaxPixelsPerDegree}) {
    mfr::Image8 board = image;
    for (size_t i = 0; i < board.rgba.size(); i += 8) board.rgba[i] = 255;
    auto flip = mfr::computeFlip(image, board, ppd);
    ASSERT_TRUE(flip.ok()) << flip.error().message;
    EXPECT_TRUE(std::isfinite(flip->mean) && flip->mean > 0.0) << ppd << ": " << flip->mean;
  }
}

TEST(ReliabilityMemory, FlipPixelsPerDegreeOfMetricsAndCompareIsCheckedBeforeAnyWork) {
  mfr::Image8 image;
  image.width = image.height = 4;
  image.rgba.assign(4 * 4 * 4, 200);
  const std::string png = (scratch() / "ppd.png").string();
  ASSERT_TRUE(mfr::writePng(png, image).ok());
  for (const char* ppd : {"1e8", "1e10", "1e15", "1e30"}) {
    EXPECT_TRUE(fastOneLine(runMeasured({"metrics", png, png, "--ppd", ppd}),
                            {"--ppd ", "must be in [2, 1000]"}))
        << ppd;
    EXPECT_TRUE(
        fastOneLine(runMeasured({"compare", "procedural:layers", "--width", "16", "--height", "16",
                                 "--methods", "fkb", "--budget", "1MB", "--ppd", ppd, "-q", "--out",
                                 (scratch() / "never_compare").string()}),
                    {"--ppd ", "must be in [2, 1000]"}))
        << ppd;
  }
  EXPECT_FALSE(fs::exists(scratch() / "never_compare"));
  const MeasuredRun fits = runMeasured({"metrics", png, png, "--ppd", "1000", "-q"});
  EXPECT_EQ(fits.exitCode, 0) << fits.err;
}

// ---------------------------------------------------------------------------------------------
// Rows 4 and 5: glTF node references and instancing

/// A glTF whose one mesh has a POSITION accessor of `count` zero vertices (no bufferView), used by
/// `nodes` nodes (the issue's file is 622 bytes with 4).
std::string sharedZeroAccessorGltf(int nodes, uint64_t count) {
  std::string nodeList, sceneNodes;
  for (int i = 0; i < nodes; ++i) {
    nodeList +=
        std::string(i ? "," : "") + R"({"mesh":0,"translation":[)" + std::to_string(i) + ",0,0]}";
    sceneNodes += std::string(i ? "," : "") + std::to_string(i);
  }
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[)" + sceneNodes +
         R"(]}],"nodes":[)" + nodeList +
         R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
         R"("accessors":[{"componentType":5126,"count":)" +
         std::to_string(count) + R"(,"type":"VEC3","min":[0,0,0],"max":[0,0,0]}]})";
}

TEST(ReliabilityMemory, GltfNodesSharingAZeroAccessorAreRefusedBeforeTheyAreBuilt) {
  for (int nodes : {4, 16, 32}) {
    const std::string file =
        write("shared_" + std::to_string(nodes) + ".gltf", sharedZeroAccessorGltf(nodes, 4194304));
    const MeasuredRun r =
        runMeasured({"render", file, "--width", "64", "--height", "64", "--memory-limit", "256MB",
                     "-q", "-o", (scratch() / "never.png").string()});
    const uint64_t vertices = uint64_t{4194304} * static_cast<uint64_t>(nodes);
    const uint64_t triangles = uint64_t{4194304 / 3} * static_cast<uint64_t>(nodes);
    EXPECT_TRUE(fastOneLine(
        r, {file + ": the " + std::to_string(vertices) + " vertices and " +
                std::to_string(triangles) + " triangles its nodes and instances place need",
            "more than the memory limit of 256.00 MiB (268435456 bytes"}))
        << nodes;
    EXPECT_GE(neededBytes(r.err), mfr::sceneMemoryBytes(vertices, triangles)) << r.err;
    EXPECT_LT(r.peakRssBytes, (uint64_t{256} << 20) + kRssMarginBytes) << r.err;
  }
  EXPECT_FALSE(fs::exists(scratch() / "never.png"));
  // the file of the issue is 622 bytes
  EXPECT_LT(sharedZeroAccessorGltf(4, 4194304).size(), 700u);
}

TEST(ReliabilityMemory, GltfThatFitsIsBuiltIntoArraysOfItsExactSize) {
  // three nodes drawing one triangle: the scene's arrays are reserved once at their final size,
  // the unused uvs and colours freed
  mfr::LoadOptions options;
  options.memoryLimitBytes = uint64_t{256} << 20;
  const std::string tri =
      R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1,2]}],"nodes":[)"
      R"({"mesh":0},{"mesh":0,"translation":[2,0,0]},{"mesh":0,"translation":[4,0,0]}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"accessors":[{"bufferView":0,)"
      R"("componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36,"uri":)"
      R"("data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
  auto loaded = mfr::loadGltf(write("tri3.gltf", tri), options);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded->positions.size(), 9u);
  EXPECT_EQ(loaded->positions.capacity(), 9u);
  EXPECT_EQ(loaded->indices.capacity(), 9u);
  EXPECT_EQ(loaded->uvs.capacity(), 0u);
  EXPECT_EQ(loaded->colors.capacity(), 0u);
  // a limit below what the three triangles need refuses them, naming the counts
  options.memoryLimitBytes = mfr::sceneMemoryBytes(9, 3) - 1;
  auto refused = mfr::loadGltf(write("tri3.gltf", tri), options);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(contains(refused.error().message, "the 9 vertices and 3 triangles"))
      << refused.error().message;
}

/// A triangle drawn by a node with EXT_mesh_gpu_instancing of `instances` instances whose
/// TRANSLATION accessor has no bufferView (zeros): the issue's 808-byte file.
std::string instancingGltf(uint64_t instances) {
  return R"({"asset":{"version":"2.0"},"extensionsUsed":["EXT_mesh_gpu_instancing"],"scene":0,)"
         R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":)"
         R"({"attributes":{"TRANSLATION":1}}}}],"meshes":[{"primitives":[{"attributes":)"
         R"({"POSITION":0}}]}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,)"
         R"("type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"componentType":5126,"count":)" +
         std::to_string(instances) +
         R"(,"type":"VEC3"}],"bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[)"
         R"({"byteLength":36,"uri":"data:application/octet-stream;base64,)"
         R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
}

TEST(ReliabilityMemory, InstancingFromAZeroAccessorIsRefusedBeforeAnyInstanceIsBuilt) {
  const std::string file = write("instances.gltf", instancingGltf(4194304));
  const MeasuredRun r =
      runMeasured({"render", file, "--width", "64", "--height", "64", "--memory-limit", "1GB", "-q",
                   "-o", (scratch() / "never.png").string()});
  EXPECT_TRUE(fastOneLine(r, {file + ": the 12582912 vertices and 4194304 triangles",
                              "more than the memory limit of 1.00 GiB (1073741824 bytes"}));
  // the old check ran after the first instance was built: 2.4 GB before refusing
  EXPECT_LT(r.peakRssBytes, (uint64_t{1} << 30) + kRssMarginBytes) << r.err;
  EXPECT_LT(r.peakRssBytes, uint64_t{256} << 20) << "refused before reading the instances";
  EXPECT_FALSE(fs::exists(scratch() / "never.png"));
  // a few instances of the same file render
  const MeasuredRun fits =
      runMeasured({"render", write("few.gltf", instancingGltf(8)), "--width", "32", "--height",
                   "32", "--memory-limit", "64MB", "-q", "-o", (scratch() / "few.png").string()});
  EXPECT_EQ(fits.exitCode, 0) << fits.err;
  // the node's mesh does not exist (found by fuzzing): refused before its 4 M instances are read,
  // which the expansion check, counting no mesh, had not charged
  std::string noMesh = instancingGltf(4194304);
  noMesh.replace(noMesh.find(R"("mesh":0)"), 8, R"("mesh":5)");
  const std::string missing = write("no_mesh.gltf", noMesh);
  const MeasuredRun r2 =
      runMeasured({"render", missing, "--width", "64", "--height", "64", "--memory-limit", "32MB",
                   "-q", "-o", (scratch() / "never.png").string()});
  EXPECT_TRUE(fastOneLine(r2, {missing + ": ", "mesh 5 does not exist"}));
  EXPECT_LT(r2.peakRssBytes, (uint64_t{32} << 20) + kRssMarginBytes) << r2.err;
}

// ---------------------------------------------------------------------------------------------
// Row 6: procedural scenes

TEST(ReliabilityMemory, ProceduralSmokeOfTenMillionParticlesIsRefusedFromItsParameters) {
  const MeasuredRun r =
      runMeasured({"render", "procedural:smoke?count=10000000", "--width", "64", "--height", "64",
                   "--memory-limit", "2GB", "-q", "-o", (scratch() / "never.png").string()});
  EXPECT_TRUE(fastOneLine(r, {"procedural:smoke?count=10000000: ",
                              "its 20000000 triangles and up to 40000000 vertices need",
                              "more than the memory limit of 2.00 GiB (2147483648 bytes"}));
  EXPECT_LT(r.peakRssBytes, uint64_t{256} << 20) << "refused before building: " << r.err;
  EXPECT_FALSE(fs::exists(scratch() / "never.png"));
  // the library says the same
  auto scene = mfr::makeProceduralScene("smoke?count=10000000", 1, mfr::kMaxProceduralTriangles,
                                        uint64_t{2} << 30);
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(neededBytes(scene.error().message), mfr::sceneMemoryBytes(40000000, 20000000));
}

TEST(ReliabilityMemory, PeakResidentMemoryOfAnAcceptedSceneStaysUnderTheLimitPlusTheMargin) {
  // 200,000 particles need 238 MiB by sceneMemoryBytes: accepted under 256 MB, and the measured
  // peak of loading, setting up and rendering it stays below the limit plus the margin;
  // 230,000 need 274 MiB: refused
  const uint64_t limit = uint64_t{256} << 20;
  const MeasuredRun fits =
      runMeasured({"render", "procedural:smoke?count=200000", "--width", "64", "--height", "64",
                   "--memory-limit", "256MB", "-q", "-o", (scratch() / "smoke.png").string()},
                  60);
  EXPECT_EQ(fits.exitCode, 0) << fits.err;
  EXPECT_LT(fits.peakRssBytes, limit + kRssMarginBytes);
  EXPECT_GT(fits.peakRssBytes, uint64_t{64} << 20);  // it did build the scene
  const MeasuredRun over =
      runMeasured({"render", "procedural:smoke?count=230000", "--width", "64", "--height", "64",
                   "--memory-limit", "256MB", "-q", "-o", (scratch() / "never.png").string()});
  EXPECT_TRUE(fastOneLine(over, {"procedural:smoke?count=230000", "256.00 MiB"}));
}

TEST(ReliabilityMemory, RenderBuffersAreCheckedBesideTheSceneNotAgainstTheWholeLimit) {
  // 200,000 particles hold 238 MiB by sceneMemoryBytes; at 1024 x 1024 the A-buffer's per-pixel
  // buffers take tens of MiB more: each fits 256 MB alone, together they do not
  const MeasuredRun both =
      runMeasured({"render", "procedural:smoke?count=200000", "--width", "1024", "--height", "1024",
                   "--memory-limit", "256MB", "-q", "-o", (scratch() / "never.png").string()},
                  60);
  EXPECT_TRUE(both.exitCode == 1 && contains(both.err, "per-pixel buffers and the scene's") &&
              contains(both.err, "256.00 MiB"))
      << both.err;
  EXPECT_LT(both.peakRssBytes, (uint64_t{256} << 20) + kRssMarginBytes);
  EXPECT_FALSE(fs::exists(scratch() / "never.png"));
}

TEST(ReliabilityMemory, ProceduralScenesMakeAtMostTwoVerticesATriangle) {
  // checkTriangleBudget counts twice the triangles as vertices: no scene makes more
  for (const std::string& name : mfr::proceduralSceneNames()) {
    auto scene = mfr::makeProceduralScene(name, 1);
    ASSERT_TRUE(scene.ok()) << name << ": " << scene.error().message;
    EXPECT_LE(scene->vertexCount(), 2 * scene->triangleCount()) << name;
  }
}

// ---------------------------------------------------------------------------------------------
// Row 7: mfr metrics of large images

/// CRC-32 of PNG chunks (ISO 3309).
uint32_t crc32(const std::string& bytes) {
  uint32_t crc = 0xffffffffu;
  for (unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xffffffffu;
}

std::string bigEndian(uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
          static_cast<char>(v)};
}

std::string chunk(const std::string& type, const std::string& data) {
  return bigEndian(static_cast<uint32_t>(data.size())) + type + data +
         bigEndian(crc32(type + data));
}

/// A black width x height PNG (1-bit grey) in a few hundred kilobytes, made without holding its
/// pixels: the zlib stream of its zero rows is one fixed-Huffman deflate block of a literal 0 and
/// repeated 258-byte copies at distance 1 (RFC 1951 3.2.6).
std::string blackPng(uint32_t width, uint32_t height) {
  const uint64_t raw = uint64_t{height} * (1 + (width + 7) / 8);  // a filter byte a row
  std::string zlib = "\x78\x01";
  uint64_t bits = 0;
  int count = 0;
  const auto put = [&](uint32_t value, int n) {  // LSB first
    bits |= uint64_t{value} << count;
    count += n;
    while (count >= 8) {
      zlib += static_cast<char>(bits & 0xff);
      bits >>= 8;
      count -= 8;
    }
  };
  const auto huffman = [&](uint32_t code, int n) {  // Huffman codes go most significant bit first
    uint32_t reversed = 0;
    for (int i = 0; i < n; ++i) reversed |= ((code >> i) & 1u) << (n - 1 - i);
    put(reversed, n);
  };
  put(1, 1);         // BFINAL
  put(1, 2);         // fixed Huffman codes
  huffman(0x30, 8);  // literal 0
  uint64_t left = raw - 1;
  for (; left >= 258; left -= 258) {
    huffman(0xc5, 8);  // length 258 (code 285)
    huffman(0, 5);     // distance 1 (code 0)
  }
  for (; left > 0; --left) huffman(0x30, 8);
  huffman(0, 7);  // end of block
  if (count > 0) put(0, 8 - count);
  zlib += bigEndian(static_cast<uint32_t>(((raw % 65521) << 16) | 1));  // Adler-32 of zeros
  const std::string ihdr = bigEndian(width) + bigEndian(height) + std::string("\x01\0\0\0\0", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", zlib) +
         chunk("IEND", "");
}

TEST(ReliabilityMemory, MetricsOfTwo16384SquaredPngsIsRefusedFromTheirHeaders) {
  const std::string png = blackPng(16384, 16384);
  EXPECT_LT(png.size(), 400u << 10);
  const std::string a = write("big_a.png", png), b = write("big_b.png", png);
  const MeasuredRun r = runMeasured({"metrics", a, b, "--memory-limit", "1GB"});
  EXPECT_TRUE(fastOneLine(r, {a + ": 16384 x 16384 pixels: the two images and FLIP's buffers need",
                              "more than the memory limit of 1.00 GiB (1073741824 bytes; "
                              "--memory-limit)"}));
  // at least FLIP's planes and the two decoded images
  EXPECT_GE(neededBytes(r.err), mfr::flipWorkingBytes(16384, 16384) + (uint64_t{2} << 30)) << r.err;
  EXPECT_FALSE(contains(r.err, "--width")) << r.err;  // metrics takes no such option
  EXPECT_LT(r.peakRssBytes, uint64_t{128} << 20) << "refused before decoding: " << r.err;
  // the same writer's small images decode, and their metrics fit a small limit
  const std::string small = write("small.png", blackPng(300, 200));
  const MeasuredRun fits = runMeasured({"metrics", small, small, "--memory-limit", "64MB", "-q"});
  EXPECT_EQ(fits.exitCode, 0) << fits.err;
  // the option is parsed and documented
  EXPECT_TRUE(fastOneLine(runMeasured({"metrics", small, small, "--memory-limit", "lots"}),
                          {"--memory-limit 'lots'"}));
}

}  // namespace
