// Scene files as a hostile user writes them (issue 29): each case is the input that once loaded
// wrongly, hung or gave a misleading message, written here, and the behaviour mfr now promises:
// one line naming the file and the problem, or a correct scene.
//  - GLB chunk lengths beyond the file; a buffer swapped for a symbolic link while loading;
//  - required glTF extensions mfr does not implement; strides, data URIs, camera fields;
//  - OBJ polygons of a million corners, face indices beyond 32 bits;
//  - PLY headers of 200,000 element lines;
//  - inputs echoed in errors are cut to a bounded length.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "error_assertions.hpp"
#include "gltf_quads.hpp"
#include "mfr/scene/load.hpp"
#include "scene/polygon.hpp"
#include "scratch_folder.hpp"

namespace {

namespace fs = std::filesystem;
using mfr::test::contains;
using mfr::test::refused;
using nlohmann::json;

class HostileInputs : public mfr::test::ScratchFolderTest {
 protected:
  HostileInputs() : ScratchFolderTest("mfr_hostile") {}
  std::string write(const std::string& name, const std::string& bytes) const {
    return mfr::test::writeFile(model() / name, bytes);
  }
};

std::string floatBytes(const std::vector<float>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
}

/// A glTF drawing one triangle with `positions` from buffer 0 (`uri`, or the GLB's BIN chunk
/// when empty).
json triangleGltf(const std::string& uri, size_t byteLength = 36) {
  json buffer = {{"byteLength", byteLength}};
  if (!uri.empty()) buffer["uri"] = uri;
  return {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
      {"buffers", {buffer}}};
}

const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

std::string dataUri(const std::string& bytes) {
  return "data:application/octet-stream;base64," + mfr::test::base64Encode(bytes);
}

void le32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}

/// A GLB of `doc` with `bin` as its BIN chunk; `binLengthExtra` is added to the BIN chunk's
/// declared length only (the file keeps its true size in the header).
std::string glb(const json& doc, const std::string& bin, uint32_t binLengthExtra = 0) {
  std::string text = doc.dump();
  while (text.size() % 4 != 0) text += ' ';
  std::string out = "glTF";
  le32(out, 2);
  le32(out, static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
  le32(out, static_cast<uint32_t>(text.size()));
  le32(out, 0x4E4F534Au);
  out += text;
  le32(out, static_cast<uint32_t>(bin.size()) + binLengthExtra);
  le32(out, 0x004E4942u);
  out += bin;
  return out;
}

// ---------------------------------------------------------------------------------------------
// glTF

TEST_F(HostileInputs, GlbChunkLengthsBeyondTheFileAreRefusedBeforeTheLoaderReadsThem) {
  // the same triangle twice in the BIN chunk: with 8 bytes claimed past the end, the loader read
  // two vertices from beyond the buffer
  const std::string bin = floatBytes(kTriangle) + floatBytes(kTriangle);
  json doc = triangleGltf("", bin.size());
  const std::string good = write("good.glb", glb(doc, bin));
  auto loaded = mfr::loadScene(good);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded->triangleCount(), 1u);

  const std::string over = write("over.glb", glb(doc, bin, 8));
  EXPECT_TRUE(refused(mfr::loadScene(over), over,
                      {"GLB chunk 1 (BIN) declares 80 bytes, only 72 are left"}));
  // the header's total length beyond the file (a truncated download)
  std::string cut = glb(doc, bin);
  cut.resize(cut.size() - 16);
  const std::string truncated = write("truncated.glb", cut);
  EXPECT_TRUE(refused(mfr::loadScene(truncated), truncated, {"GLB header declares"}));
  // the JSON chunk's length beyond the file
  std::string json = glb(doc, bin);
  json[12] = '\xff';
  json[13] = '\xff';
  const std::string badJson = write("json.glb", json);
  EXPECT_TRUE(refused(mfr::loadScene(badJson), badJson, {"GLB chunk 0 (JSON) declares"}));
  std::string version = glb(doc, bin);
  version[4] = 1;
  const std::string v1 = write("v1.glb", version);
  EXPECT_TRUE(refused(mfr::loadScene(v1), v1, {"GLB version 1"}));
}

