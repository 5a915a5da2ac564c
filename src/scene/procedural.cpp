// Built-in procedural scenes: parsing of "NAME[?key=value&...]", dispatch to the scene builders
// (one file each: procedural_layers/hairball/smoke/bottles/spheres.cpp) and the helpers they share
// (parameter reader, colours, framing, tube / lathe / sphere mesh builders).
#include "mfr/scene/procedural.hpp"
#include "mfr/core/memory_limit.hpp"
#include "mfr/core/quote.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr {
namespace procedural {
namespace {

/// The value quoted for a one-line message (control characters replaced, cut at 80 characters).
std::string quoted(std::string_view text) {
  return quoteInput(text, 80);
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

struct SceneDef {
  const char* name;
  std::vector<std::string> keys;  // without "seed", which every scene accepts
  Result<Scene> (*build)(ParamReader&, uint64_t);
};

const std::vector<SceneDef>& sceneDefs() {
  static const std::vector<SceneDef> defs = {
      {"layers", {"k", "r", "pd", "alpha"}, &buildLayers},
      {"hairball", {"strands", "segments", "sides", "radius", "alpha"}, &buildHairball},
      {"smoke", {"count", "size", "alpha"}, &buildSmoke},
      {"bottles", {"count", "segments", "alpha", "spacing"}, &buildBottles},
      {"spheres", {"count", "scale", "detail", "alpha"}, &buildSpheres},
      {"glassware", {"count", "segments", "shells", "alpha", "spread"}, &buildGlassware},
      {"foliage", {"plants", "leaves", "alpha", "spread"}, &buildFoliage},
      {"particles", {"clouds", "count", "size", "alpha", "spread"}, &buildParticles},
      {"hair", {"strands", "segments", "sides", "alpha", "spread"}, &buildHair},
      {"panels", {"boxes", "panels", "alpha", "spread"}, &buildPanels},
      {"city", {"rows", "columns", "alpha", "spread"}, &buildCity},
  };
  return defs;
}

}  // namespace

// --- ParamReader ------------------------------------------------------------------------------

const std::string* ParamReader::find(std::string_view key) const {
  const auto it = params_.find(std::string(key));
  return it == params_.end() ? nullptr : &it->second;
}

void ParamReader::record(const std::string& message) {
  if (!error_) error_ = fail(message);
}

int64_t ParamReader::integer(std::string_view key, int64_t fallback, int64_t lo, int64_t hi) {
  const std::string* text = find(key);
  if (!text) return fallback;
  int64_t value = 0;
  const char* end = text->data() + text->size();
  const auto [ptr, ec] = std::from_chars(text->data(), end, value);
  if (ec != std::errc() || ptr != end || text->empty()) {
    record("parameter '" + std::string(key) + "' has invalid value " + quoted(*text) +
           " (expected an integer)");
    return fallback;
  }
  if (value < lo || value > hi) {
    record("parameter '" + std::string(key) + "' value " + quoted(*text) + " is out of range [" +
           std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return fallback;
  }
  return value;
}

float ParamReader::real(std::string_view key, double fallback, double lo, double hi, bool lowOpen) {
  const std::string* text = find(key);
  if (!text) return static_cast<float>(fallback);
  double value = 0.0;
  const char* end = text->data() + text->size();
  const auto [ptr, ec] = std::from_chars(text->data(), end, value);
  if (ec != std::errc() || ptr != end || text->empty()) {
    record("parameter '" + std::string(key) + "' has invalid value " + quoted(*text) +
           " (expected a number)");
    return static_cast<float>(fallback);
  }
  const bool aboveLow = lowOpen ? value > lo : value >= lo;  // false for NaN
  if (!aboveLow || !(value <= hi)) {
    record("parameter '" + std::string(key) + "' value " + quoted(*text) + " is out of range " +
           (lowOpen ? "(" : "[") + formatNumber(lo) + ", " + formatNumber(hi) + "]");
    return static_cast<float>(fallback);
  }
  return static_cast<float>(value);
}

Result<void> checkTriangleBudget(const ParamReader& params, double triangles) {
  if (!(triangles <= params.maxTriangles()))
    return params.fail("parameters produce " + formatNumber(std::round(triangles)) +
                       " triangles (limit " + formatNumber(params.maxTriangles()) + ")");
  const auto count = static_cast<uint64_t>(std::ceil(triangles));  // within the cap above
  if (auto fits = checkMemory(sceneMemoryBytes(2 * count, count), params.memoryLimit(),
                              "its " + std::to_string(count) + " triangles and up to " +
                                  std::to_string(2 * count) + " vertices");
      !fits)
    return params.fail(fits.error().message);
  return {};
}

std::string formatNumber(double value) {
  char buffer[64];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return ec == std::errc() ? std::string(buffer, ptr) : std::string("?");
}

// --- Colours and cameras ----------------------------------------------------------------------

glm::vec3 hsv(float hue, float saturation, float value) {
  hue -= std::floor(hue);
  const float h = hue * 6.0f;
  const int sector = std::min(static_cast<int>(h), 5);
  const float f = h - static_cast<float>(sector);
  const float p = value * (1.0f - saturation);
  const float q = value * (1.0f - saturation * f);
  const float t = value * (1.0f - saturation * (1.0f - f));
  switch (sector) {
    case 0:
      return {value, t, p};
    case 1:
      return {q, value, p};
    case 2:
      return {p, value, t};
    case 3:
      return {p, q, value};
    case 4:
      return {t, p, value};
    default:
      return {value, p, q};
  }
}

float goldenHue(uint32_t i, float offset) {
  const double h = static_cast<double>(offset) + 0.6180339887498949 * static_cast<double>(i);
  return static_cast<float>(h - std::floor(h));
}

Camera cameraForSphere(const glm::vec3& center, float radius, float fovYDegrees) {
  Camera camera;
  const float distance = radius / std::sin(glm::radians(fovYDegrees) * 0.5f) * 1.05f;
  camera.target = center;
  camera.eye = center + glm::normalize(glm::vec3(0.0f, 0.35f, 1.0f)) * distance;
  camera.up = {0.0f, 1.0f, 0.0f};
  camera.fovYDegrees = fovYDegrees;
  return camera;
}

Camera frameVertices(const Scene& scene, float fovYDegrees) {
  const glm::vec3 center = sceneBounds(scene).center();
  Camera camera = cameraForSphere(center, 1.0f, fovYDegrees);
  const glm::vec3 back = glm::normalize(camera.eye - center);  // from the target to the eye
  const glm::vec3 right = glm::normalize(glm::cross(-back, camera.up));
  const glm::vec3 up = glm::cross(right, -back);
  const float tanHalf = std::tan(glm::radians(fovYDegrees) * 0.5f) * 0.95f;
  // A vertex at offset q from the centre is in view from distance D when
  // max(|q.right|, |q.up|) <= tanHalf * (D - q.back).
  float distance = 0.0f, nearest = 0.0f, farthest = 0.0f;  // extremes of q.back
  for (const glm::vec3& p : scene.positions) {
    const glm::vec3 q = p - center;
    const float lateral = std::max(std::abs(glm::dot(q, right)), std::abs(glm::dot(q, up)));
    distance = std::max(distance, glm::dot(q, back) + lateral / tanHalf);
    nearest = std::max(nearest, glm::dot(q, back));
    farthest = std::min(farthest, glm::dot(q, back));
  }
  distance = std::max(distance, 1e-3f);
  camera.eye = center + back * distance;
  // Clip planes 5% beyond the nearest and farthest vertex depths.
  camera.zNear = std::max((distance - nearest) * 0.95f, distance * 1e-3f);
  camera.zFar = (distance - farthest) * 1.05f;
  return camera;
}

// --- Mesh building ----------------------------------------------------------------------------

void MeshBuilder::reserve(size_t vertices, size_t triangles) {
  scene_.positions.reserve(scene_.positions.size() + vertices);
  scene_.normals.reserve(scene_.normals.size() + vertices);
  scene_.indices.reserve(scene_.indices.size() + 3 * triangles);
  scene_.triangleMaterial.reserve(scene_.triangleMaterial.size() + triangles);
}

uint32_t MeshBuilder::material(std::string name, const glm::vec3& color, float alpha) {
  Material m;
  m.name = std::move(name);
  m.baseColor = glm::vec4(color, alpha);
  m.alphaMode = AlphaMode::Blend;
  scene_.materials.push_back(std::move(m));
  return static_cast<uint32_t>(scene_.materials.size() - 1);
}

uint32_t MeshBuilder::vertex(const glm::vec3& position, const glm::vec3& normal) {
  scene_.positions.push_back(position);
  scene_.normals.push_back(normal);
  return static_cast<uint32_t>(scene_.positions.size() - 1);
}

void MeshBuilder::triangle(uint32_t a, uint32_t b, uint32_t c, uint32_t material) {
  const std::vector<glm::vec3>& p = scene_.positions;
  const std::vector<glm::vec3>& n = scene_.normals;
  const glm::vec3 face = glm::cross(p[b] - p[a], p[c] - p[a]);
  if (glm::dot(face, n[a] + n[b] + n[c]) < 0.0f) std::swap(b, c);
  scene_.indices.insert(scene_.indices.end(), {a, b, c});
  scene_.triangleMaterial.push_back(material);
}

void MeshBuilder::quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d, uint32_t material) {
  triangle(a, b, c, material);
  triangle(a, c, d, material);
}

void appendTube(MeshBuilder& mesh, std::span<const glm::vec3> centerline,
                std::span<const glm::vec3> tangents, float radius, int sides, uint32_t material) {
  MFR_CHECK(centerline.size() >= 2 && tangents.size() == centerline.size() && sides >= 3);
  // Initial normal: the axis least aligned with the first tangent, made perpendicular.
  const glm::vec3 t0 = tangents[0];
  const glm::vec3 axis = std::abs(t0.x) < 0.6f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  glm::vec3 normal = glm::normalize(axis - glm::dot(axis, t0) * t0);
  const uint32_t first = static_cast<uint32_t>(mesh.scene().positions.size());
  const float step = glm::two_pi<float>() / static_cast<float>(sides);
  for (size_t j = 0; j < centerline.size(); ++j) {
    const glm::vec3 t = tangents[j];
    // Parallel transport by projection (exact enough for the small turn between samples).
    const glm::vec3 projected = normal - glm::dot(normal, t) * t;
    if (glm::dot(projected, projected) > 1e-12f) normal = glm::normalize(projected);
    const glm::vec3 binormal = glm::cross(t, normal);
    for (int s = 0; s < sides; ++s) {
      const float angle = step * static_cast<float>(s);
      const glm::vec3 n = std::cos(angle) * normal + std::sin(angle) * binormal;
      mesh.vertex(centerline[j] + radius * n, n);
    }
  }
  const uint32_t ring = static_cast<uint32_t>(sides);
  for (uint32_t j = 0; j + 1 < centerline.size(); ++j) {
    for (uint32_t s = 0; s < ring; ++s) {
      const uint32_t s1 = (s + 1) % ring;
      const uint32_t a = first + j * ring + s, b = first + j * ring + s1;
      const uint32_t c = first + (j + 1) * ring + s1, d = first + (j + 1) * ring + s;
      mesh.quad(a, b, c, d, material);
    }
  }
}

double latheTriangles(std::span<const ProfilePoint> profile, double segments) {
  double triangles = 0.0;
  for (size_t i = 0; i + 1 < profile.size(); ++i) {
    const int rings = (profile[i].r > 0.0f ? 1 : 0) + (profile[i + 1].r > 0.0f ? 1 : 0);
    triangles += static_cast<double>(rings) * segments;
  }
  return triangles;
}

void appendLathe(MeshBuilder& mesh, std::span<const ProfilePoint> profile, int segments,
                 const glm::vec3& base, uint32_t material) {
  MFR_CHECK(profile.size() >= 2 && segments >= 3);
  const uint32_t seg = static_cast<uint32_t>(segments);
  std::vector<float> cosines(seg), sines(seg);
  for (uint32_t s = 0; s < seg; ++s) {
    const double angle = 2.0 * glm::pi<double>() * static_cast<double>(s) / segments;
    cosines[s] = static_cast<float>(std::cos(angle));
    sines[s] = static_cast<float>(std::sin(angle));
  }
  // First vertex of each profile point's ring (a single vertex for points on the axis).
  std::vector<uint32_t> start(profile.size());
  for (size_t i = 0; i < profile.size(); ++i) {
    const ProfilePoint& p = profile[i];
    start[i] = static_cast<uint32_t>(mesh.scene().positions.size());
    if (p.r <= 0.0f) {
      mesh.vertex(base + glm::vec3(0.0f, p.y, 0.0f), glm::vec3(0.0f, p.normal.y > 0 ? 1 : -1, 0));
      continue;
    }
    for (uint32_t s = 0; s < seg; ++s) {
      const glm::vec3 radial(cosines[s], 0.0f, -sines[s]);
      mesh.vertex(base + p.r * radial + glm::vec3(0.0f, p.y, 0.0f),
                  glm::normalize(p.normal.x * radial + glm::vec3(0.0f, p.normal.y, 0.0f)));
    }
  }
  for (size_t i = 0; i + 1 < profile.size(); ++i) {
    const bool ringA = profile[i].r > 0.0f, ringB = profile[i + 1].r > 0.0f;
    for (uint32_t s = 0; s < seg; ++s) {
      const uint32_t s1 = (s + 1) % seg;
      if (ringA && ringB) {
        mesh.quad(start[i] + s, start[i] + s1, start[i + 1] + s1, start[i + 1] + s, material);
      } else if (ringA) {
        mesh.triangle(start[i] + s, start[i] + s1, start[i + 1], material);
      } else if (ringB) {
        mesh.triangle(start[i], start[i + 1] + s, start[i + 1] + s1, material);
      }
    }
  }
}

void computeProfileNormals(std::span<ProfilePoint> profile) {
  for (size_t i = 0; i < profile.size(); ++i) {
    const ProfilePoint& prev = profile[i == 0 ? 0 : i - 1];
    const ProfilePoint& next = profile[std::min(i + 1, profile.size() - 1)];
    const glm::vec2 tangent(next.r - prev.r, next.y - prev.y);
    const float len = glm::length(tangent);
    profile[i].normal = len > 0.0f ? glm::vec2(tangent.y, -tangent.x) / len : glm::vec2(1, 0);
  }
}

void appendUvSphere(MeshBuilder& mesh, const glm::vec3& center, float radius, int rings,
                    int sectors, uint32_t material) {
  MFR_CHECK_GE(rings, 2);
  std::vector<ProfilePoint> profile(static_cast<size_t>(rings) + 1);
  for (int i = 0; i <= rings; ++i) {
    // Colatitude from the north pole; the poles themselves are exactly on the axis.
    const double theta = glm::pi<double>() * static_cast<double>(i) / rings;
    const float s = (i == 0 || i == rings) ? 0.0f : static_cast<float>(std::sin(theta));
    const float c = i == 0 ? 1.0f : i == rings ? -1.0f : static_cast<float>(std::cos(theta));
    profile[static_cast<size_t>(i)] = {radius * s, radius * c, {s, c}};
  }
  appendLathe(mesh, profile, sectors, center, material);
}

void appendBox(MeshBuilder& mesh, const glm::vec3& lo, const glm::vec3& hi, uint32_t material) {
  MFR_CHECK(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z);
  // per axis a: the face at lo[a] (normal -a) and at hi[a] (normal +a)
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      glm::vec3 normal(0.0f);
      normal[axis] = side == 0 ? -1.0f : 1.0f;
      uint32_t corner[4];
      for (int c = 0; c < 4; ++c) {
        glm::vec3 p;
        p[axis] = side == 0 ? lo[axis] : hi[axis];
        p[u] = (c == 1 || c == 2) ? hi[u] : lo[u];
        p[v] = (c >= 2) ? hi[v] : lo[v];
        corner[c] = mesh.vertex(p, normal);
      }
      mesh.quad(corner[0], corner[1], corner[2], corner[3], material);
    }
  }
}

