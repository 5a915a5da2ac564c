// Confined file access (mfr/core/file_access.hpp, LoadOptions::allowOutsideReferences): files named
// inside a scene file (glTF buffers and images, OBJ mtllib and map_Kd, a JSON scene's mesh) resolve
// only to regular files inside the naming file's folder. Absolute paths, `..` escapes, symbolic
// links leading outside, FIFOs and devices are refused with one line naming the reference, before
// anything is opened; --allow-outside-references lifts the folder rule only. Cases that could hang
// (FIFOs) run the CLI under `timeout 10`.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_timeout.hpp"
#include "error_assertions.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/image.hpp"
#include "mfr/scene/load.hpp"
#include "scratch_folder.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::cleanError;
using mfr::test::CliRun;
using mfr::test::contains;
using nlohmann::json;

/// A fresh folder per test: `model/` holds the scene files, files beside `model/` are "outside".
class Confinement : public mfr::test::ScratchFolderTest {
 protected:
  Confinement() : ScratchFolderTest("mfr_confinement") {}
  std::string write(const fs::path& path, const std::string& bytes) const {
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << bytes;
    return path.string();
  }
  void fifo(const fs::path& path) const { ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0) << path; }
  CliRun cli(const std::string& args, const mfr::test::TimedCliOptions& options = {}) const {
    return mfr::test::runCliTimed(args, root(), options);
  }
};

/// One triangle, three float positions: 36 bytes.
std::string triangleBytes() {
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  return std::string(reinterpret_cast<const char*>(p), sizeof p);
}