TEST_F(HostileInputs, ABufferSwappedForASymbolicLinkWhileLoadingIsNeverReadFromOutside) {
  // inside: the triangle at z = 0; outside: the same triangle at z = 7, which must never appear
  std::vector<float> outsideTriangle = kTriangle;
  for (size_t i = 2; i < outsideTriangle.size(); i += 3) outsideTriangle[i] = 7.0f;
  std::ofstream(root() / "outside.bin", std::ios::binary) << floatBytes(outsideTriangle);
  write("data.bin", floatBytes(kTriangle));
  const std::string path = write("scene.gltf", triangleGltf("data.bin").dump());

  std::atomic<bool> stop{false};
  std::thread swapper([&] {
    const fs::path data = model() / "data.bin", next = model() / ".next.bin";
    for (uint64_t i = 0; !stop.load(); ++i) {
      std::error_code ec;
      fs::remove(next, ec);
      if (i % 2 == 0)
        fs::create_symlink("../outside.bin", next, ec);
      else
        std::ofstream(next, std::ios::binary) << floatBytes(kTriangle);
      fs::rename(next, data, ec);  // atomic: the name is always one of the two
    }
  });
  int loads = 0, refusals = 0, outside = 0;
  for (int run = 0; run < 400; ++run) {
    auto scene = mfr::loadScene(path);
    if (!scene) {
      EXPECT_TRUE(contains(scene.error().message, "outside") ||
                  contains(scene.error().message, "byteLength") ||
                  contains(scene.error().message, "no such file"))
          << scene.error().message;
      ++refusals;
      continue;
    }
    ++loads;
    for (const glm::vec3& p : scene->positions) outside += p.z != 0.0f;
  }
  stop = true;
  swapper.join();
  EXPECT_EQ(outside, 0) << "read the outside file's bytes";
  EXPECT_EQ(loads + refusals, 400);
  std::printf("symbolic-link swap: %d loads, %d refusals, %d outside reads\n", loads, refusals,
              outside);
}

TEST_F(HostileInputs, RequiredExtensionsMfrDoesNotImplementAreRefused) {
  for (const std::string extension :
       {"KHR_texture_basisu", "EXT_texture_webp", "KHR_draco_mesh_compression", "MFR_unknown"}) {
    json doc = triangleGltf(dataUri(floatBytes(kTriangle)));
    doc["extensionsUsed"] = {extension};
    doc["extensionsRequired"] = {extension};
    const std::string path = write(extension + ".gltf", doc.dump());
    EXPECT_TRUE(refused(mfr::loadScene(path), path,
                        {"requires extension '" + extension + "'", "does not implement"}));
  }
  // used but not required: the asset is still valid without it
  json used = triangleGltf(dataUri(floatBytes(kTriangle)));
  used["extensionsUsed"] = {"EXT_texture_webp"};
  EXPECT_TRUE(mfr::loadScene(write("used.gltf", used.dump())).ok());
  // required and implemented: loads
  json quantized = triangleGltf(dataUri(floatBytes(kTriangle)));
  quantized["extensionsRequired"] = {"KHR_mesh_quantization", "KHR_materials_transmission"};
  auto loaded = mfr::loadScene(write("implemented.gltf", quantized.dump()));
  EXPECT_TRUE(loaded.ok()) << loaded.error().message;
}

