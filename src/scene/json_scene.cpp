// JSON scene files: a mesh (any loadable file or procedural spec) plus viewing overrides.
//
//   {"mesh": "path/relative/to/this/file.gltf" | "procedural:NAME?...",   (required)
//    "cameras": [{"eye": [x,y,z], "target": [x,y,z], "up": [0,1,0], "fov": 45,
//                 "near": 0, "far": 0}],          (optional; replaces the file's cameras)
//    "background": [r, g, b],                     (optional; linear RGB in [0, 1])
//    "alpha": 0.5,                                (optional; global alpha override in [0, 1])
//    "transmission_alpha_floor": 0.1}             (optional; in [0, 1])
//
// Unknown keys, wrong types and out-of-range values are errors naming the key and the file.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "file_loaders.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/scene/load.hpp"

namespace mfr {
namespace {

using nlohmann::json;

/// Error helper: every message is "<file>: '<key>' <problem>".
struct Checker {
  const std::string& path;
  Error fail(const std::string& key, const std::string& problem) const {
    return makeError(path + ": '" + oneLine(key, 80) + "' " + problem);  // keys may hold any text
  }

  Result<float> number(const json& value, const std::string& key, float min, float max) const {
    if (!value.is_number()) return fail(key, "must be a number");
    const double v = value.get<double>();
    if (!(v >= min && v <= max))
      return fail(key, "must be in [" + trim(min) + ", " + trim(max) + "], got " + trim(v));
    return static_cast<float>(v);
  }

  Result<glm::vec3> vec3(const json& value, const std::string& key, float min, float max) const {
    if (!value.is_array() || value.size() != 3) return fail(key, "must be an array of 3 numbers");
    glm::vec3 v(0.0f);
    for (int i = 0; i < 3; ++i) {
      auto c = number(value[static_cast<size_t>(i)], key, min, max);
      if (!c) return c.error();
      v[i] = *c;
    }
    return v;
  }