/// A glTF drawing one triangle from an external buffer `bufferUri` declaring `byteLength`; with
/// `imageUri`, its material's base colour texture is that image.
std::string gltfText(const std::string& bufferUri, uint64_t byteLength = 36,
                     const std::string& imageUri = "") {
  json doc = {{"asset", {{"version", "2.0"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {{{"mesh", 0}}}},
              {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
              {"accessors",
               {{{"bufferView", 0},
                 {"componentType", 5126},
                 {"count", 3},
                 {"type", "VEC3"},
                 {"min", {0, 0, 0}},
                 {"max", {1, 1, 0}}}}},
              {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
              {"buffers", {{{"byteLength", byteLength}, {"uri", bufferUri}}}}};
  if (!imageUri.empty()) {
    doc["meshes"][0]["primitives"][0]["material"] = 0;
    doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    doc["textures"] = {{{"source", 0}}};
    doc["images"] = {{{"uri", imageUri}}};
  }
  return doc.dump();
}

/// A PNG whose header (IHDR) claims width x height RGBA8 pixels, without pixel data: the decoder
/// must never get to allocate them.
std::string pngHeaderClaiming(uint32_t width, uint32_t height) {
  std::string png("\x89PNG\r\n\x1a\n", 8);
  const auto be32 = [&](uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) png += static_cast<char>((v >> s) & 0xff);
  };
  be32(13);
  png += "IHDR";
  be32(width);
  be32(height);
  png += std::string("\x08\x06\x00\x00\x00", 5);  // 8 bits, RGBA, deflate, no filter, progressive
  be32(0);                                        // CRC (not checked by stb_image)
  be32(0);
  png += "IEND";
  be32(0);
  return png;
}

std::string validPng(const fs::path& path) {
  mfr::Image8 image;
  image.width = image.height = 2;
  image.rgba.assign(16, 200);
  EXPECT_TRUE(mfr::writePng(path.string(), image).ok());
  return path.string();
}

/// A refused load: one line naming the scene file and `reference`, containing `problem`.
::testing::AssertionResult refused(const mfr::Result<mfr::Scene>& result, const std::string& file,
                                   const std::string& reference, const std::string& problem) {
  if (result.ok()) return ::testing::AssertionFailure() << "loaded, expected a refusal";
  const std::string& m = result.error().message;
  if (!contains(m, file) || !contains(m, reference) || !contains(m, problem) || contains(m, "\n"))
    return ::testing::AssertionFailure()
           << "message '" << m << "' should be one line naming '" << file << "' and '" << reference
           << "' with '" << problem << "'";
  return ::testing::AssertionSuccess();
}

mfr::LoadOptions allowOutside() {
  mfr::LoadOptions options;
  options.allowOutsideReferences = true;
  return options;
}

// ---------------------------------------------------------------------------------------------
// glTF buffers

TEST_F(Confinement, GltfBufferInsideTheFolderOrASubfolderLoads) {
  write(model() / "data.bin", triangleBytes());
  write(model() / "sub" / "deeper.bin", triangleBytes());
  auto plain = mfr::loadScene(write(model() / "plain.gltf", gltfText("data.bin")));
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  EXPECT_EQ(plain->triangleCount(), 1u);
  auto sub = mfr::loadScene(write(model() / "sub.gltf", gltfText("sub/deeper.bin")));
  ASSERT_TRUE(sub.ok()) << sub.error().message;
  // `..` that stays inside, a symbolic link to a file inside, and %-encoding are fine too
  auto inside = mfr::loadScene(write(model() / "inside.gltf", gltfText("sub/../data.bin")));
  ASSERT_TRUE(inside.ok()) << inside.error().message;
  fs::create_symlink("data.bin", model() / "link_inside.bin");
  auto link = mfr::loadScene(write(model() / "link.gltf", gltfText("link_inside.bin")));
  ASSERT_TRUE(link.ok()) << link.error().message;
  write(model() / "with space.bin", triangleBytes());
  auto encoded = mfr::loadScene(write(model() / "encoded.gltf", gltfText("with%20space.bin")));
  ASSERT_TRUE(encoded.ok()) << encoded.error().message;
}

TEST_F(Confinement, GltfBufferUriEscapingTheFolderIsRefusedWithoutOpeningIt) {
  // the issue's case: the refusal names the uri and says nothing of the file (no size)
  const std::string passwd = write(model() / "passwd.gltf", gltfText("../../../../etc/passwd"));
  auto result = mfr::loadScene(passwd);
  EXPECT_TRUE(refused(result, passwd, "buffer 0 uri '../../../../etc/passwd'", "outside"));
  ASSERT_FALSE(result.ok());
  EXPECT_FALSE(contains(result.error().message, "size")) << result.error().message;
  EXPECT_FALSE(contains(result.error().message, "requestedBytes")) << result.error().message;

  // the target outside is a FIFO: opening it would block, so a refusal that returns at all and
  // talks about the folder (not the FIFO) was decided before the file was touched
  fifo(root() / "outside_fifo");
  const std::string escape = write(model() / "escape.gltf", gltfText("../outside_fifo"));
  EXPECT_TRUE(refused(mfr::loadScene(escape), escape, "'../outside_fifo'", "outside the folder"));
  EXPECT_TRUE(refused(mfr::loadScene(escape, allowOutside()), escape, "'../outside_fifo'", "FIFO"));

  // %-encoded dots are decoded before the check, as tinygltf decodes them before opening
  const std::string encoded = write(model() / "encoded.gltf", gltfText("%2E%2E/outside_fifo"));
  EXPECT_TRUE(refused(mfr::loadScene(encoded), encoded, "'%2E%2E/outside_fifo'", "outside"));
  // a binary glTF (GLB) naming an external buffer is checked the same way
  const std::string jsonChunk = [] {
    std::string text = gltfText("../outside_fifo");
    while (text.size() % 4 != 0) text += ' ';
    return text;
  }();
  std::string glb = "glTF";
  const auto le32 = [&glb](uint32_t v) {
    for (int i = 0; i < 4; ++i) glb += static_cast<char>((v >> (8 * i)) & 0xff);
  };
  le32(2);
  le32(static_cast<uint32_t>(20 + jsonChunk.size()));
  le32(static_cast<uint32_t>(jsonChunk.size()));
  le32(0x4E4F534Au);  // "JSON"
  glb += jsonChunk;
  const std::string binary = write(model() / "escape.glb", glb);
  EXPECT_TRUE(refused(mfr::loadScene(binary), binary, "buffer 0 uri '../outside_fifo'", "outside"));

  // with the folder rule lifted, a regular file outside loads
  write(root() / "outside.bin", triangleBytes());
  const std::string outside = write(model() / "outside.gltf", gltfText("../outside.bin"));
  EXPECT_TRUE(refused(mfr::loadScene(outside), outside, "'../outside.bin'", "outside"));
  auto allowed = mfr::loadScene(outside, allowOutside());
  ASSERT_TRUE(allowed.ok()) << allowed.error().message;
  EXPECT_EQ(allowed->triangleCount(), 1u);
}

TEST_F(Confinement, GltfAbsoluteBufferUriIsRefusedEvenInsideTheFolder) {
  const std::string bin = write(model() / "data.bin", triangleBytes());
  const std::string path = write(model() / "absolute.gltf", gltfText(bin));
  EXPECT_TRUE(refused(mfr::loadScene(path), path, "'" + bin + "'", "absolute"));
  auto allowed = mfr::loadScene(path, allowOutside());
  ASSERT_TRUE(allowed.ok()) << allowed.error().message;
}

TEST_F(Confinement, GltfSymbolicLinkLeadingOutsideIsRefused) {
  write(root() / "outside.bin", triangleBytes());
  fs::create_symlink("../outside.bin", model() / "link.bin");
  const std::string path = write(model() / "link.gltf", gltfText("link.bin"));
  EXPECT_TRUE(refused(mfr::loadScene(path), path, "'link.bin'", "symbolic link"));
  // a symlinked folder leading outside, too
  fs::create_directories(root() / "elsewhere");
  write(root() / "elsewhere" / "data.bin", triangleBytes());
  fs::create_directory_symlink("../elsewhere", model() / "linked_folder");
  const std::string folder = write(model() / "folder.gltf", gltfText("linked_folder/data.bin"));
  EXPECT_TRUE(refused(mfr::loadScene(folder), folder, "'linked_folder/data.bin'", "outside"));
  EXPECT_TRUE(mfr::loadScene(path, allowOutside()).ok());
}

TEST_F(Confinement, GltfBufferNotFoundInItsFolderIsNotLookedUpInTheWorkingFolder) {
  // tinygltf on its own retries a missing file in the working folder; mfr does not
  write(root() / "x.bin", triangleBytes());
  write(model() / "s.gltf", gltfText("x.bin"));
  const CliRun r = cli("info model/s.gltf --width 16 --height 16 -q", mfr::test::inDir(root()));
  EXPECT_TRUE(cleanError(r, {"model/s.gltf", "buffer 0 uri 'x.bin'", "no such file"}));
}

TEST_F(Confinement, GltfByteLengthIsCheckedAgainstTheFileSizeBeforeReading) {
  write(model() / "data.bin", triangleBytes());
  const std::string path = write(model() / "huge.gltf", gltfText("data.bin", 1000000000000ull));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(refused(mfr::loadScene(path), path, "buffer 0 uri 'data.bin'",
                      "byteLength 1000000000000 differs from the file's size, 36 bytes"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  const std::string shorter = write(model() / "short.gltf", gltfText("data.bin", 12));
  EXPECT_TRUE(refused(mfr::loadScene(shorter), shorter, "'data.bin'", "byteLength 12"));
  // a data URI stays allowed
  const std::string data = write(model() / "data_uri.gltf",
                                 gltfText("data:application/octet-stream;base64,"
                                          "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"));
  auto loaded = mfr::loadScene(data);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded->triangleCount(), 1u);
}

TEST_F(Confinement, GltfFifoAndDeviceAreRefusedWithoutHanging) {
  write(model() / "data.bin", triangleBytes());
  fifo(model() / "pipe.bin");
  write(model() / "fifo.gltf", gltfText("pipe.bin"));
  const CliRun r = cli("info model/fifo.gltf --width 16 --height 16 -q", mfr::test::inDir(root()));
  EXPECT_TRUE(cleanError(r, {"model/fifo.gltf", "buffer 0 uri 'pipe.bin'", "FIFO"}));
  const CliRun allowed =
      cli("info model/fifo.gltf --width 16 --height 16 -q "
          "--allow-outside-references",
          mfr::test::inDir(root()));
  EXPECT_TRUE(cleanError(allowed, {"'pipe.bin'", "FIFO"}));
  // a device: absolute (refused as such), then allowed outside (refused as a device, not read)
  write(model() / "zero.gltf", gltfText("/dev/zero"));
  EXPECT_TRUE(cleanError(cli("info model/zero.gltf -q", mfr::test::inDir(root())),
                         {"'/dev/zero'", "absolute"}));
  EXPECT_TRUE(cleanError(
      cli("info model/zero.gltf -q --allow-outside-references", mfr::test::inDir(root())),
      {"'/dev/zero'", "device"}));
  // and through a symbolic link inside the folder
  fs::create_symlink("/dev/zero", model() / "zero.bin");
  write(model() / "zero_link.gltf", gltfText("zero.bin"));
  EXPECT_TRUE(cleanError(
      cli("info model/zero_link.gltf -q --allow-outside-references", mfr::test::inDir(root())),
      {"'zero.bin'", "device"}));
}

// ---------------------------------------------------------------------------------------------
// glTF images

TEST_F(Confinement, GltfImageUriIsConfinedLikeBuffers) {
  write(model() / "data.bin", triangleBytes());
  validPng(root() / "outside.png");
  validPng(model() / "tex.png");
  auto inside = mfr::loadScene(write(model() / "inside.gltf", gltfText("data.bin", 36, "tex.png")));
  ASSERT_TRUE(inside.ok()) << inside.error().message;
  EXPECT_EQ(inside->textures.size(), 1u);

  const std::string escape =
      write(model() / "escape.gltf", gltfText("data.bin", 36, "../outside.png"));
  EXPECT_TRUE(refused(mfr::loadScene(escape), escape, "image 0 uri '../outside.png'", "outside"));
  auto allowed = mfr::loadScene(escape, allowOutside());
  ASSERT_TRUE(allowed.ok()) << allowed.error().message;
  EXPECT_EQ(allowed->textures.size(), 1u);

  const std::string absolute = (root() / "outside.png").string();
  const std::string abs = write(model() / "abs.gltf", gltfText("data.bin", 36, absolute));
  EXPECT_TRUE(refused(mfr::loadScene(abs), abs, "image 0 uri '" + absolute + "'", "absolute"));

  fifo(model() / "pipe.png");
  write(model() / "fifo.gltf", gltfText("data.bin", 36, "pipe.png"));
  EXPECT_TRUE(cleanError(
      cli("info model/fifo.gltf -q --allow-outside-references", mfr::test::inDir(root())),
      {"image 0 uri 'pipe.png'", "FIFO"}));
}

TEST_F(Confinement, GltfImageHeaderBeyondTheSizeCapIsRefusedBeforeDecoding) {
  write(model() / "data.bin", triangleBytes());
  write(model() / "huge.png", pngHeaderClaiming(100000, 100000));
  write(model() / "wide.png", pngHeaderClaiming(20000, 16));
  const auto start = std::chrono::steady_clock::now();
  const std::string huge = write(model() / "huge.gltf", gltfText("data.bin", 36, "huge.png"));
  auto result = mfr::loadScene(huge);
  ASSERT_FALSE(result.ok());
  EXPECT_TRUE(contains(result.error().message, huge) &&
              contains(result.error().message, "image 0 ('huge.png')"))
      << result.error().message;
  const std::string wide = write(model() / "wide.gltf", gltfText("data.bin", 36, "wide.png"));
  EXPECT_TRUE(refused(mfr::loadScene(wide), wide, "image 0 ('wide.png')",
                      "20000 x 16 pixels refused (at most 16384 x 16384)"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

// ---------------------------------------------------------------------------------------------
// OBJ: mtllib and map_Kd

const char* kObjBody =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";

TEST_F(Confinement, ObjMtllibIsConfinedToTheObjFolder) {
  write(root() / "outside.mtl", "newmtl m\nKd 1 0 0\nd 0.5\n");
  write(model() / "sub" / "inside.mtl", "newmtl m\nKd 0 1 0\n");
  auto inside = mfr::loadScene(
      write(model() / "inside.obj", std::string("mtllib sub/inside.mtl\n") + kObjBody));
  ASSERT_TRUE(inside.ok()) << inside.error().message;
  EXPECT_EQ(inside->materials[0].baseColor, glm::vec4(0, 1, 0, 1));

  const std::string escape =
      write(model() / "escape.obj", std::string("mtllib ../outside.mtl\n") + kObjBody);
  EXPECT_TRUE(refused(mfr::loadScene(escape), escape, "mtllib '../outside.mtl'", "outside"));
  auto allowed = mfr::loadScene(escape, allowOutside());
  ASSERT_TRUE(allowed.ok()) << allowed.error().message;
  EXPECT_FLOAT_EQ(allowed->materials[0].baseColor.a, 0.5f);

  const std::string absolutePath = (root() / "outside.mtl").string();
  const std::string abs = write(model() / "abs.obj", "mtllib " + absolutePath + "\n" + kObjBody);
  EXPECT_TRUE(refused(mfr::loadScene(abs), abs, "mtllib '" + absolutePath + "'", "absolute"));

  fs::create_symlink("../outside.mtl", model() / "link.mtl");
  const std::string link = write(model() / "link.obj", std::string("mtllib link.mtl\n") + kObjBody);
  EXPECT_TRUE(refused(mfr::loadScene(link), link, "mtllib 'link.mtl'", "symbolic link"));

  // a missing MTL inside the folder still only falls back to the default material
  auto missing =
      mfr::loadScene(write(model() / "missing.obj", std::string("mtllib absent.mtl\n") + kObjBody));
  ASSERT_TRUE(missing.ok()) << missing.error().message;
}

TEST_F(Confinement, ObjMtllibFifoIsRefusedWithoutHanging) {
  fifo(model() / "pipe.mtl");
  write(model() / "fifo.obj", std::string("mtllib pipe.mtl\n") + kObjBody);
  EXPECT_TRUE(cleanError(cli("info model/fifo.obj -q", mfr::test::inDir(root())),
                         {"model/fifo.obj", "mtllib 'pipe.mtl'", "FIFO"}));
  EXPECT_TRUE(
      cleanError(cli("info model/fifo.obj -q --allow-outside-references", mfr::test::inDir(root())),
                 {"mtllib 'pipe.mtl'", "FIFO"}));
}

TEST_F(Confinement, ObjMapKdIsConfinedToItsMtlFolder) {
  validPng(root() / "outside.png");
  validPng(model() / "tex" / "inside.png");
  write(model() / "inside.mtl", "newmtl m\nmap_Kd tex/inside.png\n");
  auto inside =
      mfr::loadScene(write(model() / "inside.obj", std::string("mtllib inside.mtl\n") + kObjBody));
  ASSERT_TRUE(inside.ok()) << inside.error().message;
  EXPECT_EQ(inside->textures.size(), 1u);

  write(model() / "escape.mtl", "newmtl m\nmap_Kd ../outside.png\n");
  const std::string escape =
      write(model() / "escape.obj", std::string("mtllib escape.mtl\n") + kObjBody);
  EXPECT_TRUE(refused(mfr::loadScene(escape), escape, "map_Kd '../outside.png'", "outside"));
  auto allowed = mfr::loadScene(escape, allowOutside());
  ASSERT_TRUE(allowed.ok()) << allowed.error().message;
  EXPECT_EQ(allowed->textures.size(), 1u);

  fs::create_symlink("../outside.png", model() / "link.png");
  write(model() / "link.mtl", "newmtl m\nmap_Kd link.png\n");
  const std::string link = write(model() / "link.obj", std::string("mtllib link.mtl\n") + kObjBody);
  EXPECT_TRUE(refused(mfr::loadScene(link), link, "map_Kd 'link.png'", "symbolic link"));

  fifo(model() / "pipe.png");
  write(model() / "fifo.mtl", "newmtl m\nmap_Kd pipe.png\n");
  write(model() / "fifo.obj", std::string("mtllib fifo.mtl\n") + kObjBody);
  EXPECT_TRUE(
      cleanError(cli("info model/fifo.obj -q --allow-outside-references", mfr::test::inDir(root())),
                 {"model/fifo.obj", "map_Kd 'pipe.png'", "FIFO"}));
}

TEST_F(Confinement, ObjTextureHeaderBeyondTheSizeCapIsRefusedBeforeDecoding) {
  write(model() / "huge.png", pngHeaderClaiming(100000, 100000));
  write(model() / "wide.png", pngHeaderClaiming(20000, 16));
  write(model() / "huge.mtl", "newmtl m\nmap_Kd huge.png\n");
  write(model() / "wide.mtl", "newmtl m\nmap_Kd wide.png\n");
  const std::string huge = write(model() / "huge.obj", std::string("mtllib huge.mtl\n") + kObjBody);
  const std::string wide = write(model() / "wide.obj", std::string("mtllib wide.mtl\n") + kObjBody);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(refused(mfr::loadScene(huge), huge, "map_Kd 'huge.png'", "100000 x 100000 pixels"));
  EXPECT_TRUE(refused(mfr::loadScene(wide), wide, "map_Kd 'wide.png'", "20000 x 16 pixels"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

// ---------------------------------------------------------------------------------------------
// JSON scene: mesh

TEST_F(Confinement, JsonSceneMeshIsConfinedToItsFolder) {
  write(model() / "data.bin", triangleBytes());
  write(model() / "tri.gltf", gltfText("data.bin"));
  write(root() / "outside" / "data.bin", triangleBytes());
  write(root() / "outside" / "tri.gltf", gltfText("data.bin"));

  auto inside = mfr::loadScene(write(model() / "inside.json", R"({"mesh": "tri.gltf"})"));
  ASSERT_TRUE(inside.ok()) << inside.error().message;

  const std::string escape = write(model() / "escape.json", R"({"mesh": "../outside/tri.gltf"})");
  EXPECT_TRUE(refused(mfr::loadScene(escape), escape, "'mesh' ../outside/tri.gltf", "outside"));
  auto allowed = mfr::loadScene(escape, allowOutside());
  ASSERT_TRUE(allowed.ok()) << allowed.error().message;
  EXPECT_EQ(allowed->triangleCount(), 1u);

  const std::string target = (root() / "outside" / "tri.gltf").string();
  const std::string abs = write(model() / "abs.json", json{{"mesh", target}}.dump());
  EXPECT_TRUE(refused(mfr::loadScene(abs), abs, "'mesh' " + target, "absolute"));

  fs::create_symlink("../outside/tri.gltf", model() / "link.gltf");
  const std::string link = write(model() / "link.json", R"({"mesh": "link.gltf"})");
  EXPECT_TRUE(refused(mfr::loadScene(link), link, "'mesh' link.gltf", "symbolic link"));

  // the rule applies again inside the mesh file it names: the allowed glTF above names its own
  // buffer; one that escapes its folder is refused even when the JSON itself is fine
  write(model() / "sub" / "escaping.gltf", gltfText("../../outside/data.bin"));
  const std::string nested = write(model() / "nested.json", R"({"mesh": "sub/escaping.gltf"})");
  EXPECT_TRUE(refused(mfr::loadScene(nested), nested, "'../../outside/data.bin'", "outside"));
}

TEST_F(Confinement, JsonSceneMeshFifoIsRefusedWithoutHanging) {
  fifo(model() / "pipe.gltf");
  write(model() / "fifo.json", R"({"mesh": "pipe.gltf"})");
  EXPECT_TRUE(cleanError(cli("info model/fifo.json -q", mfr::test::inDir(root())),
                         {"model/fifo.json", "'mesh' pipe.gltf", "FIFO"}));
  EXPECT_TRUE(cleanError(
      cli("info model/fifo.json -q --allow-outside-references", mfr::test::inDir(root())),
      {"'mesh' pipe.gltf", "FIFO"}));
}

// ---------------------------------------------------------------------------------------------
// The scene named on the command line, and the option on every scene command

TEST_F(Confinement, SceneGivenDirectlyMustBeARegularFile) {
  fifo(root() / "pipe.gltf");
  EXPECT_TRUE(cleanError(cli("render pipe.gltf -q -o out.png", mfr::test::inDir(root())),
                         {"pipe.gltf", "FIFO"}));
  fs::create_symlink("/dev/zero", root() / "zero.obj");
  EXPECT_TRUE(
      cleanError(cli("info zero.obj -q", mfr::test::inDir(root())), {"zero.obj", "device"}));
  EXPECT_TRUE(cleanError(cli("info . -q", mfr::test::inDir(root())), {"is a directory"}));
  // library entry points directly, too (no CLI in front)
  auto fifoScene = mfr::loadGltf((root() / "pipe.gltf").string(), {});
  ASSERT_FALSE(fifoScene.ok());
  EXPECT_TRUE(contains(fifoScene.error().message, "FIFO")) << fifoScene.error().message;
  for (auto* loader : {&mfr::loadObj, &mfr::loadPly, &mfr::loadJsonScene}) {
    auto r = (*loader)((root() / "pipe.gltf").string(), {});
    ASSERT_FALSE(r.ok());
    EXPECT_TRUE(contains(r.error().message, "FIFO")) << r.error().message;
  }
}

TEST_F(Confinement, ModelDatasetAndPngInputsMustBeRegularFiles) {
  fifo(root() / "pipe.mfrnn");
  fifo(root() / "pipe.mfrds");
  const mfr::test::TimedCliOptions here = mfr::test::inDir(root());
  EXPECT_TRUE(cleanError(cli("render procedural:layers --width 16 --height 16 -q -o a.png "
                             "--method dkb --budget 64KB --model pipe.mfrnn",
                             here),
                         {"pipe.mfrnn", "not a regular file"}));
  EXPECT_TRUE(cleanError(cli("train pipe.mfrds -q -o m.mfrnn", here),
                         {"pipe.mfrds", "not a regular file"}));
  validPng(root() / "a.png");
  EXPECT_TRUE(cleanError(cli("metrics a.png pipe.mfrnn", here), {"pipe.mfrnn", "FIFO"}));
}

TEST_F(Confinement, AllowOutsideReferencesLetsTheEscapeLoadButNeverAFifo) {
  write(root() / "outside.bin", triangleBytes());
  write(model() / "escape.gltf", gltfText("../outside.bin"));
  fifo(model() / "pipe.bin");
  write(model() / "fifo.gltf", gltfText("pipe.bin"));
  const mfr::test::TimedCliOptions here = mfr::test::inDir(root());
  EXPECT_TRUE(cleanError(cli("render model/escape.gltf --width 16 --height 16 -q -o a.png", here),
                         {"model/escape.gltf", "'../outside.bin'", "--allow-outside-references"}));
  EXPECT_FALSE(fs::exists(root() / "a.png"));
  const CliRun render =
      cli("render model/escape.gltf --width 16 --height 16 -q -o a.png --allow-outside-references",
          here);
  EXPECT_EQ(render.exitCode, 0) << render.err;
  EXPECT_TRUE(fs::exists(root() / "a.png"));
  EXPECT_TRUE(cleanError(cli("render model/fifo.gltf --width 16 --height 16 -q -o b.png "
                             "--allow-outside-references",
                             here),
                         {"'pipe.bin'", "FIFO"}));
  // every command that loads scenes takes the option
  const CliRun info =
      cli("info model/escape.gltf --width 16 --height 16 -q --allow-outside-references", here);
  EXPECT_EQ(info.exitCode, 0) << info.err;
  const CliRun compare =
      cli("compare model/escape.gltf --width 16 --height 16 -q --budget 64KB --methods fkb "
          "--out cmp --allow-outside-references",
          here);
  EXPECT_EQ(compare.exitCode, 0) << compare.err;
  EXPECT_TRUE(cleanError(cli("compare model/escape.gltf --width 16 --height 16 -q --budget 64KB "
                             "--methods fkb --out cmp2",
                             here),
                         {"'../outside.bin'", "outside"}));
  const CliRun dataset = cli(
      "dataset model/escape.gltf --width 16 --height 16 -q -o d.mfrds --allow-outside-references",
      here);
  EXPECT_EQ(dataset.exitCode, 0) << dataset.err;
  EXPECT_TRUE(
      cleanError(cli("dataset model/escape.gltf --width 16 --height 16 -q -o e.mfrds", here),
                 {"'../outside.bin'", "outside"}));
}

}  // namespace