TEST_F(HostileInputs, GltfCameraFieldOfViewOutsideItsRangeIsRefused) {
  for (const double yfov : {0.0, -1.0, M_PI, 4.0}) {
    json doc = triangleGltf(dataUri(floatBytes(kTriangle)));
    doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 0.1}}}}};
    doc["nodes"].push_back({{"camera", 0}, {"translation", {0, 0, 5}}});
    doc["scenes"][0]["nodes"] = {0, 1};
    const std::string path = write("camera.gltf", doc.dump());
    EXPECT_TRUE(refused(mfr::loadScene(path), path, {"camera 0: perspective.yfov", "(0, pi)"}))
        << "yfov " << yfov;
  }
  json doc = triangleGltf(dataUri(floatBytes(kTriangle)));
  doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
  doc["nodes"].push_back({{"camera", 0}, {"translation", {0, 0, 5}}});
  doc["scenes"][0]["nodes"] = {0, 1};
  auto loaded = mfr::loadScene(write("good_camera.gltf", doc.dump()));
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  ASSERT_EQ(loaded->cameras.size(), 1u);
  EXPECT_NEAR(loaded->cameras[0].fovYDegrees, 0.8 * 180.0 / M_PI, 1e-4);
}

TEST_F(HostileInputs, GltfJsonErrorsAreOneLineWithoutTheLibrarysPrefix) {
  std::string text = triangleGltf(dataUri(floatBytes(kTriangle))).dump();
  const std::string nan =
      write("nan.gltf", text.replace(text.find("\"count\":3"), 9, "\"count\":NaN"));
  EXPECT_TRUE(refused(mfr::loadScene(nan), nan, {"JSON error", "line 1"}));
  EXPECT_FALSE(contains(mfr::loadScene(nan).error().message, "[json.exception"));
  std::string inf = triangleGltf(dataUri(floatBytes(kTriangle))).dump();
  inf.replace(inf.find("\"count\":3"), 9, "\"count\":Infinity");
  const std::string infPath = write("inf.gltf", inf);
  EXPECT_TRUE(refused(mfr::loadScene(infPath), infPath, {"JSON error"}));
}

TEST_F(HostileInputs, GltfFieldsWithMisleadingMessagesNameTheirRealProblem) {
  // a stride that is a multiple of 4 but far beyond the spec's 252
  json stride = triangleGltf(dataUri(floatBytes(kTriangle)));
  stride["bufferViews"][0]["byteStride"] = 2147483644;
  const std::string stridePath = write("stride.gltf", stride.dump());
  EXPECT_TRUE(refused(mfr::loadScene(stridePath), stridePath,
                      {"bufferViews[0].byteStride 2147483644", "multiple of 4 in [4, 252]"}));
  // a data URI declared as a petabyte
  json huge = triangleGltf(dataUri(floatBytes(kTriangle)), 1000000000000000ull);
  const std::string hugePath = write("huge.gltf", huge.dump());
  EXPECT_TRUE(refused(mfr::loadScene(hugePath), hugePath,
                      {"buffer 0: byteLength 1000000000000000 differs from the size of its data "
                       "URI, 36 bytes"}));
  // a texture whose PNG header claims 60000 x 60000 pixels
  std::string png("\x89PNG\r\n\x1a\n", 8);
  const auto be32 = [&png](uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) png += static_cast<char>((v >> s) & 0xff);
  };
  be32(13);
  png += "IHDR";
  be32(60000);
  be32(60000);
  png += std::string("\x08\x06\x00\x00\x00", 5);
  be32(0);
  be32(0);
  png += "IEND";
  be32(0);
  json textured = triangleGltf(dataUri(floatBytes(kTriangle)));
  textured["meshes"][0]["primitives"][0]["material"] = 0;
  textured["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  textured["textures"] = {{{"source", 0}}};
  textured["images"] = {{{"uri", "data:image/png;base64," + mfr::test::base64Encode(png)}}};
  const std::string texturePath = write("texture.gltf", textured.dump());
  EXPECT_TRUE(refused(mfr::loadScene(texturePath), texturePath, {"60000 x 60000 pixels"}));
  // vertices at 1e38: finite, but the framing camera's arithmetic overflows on them
  const std::vector<float> far = {0, 0, 0, 1e38f, 0, 0, 0, 1e38f, 0};
  const std::string farPath = write("far.gltf", triangleGltf(dataUri(floatBytes(far))).dump());
  EXPECT_TRUE(refused(mfr::loadScene(farPath), farPath, {"coordinate 1e+38", "+-1e18"}));
  EXPECT_FALSE(contains(mfr::loadScene(farPath).error().message, "camera"));
  // the largest coordinates allowed still load and frame a camera
  const std::vector<float> large = {0, 0, 0, 1e17f, 0, 0, 0, 1e17f, 0};
  EXPECT_TRUE(mfr::loadScene(write("large.gltf", triangleGltf(dataUri(floatBytes(large))).dump())));
}