  static std::string trim(double v) {
    std::string s = std::to_string(v);
    if (s.find('.') != std::string::npos) {
      s.erase(s.find_last_not_of('0') + 1);
      if (s.back() == '.') s.pop_back();
    }
    return s;
  }
};

constexpr float kHuge = 3.0e38f;

Result<Camera> parseCamera(const Checker& check, const json& value, const std::string& key) {
  if (!value.is_object()) return check.fail(key, "must be an object");
  Camera camera;
  camera.zNear = 0.0f;
  camera.zFar = 0.0f;
  for (const auto& [name, item] : value.items()) {
    const std::string field = key + "." + name;
    if (name == "eye" || name == "target" || name == "up") {
      auto v = check.vec3(item, field, -kHuge, kHuge);
      if (!v) return v.error();
      (name == "eye" ? camera.eye : name == "target" ? camera.target : camera.up) = *v;
    } else if (name == "fov") {
      auto v = check.number(item, field, 0.0f, 180.0f);
      if (!v) return v.error();
      if (*v <= 0.0f || *v >= 180.0f) return check.fail(field, "must be in (0, 180) degrees");
      if (!validFovYDegrees(*v)) {
        char value[32];
        std::snprintf(value, sizeof value, "%g", item.get<double>());
        return check.fail(field, "is " + std::string(value) + " degrees, narrower than " +
                                     kMinFovText + " (" + kNarrowFovReason + ")");
      }
      camera.fovYDegrees = *v;
    } else if (name == "near" || name == "far") {
      // a far plane beyond maxFarPlane(near) is clamped to it (fitClipPlanes); a near one beyond
      // kMaxNearPlane cannot be projected in single precision
      auto v = check.number(item, field, 0.0f, kHuge);
      if (!v) return v.error();
      if (name == "near" && *v > kMaxNearPlane) {
        char value[32];
        std::snprintf(value, sizeof value, "%g", item.get<double>());
        return check.fail(field, "is " + std::string(value) +
                                     ", beyond 1e18 (the projection's 2 far near would overflow "
                                     "single precision)");
      }
      (name == "near" ? camera.zNear : camera.zFar) = *v;
    } else {
      return check.fail(field, "is not a camera key (eye, target, up, fov, near, far)");
    }
  }
  if (!value.contains("eye")) return check.fail(key + ".eye", "is required");
  if (!value.contains("target")) return check.fail(key + ".target", "is required");
  const glm::vec3 forward = camera.target - camera.eye;
  if (!(glm::length(forward) > 0.0f)) return check.fail(key, "has eye == target");
  if (!(glm::length(glm::cross(forward, camera.up)) > 0.0f))
    return check.fail(key + ".up", "must not be zero or parallel to the view direction");
  if (camera.zNear > 0.0f && camera.zFar > 0.0f && camera.zFar <= camera.zNear)
    return check.fail(key + ".far", "must be greater than near");
  return camera;
}

}  // namespace

Result<Scene> loadJsonScene(const std::string& path, const OpenFile& file,
                            const LoadOptions& options) {
  auto text = file.readText();
  if (!text) return text.error();
  // before anything recursive reads it (copies, comparisons and dumps recurse per level)
  if (const std::string deep = jsonDepthProblem(*text); !deep.empty())
    return makeError(path + ": " + deep);
  json root;
  try {
    root = json::parse(*text);
  } catch (const json::exception& e) {
    return makeError(path + ": " + jsonErrorText(e.what()));
  }
  const Checker check{path};
  if (!root.is_object()) return makeError(path + ": JSON error: top level must be an object");

  std::string mesh;
  std::optional<std::vector<Camera>> cameras;
  std::optional<glm::vec3> background;
  std::optional<float> alpha;
  LoadOptions meshOptions = options;
  for (const auto& [key, value] : root.items()) {
    if (key == "mesh") {
      if (!value.is_string() || value.get<std::string>().empty())
        return check.fail(key, "must be a non-empty string");
      mesh = value.get<std::string>();
    } else if (key == "cameras") {
      if (!value.is_array()) return check.fail(key, "must be an array of camera objects");
      cameras.emplace();
      for (size_t i = 0; i < value.size(); ++i) {
        auto camera = parseCamera(check, value[i], "cameras[" + std::to_string(i) + "]");
        if (!camera) return camera.error();
        cameras->push_back(*camera);
      }
    } else if (key == "background") {
      auto v = check.vec3(value, key, 0.0f, 1.0f);
      if (!v) return v.error();
      background = *v;
    } else if (key == "alpha") {
      auto v = check.number(value, key, 0.0f, 1.0f);
      if (!v) return v.error();
      alpha = *v;
    } else if (key == "transmission_alpha_floor") {
      auto v = check.number(value, key, 0.0f, 1.0f);
      if (!v) return v.error();
      meshOptions.transmissionAlphaFloor = *v;
    } else {
      return check.fail(key,
                        "is not a scene key (mesh, cameras, background, alpha, "
                        "transmission_alpha_floor)");
    }
  }
  if (mesh.empty()) return check.fail("mesh", "is required");

  // Files resolve against this file's directory and must lie inside it (unless allowed outside,
  // file_access.hpp); JSON scene files do not nest.
  Result<Scene> loaded = makeError("");
  if (mesh.rfind("procedural:", 0) == 0) {
    loaded = loadScene(mesh, meshOptions);
  } else {
    const std::filesystem::path meshPath(mesh);
    if (lowercaseExtension(meshPath) == ".json")
      return check.fail("mesh", "must not be another JSON scene file");
    // opened once, relative to this file's folder; the mesh loader reads that descriptor
    auto meshFile =
        openReference(path, mesh, "'mesh' " + oneLine(mesh, 200), options.allowOutsideReferences);
    if (!meshFile) return makeError(path + ": " + meshFile.error().message);
    const std::string source =
        meshPath.is_absolute()
            ? mesh
            : (std::filesystem::path(path).parent_path() / meshPath).lexically_normal().string();
    loaded = loadOpenFile(source, *meshFile, meshOptions);
    if (loaded) loaded->name = source;
  }
  if (!loaded) return makeError(path + ": mesh: " + oneLine(loaded.error().message, 1000));

  Scene scene = std::move(*loaded);
  scene.name = path;
  if (cameras) {
    scene.cameras = std::move(*cameras);
    scene.cameraProblems.clear();  // the mesh file's cameras are replaced, their problems too
  }
  if (background) scene.background = *background;
  if (alpha) scene.alphaOverride = *alpha;
  MFR_TRY(validateScene(scene));
  return scene;
}

}  // namespace mfr