float jitteredAlpha(Rng& rng, float alpha, float spread) {
  const float factor = rng.uniform(1.0f - spread, 1.0f + spread);
  return std::clamp(alpha * factor, 0.02f, 1.0f);
}

}  // namespace procedural

// --- Public entry points ----------------------------------------------------------------------

std::vector<std::string> proceduralSceneNames() {
  std::vector<std::string> names;
  for (const procedural::SceneDef& def : procedural::sceneDefs()) names.emplace_back(def.name);
  return names;
}

Result<Scene> makeProceduralScene(const std::string& spec, uint64_t seed, double maxTriangles,
                                  std::optional<uint64_t> memoryLimitBytes) {
  using namespace procedural;
  std::string_view text = spec;
  if (text.starts_with("procedural:")) text.remove_prefix(std::string_view("procedural:").size());
  const size_t question = text.find('?');
  const std::string name(text.substr(0, question));
  const std::string_view query =
      question == std::string_view::npos ? std::string_view() : text.substr(question + 1);

  const auto& defs = sceneDefs();
  const auto def =
      std::find_if(defs.begin(), defs.end(), [&](const SceneDef& d) { return name == d.name; });
  if (def == defs.end())
    return makeError("procedural: unknown scene " + quoted(name) +
                     " (known: " + joined(proceduralSceneNames()) + ")");

  const std::string prefix = "procedural:" + name;
  std::vector<std::string> known = def->keys;
  known.emplace_back("seed");
  known.emplace_back("blend");

  ProceduralParams params;
  size_t pos = 0;
  while (!query.empty() && pos <= query.size()) {
    const size_t amp = std::min(query.find('&', pos), query.size());
    const std::string_view item = query.substr(pos, amp - pos);
    pos = amp + 1;
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0)
      return makeError(prefix + ": malformed parameter " + quoted(item) + " (expected key=value)");
    const std::string key(item.substr(0, eq));
    if (std::find(known.begin(), known.end(), key) == known.end())
      return makeError(prefix + ": unknown parameter " + quoted(key) + " (known: " + joined(known) +
                       ")");
    if (!params.emplace(key, std::string(item.substr(eq + 1))).second)
      return makeError(prefix + ": parameter " + quoted(key) + " given twice");
  }

  if (const auto it = params.find("seed"); it != params.end()) {
    const std::string& value = it->second;
    const char* end = value.data() + value.size();
    const auto [ptr, ec] = std::from_chars(value.data(), end, seed);
    if (ec != std::errc() || ptr != end || value.empty())
      return makeError(prefix + ": parameter 'seed' has invalid value " + quoted(value) +
                       " (expected an integer in [0, 18446744073709551615])");
  }

  // blend=MODE: every material of the scene (scene/blend_mode.hpp)
  std::optional<BlendMode> blend;
  if (const auto it = params.find("blend"); it != params.end()) {
    auto mode = parseBlendMode(it->second, prefix + ": parameter 'blend'");
    if (!mode) return mode.error();
    blend = *mode;
  }

  ParamReader reader(prefix, params, maxTriangles, memoryLimitBytes.value_or(defaultMemoryLimit()));
  Result<Scene> scene = def->build(reader, seed);
  if (!scene) return scene.error();
  if (blend)
    for (Material& m : scene->materials) m.blend = *blend;
  scene->name = "procedural:" + std::string(text);
  MFR_TRY(validateScene(*scene));
  return scene;
}

}  // namespace mfr
