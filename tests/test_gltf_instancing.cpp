// EXT_mesh_gpu_instancing (issue 24): a node's mesh drawn once per instance, instance i placed by
// the node's transform times T(i) R(i) S(i). Expectations are computed here from the attribute
// values, and on the Khronos conformance model SimpleInstancing (125 instances of a 12-triangle
// cube: 1,500 triangles).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "gltf_quads.hpp"
#include "mfr/scene/load.hpp"
#include "quad_checks.hpp"
#include "shared_scenes.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string bytesOf(const std::vector<float>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
}

/// One triangle (0,0,0) (1,0,0) (0,1,0) in a node with the instancing extension; each attribute
/// present only when its values are given.
std::string instancedGltf(const std::vector<float>& translation, const std::vector<float>& rotation,
                          const std::vector<float>& scale, const json& nodeExtra = json::object()) {
  std::string bin = bytesOf({0, 0, 0, 1, 0, 0, 0, 1, 0});
  json views = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}}};
  json accessors = {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}};
  json attributes = json::object();
  const auto add = [&](const char* name, const std::vector<float>& values, const char* type,
                       size_t width) {
    if (values.empty()) return;
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", values.size() * 4}});
    bin += bytesOf(values);
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", 5126},
                         {"count", values.size() / width},
                         {"type", type}});
    attributes[name] = accessors.size() - 1;
  };
  add("TRANSLATION", translation, "VEC3", 3);
  add("ROTATION", rotation, "VEC4", 4);
  add("SCALE", scale, "VEC3", 3);
  json node = {{"mesh", 0},
               {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", attributes}}}}}};
  node.update(nodeExtra);
  return json{{"asset", {{"version", "2.0"}}},
              {"extensionsUsed", {"EXT_mesh_gpu_instancing"}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {node}},
              {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
              {"accessors", accessors},
              {"bufferViews", views},
              {"buffers", mfr::test::gltfEmbeddedBuffer(bin)}}
      .dump();
}

mfr::Result<mfr::Scene> load(const std::string& text) {
  return mfr::test::loadGltfText(text, "mfr_instancing");
}

/// The scene's triangle t as three positions.
std::vector<glm::vec3> triangle(const mfr::Scene& scene, size_t t) {
  return {scene.positions[scene.indices[3 * t]], scene.positions[scene.indices[3 * t + 1]],
          scene.positions[scene.indices[3 * t + 2]]};
}

void expectNear(const glm::vec3& a, const glm::vec3& b) {
  EXPECT_NEAR(a.x, b.x, 1e-5f);
  EXPECT_NEAR(a.y, b.y, 1e-5f);
  EXPECT_NEAR(a.z, b.z, 1e-5f);
}

TEST(GltfInstancing, EachAttributePlacesItsInstance) {
  // translation only: two copies, 5 apart in x
  auto moved = load(instancedGltf({0, 0, 0, 5, 0, 0}, {}, {}));
  ASSERT_TRUE(moved.ok()) << moved.error().message;
  ASSERT_EQ(moved->triangleCount(), 2u);
  expectNear(triangle(*moved, 1)[1], {6, 0, 0});
  // rotation only: 90 degrees about z maps (1,0,0) to (0,1,0); the quaternion is stored x, y, z, w
  const float h = std::sqrt(0.5f);
  auto turned = load(instancedGltf({}, {0, 0, h, h}, {}));
  ASSERT_TRUE(turned.ok()) << turned.error().message;
  ASSERT_EQ(turned->triangleCount(), 1u);
  expectNear(triangle(*turned, 0)[1], {0, 1, 0});
  expectNear(triangle(*turned, 0)[2], {-1, 0, 0});
  // all three, T R S in that order: scale 2, turn, then move
  auto all = load(instancedGltf({1, 2, 3}, {0, 0, h, h}, {2, 2, 2}));
  ASSERT_TRUE(all.ok()) << all.error().message;
  expectNear(triangle(*all, 0)[1], {1, 4, 3});
  // the node's own transform applies after the instance's
  auto nested =
      load(instancedGltf({5, 0, 0}, {}, {}, {{"scale", {1, 1, 10}}, {"translation", {0, 7, 0}}}));
  ASSERT_TRUE(nested.ok()) << nested.error().message;
  expectNear(triangle(*nested, 0)[0], {5, 7, 0});
  // a negative scale mirrors: the winding is kept facing the same way (indices swapped)
  auto mirrored = load(instancedGltf({}, {}, {-1, 1, 1}));
  ASSERT_TRUE(mirrored.ok()) << mirrored.error().message;
  const auto m = triangle(*mirrored, 0);
  EXPECT_GT(glm::cross(m[1] - m[0], m[2] - m[0]).z, 0.0f);
}

TEST(GltfInstancing, AttributesOfDifferentCountsAreRefused) {
  auto result = load(instancedGltf({0, 0, 0, 1, 0, 0}, {0, 0, 0, 1}, {}));
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().message.find("EXT_mesh_gpu_instancing: ROTATION has 1 instances"),
            std::string::npos)
      << result.error().message;
}

TEST(GltfInstancing, SimpleInstancingHas125Cubes) {
  MFR_SHARED_SCENE(path, "khronos-conformance/SimpleInstancing/glTF/SimpleInstancing.gltf");
  auto scene = mfr::loadScene(path.string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->triangleCount(), 1500u);  // 12 before the extension was read
  // the instances are spread out: the bounds are much larger than one unit cube
  const mfr::Bounds bounds = mfr::sceneBounds(*scene);
  EXPECT_GT(bounds.max.x - bounds.min.x, 4.0f);
}

}  // namespace