TEST_F(HostileInputs, EchoedInputsInErrorsAreCutToABoundedLength) {
  // a JSON scene whose mesh name is 5 MB long, a 3 MB data URI with a wrong byteLength
  const std::string name(5 << 20, 'm');
  const std::string scene = write("long.json", json{{"mesh", name + ".gltf"}}.dump());
  EXPECT_TRUE(refused(mfr::loadScene(scene), scene, {"'mesh'"}));
  const std::string payload(3 << 20, 'x');
  const std::string uri = write("uri.gltf", triangleGltf(dataUri(payload), 5).dump());
  EXPECT_TRUE(refused(mfr::loadScene(uri), uri, {"byteLength 5 differs"}));
  // an OBJ texture name and a PLY element name of 1 MB
  const std::string obj = write("long.obj", "mtllib " + std::string(1 << 20, 'x') +
                                                ".mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  auto loaded = mfr::loadScene(obj);  // a missing MTL file falls back to the default material
  if (!loaded) {
    EXPECT_LT(loaded.error().message.size(), 1500u);
  }
  const std::string ply = write("long.ply",
                                "ply\nformat ascii 1.0\nelement vertex 3\n"
                                "property float x\nproperty float y\n"
                                "property float " +
                                    std::string(1 << 20, 'z') + "\nend_header\n");
  EXPECT_TRUE(refused(mfr::loadScene(ply), ply, {}));
  // a procedural value of 5,000 characters, a missing file of a 5,000-character name: cut, and
  // the problem after the echo survives
  const std::string count(5000, '9');
  EXPECT_TRUE(refused(mfr::loadScene("procedural:spheres?count=" + count), "procedural:spheres",
                      {"'count'", "invalid value '9999"}));
  const std::string missing = (model() / (std::string(5000, 'n') + ".obj")).string();
  auto result = mfr::loadScene(missing);
  ASSERT_FALSE(result.ok());
  EXPECT_LT(result.error().message.size(), 1500u);
  EXPECT_NE(result.error().message.find("cannot be read"), std::string::npos)
      << result.error().message;
}

// ---------------------------------------------------------------------------------------------
// OBJ

/// An OBJ of one face: a regular `corners`-gon of radius 1 in the plane z = 0.
std::string discObj(size_t corners) {
  std::string text;
  text.reserve(corners * 40);
  char line[96];
  for (size_t i = 0; i < corners; ++i) {
    const double angle = 2.0 * M_PI * static_cast<double>(i) / static_cast<double>(corners);
    std::snprintf(line, sizeof line, "v %.9f %.9f 0\n", std::cos(angle), std::sin(angle));
    text += line;
  }
  text += "f";
  for (size_t i = 1; i <= corners; ++i) {
    text += ' ';  // appended piece by piece (GCC 12 warns on " " + string, PR 105329)
    text += std::to_string(i);
  }
  return text + "\n";
}

/// The summed area of the scene's triangles: a triangulation that folds over itself covers some
/// of the polygon more than once, and sums to more than its area.
double summedArea(const mfr::Scene& scene) {
  double area = 0.0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const glm::dvec3 a(scene.positions[scene.indices[3 * t]]);
    const glm::dvec3 b(scene.positions[scene.indices[3 * t + 1]]);
    const glm::dvec3 c(scene.positions[scene.indices[3 * t + 2]]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

TEST_F(HostileInputs, ObjFacesOfAMillionCornersTriangulateInLinearTimeWithoutOverlap) {
  for (const size_t corners : {size_t{5}, size_t{10000}, size_t{100000}, size_t{1000000}}) {
    const std::string path = write("disc.obj", discObj(corners));
    const auto start = std::chrono::steady_clock::now();
    auto scene = mfr::loadScene(path);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->triangleCount(), corners - 2);
    // a regular n-gon's area; a fold (the old triangulation: depth complexity 3-5) doubles it
    const double n = static_cast<double>(corners);
    EXPECT_NEAR(summedArea(*scene), 0.5 * n * std::sin(2.0 * M_PI / n), 1e-4) << corners;
    std::printf("%zu-corner face: %.2f s\n", corners, seconds);
  }
}

TEST_F(HostileInputs, NonConvexObjFacesAreEarClippedOrRefusedBeyondTheStatedLimit) {
  // a comb: 3 teeth of width 1 and height 2 on a base 1 high, 5 wide; area 5 + 3 * 2 = 11
  const std::string comb = write("comb.obj",
                                 "v 0 0 0\nv 5 0 0\nv 5 3 0\nv 4 3 0\nv 4 1 0\nv 3 1 0\n"
                                 "v 3 3 0\nv 2 3 0\nv 2 1 0\nv 1 1 0\nv 1 3 0\nv 0 3 0\n"
                                 "f 1 2 3 4 5 6 7 8 9 10 11 12\n");
  auto scene = mfr::loadScene(comb);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->triangleCount(), 10u);
  EXPECT_NEAR(summedArea(*scene), 11.0, 1e-9);
  // a star of 2,048 corners (twice the limit) is not convex and beyond the ear-clipping limit
  std::string star;
  const size_t corners = 2 * mfr::kMaxNonConvexCorners;
  for (size_t i = 0; i < corners; ++i) {
    const double angle = 2.0 * M_PI * static_cast<double>(i) / static_cast<double>(corners);
    const double radius = i % 2 == 0 ? 1.0 : 0.5;
    star += "v " + std::to_string(radius * std::cos(angle)) + " " +
            std::to_string(radius * std::sin(angle)) + " 0\n";
  }
  star += "f";
  for (size_t i = 1; i <= corners; ++i) {
    star += ' ';
    star += std::to_string(i);
  }
  const std::string starPath = write("star.obj", star + "\n");
  EXPECT_TRUE(refused(mfr::loadScene(starPath), starPath,
                      {"a non-convex face of " + std::to_string(corners) + " vertices",
                       "up to " + std::to_string(mfr::kMaxNonConvexCorners)}));
  // a pentagram (every turn the same way, winding twice) is not taken for convex: it crosses
  // itself, and says so
  std::string pentagram;
  for (int i = 0; i < 5; ++i) {
    const double angle = 2.0 * M_PI * (2 * i % 5) / 5.0;
    pentagram +=
        "v " + std::to_string(std::cos(angle)) + " " + std::to_string(std::sin(angle)) + " 0\n";
  }
  const std::string pentagramPath = write("pentagram.obj", pentagram + "f 1 2 3 4 5\n");
  EXPECT_TRUE(refused(mfr::loadScene(pentagramPath), pentagramPath, {"crosses itself"}));
}

TEST_F(HostileInputs, ObjFaceIndicesBeyond32BitsAreRefusedNotWrapped) {
  const std::string body = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (const std::string index :
       {"4294967299", "2147483648", "-2147483649", "99999999999999999999999"}) {
    const std::string path = write("index.obj", body + "f 1 2 " + index + "\n");
    EXPECT_TRUE(
        refused(mfr::loadScene(path), path, {"line 4: face index '" + index + "' is out of range"}))
        << index;
  }
  // in v/vt/vn form too, and the largest 32-bit index is an ordinary out-of-range vertex
  const std::string slash = write("slash.obj", body + "f 1/1 2/1 3/4294967296\n");
  EXPECT_TRUE(refused(mfr::loadScene(slash), slash, {"face index '4294967296'"}));
  const std::string largest = write("largest.obj", body + "f 1 2 2147483647\n");
  EXPECT_TRUE(refused(mfr::loadScene(largest), largest, {"out of bounds"}));
  // a comment is not a face
  EXPECT_TRUE(mfr::loadScene(write("comment.obj", body + "f 1 2 3\n# f 1 2 99999999999\n")).ok());
}

// ---------------------------------------------------------------------------------------------
// PLY

TEST_F(HostileInputs, PlyHeaderOf200000ElementLinesIsRefusedAtOnce) {
  std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\n";
  for (int i = 0; i < 200000; ++i) header += "element e" + std::to_string(i) + " 0\n";
  const std::string path =
      write("elements.ply", header + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  // assimp's reader is quadratic in the header's lines (11 s for these): refused by the check,
  // whose duplicate-name test is a hash set now (it was quadratic too: 15 s for 50,000)
  EXPECT_TRUE(refused(mfr::loadScene(path), path, {"PLY header has more than 10000 lines"}));
  // 5,000 distinct elements are still read
  std::string many =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\n";
  for (int i = 0; i < 5000; ++i) many += "element e" + std::to_string(i) + " 0\n";
  auto scene =
      mfr::loadScene(write("many.ply", many + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->triangleCount(), 1u);
  // a repeated name is still caught (assimp would merge the two elements' data)
  const std::string twice =
      write("twice.ply", "ply\nformat ascii 1.0\nelement vertex 0\nelement vertex 0\nend_header\n");
  EXPECT_TRUE(refused(mfr::loadScene(twice), twice, {"'vertex' is declared twice"}));
}

TEST_F(HostileInputs, PlyThatAbortedAssimpsTriangulationLoads) {
  // fuzz_ply's finding (fuzz/crashes/ply/crash-844b72d...): an element named "ver/ex" before the
  // vertex element made assimp's Triangulate step abort the process (ai_assert); mfr splits the
  // faces itself now
  const std::string path =
      write("aborts.ply",
            "ply\nformat ascii 1.0\nelement ver/ex 1\nproperty float x\nproperty float y\n"
            "property float z\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 3 2 1\n");
  auto scene = mfr::loadScene(path);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_GE(scene->triangleCount(), 1u);
  // a quad and a convex pentagon are split into 2 and 3 triangles covering their area once
  const std::string polygons =
      write("polygons.ply",
            "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
            "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n2 0 0\n2 1 0\n1 2 0\n0 1 0\n4 0 1 2 4\n5 0 1 2 3 4\n");
  // fuzz_ply's second finding (crash-a214f36...): assimp read a 41-digit element name as a count
  // and asked for 45 GB; element and property names start with a letter or '_' (std::bad_alloc
  // reached the user as "std::bad_alloc")
  const std::string digits =
      write("digits.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement " +
                std::string(37, '7') +
                "face 2\nproperty list uchar int vertex_indices\nend_header\n"
                "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n");
  EXPECT_TRUE(refused(mfr::loadScene(digits), digits,
                      {"PLY element name '7777", "must start with a letter or '_'"}));
  // fuzz_ply's third finding (leak-1e37540...): assimp leaked the faces of a triangle strip with
  // indices out of range; strip indices are checked like face indices (-1 restarts a strip)
  const std::string strip =
      write("strip.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement tristrips 1\nproperty list int int vertex_indices\n"
            "end_header\n0 0 0\n1 2 0\n1 1 0\n6 0 1 2 -9 900 901\n");
  EXPECT_TRUE(refused(mfr::loadScene(strip), strip, {"PLY triangle strip index -9 out of range"}));
  std::ifstream in(strip);
  std::string renamed{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  renamed.replace(renamed.find("vertex_indices"), 14, "vertex_edniics");  // any name (leak-c295b12)
  const std::string other = write("strip_name.ply", renamed);
  EXPECT_TRUE(refused(mfr::loadScene(other), other, {"PLY triangle strip index -9 out of range"}));
  auto split = mfr::loadScene(polygons);
  ASSERT_TRUE(split.ok()) << split.error().message;
  EXPECT_EQ(split->triangleCount(), 5u);
  EXPECT_NEAR(summedArea(*split), 2.0 + 3.0, 1e-6);
}

}  // namespace
