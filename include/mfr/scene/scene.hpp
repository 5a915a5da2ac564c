// The scene every backend renders: one flat triangle soup in world space (node transforms already
// applied by the loaders), materials with glTF-style alpha semantics, textures and cameras.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/blend_mode.hpp"
#include "mfr/core/result.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/cull_mode.hpp"

namespace mfr {

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

/// RGBA8 texture, rows top to bottom, colour channels sRGB-encoded (glTF base colour convention),
/// alpha linear. How it is sampled is the referencing material's TextureSampler.
struct Texture {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4
};

/// glTF sampler wrap modes per axis (values: method_math.h's kTextureWrap*, shared by both
/// engines).
enum class TextureWrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
/// Filter of the one sample a fragment takes (no derivatives, no mip-maps: docs/GLTF.md).
enum class TextureFilter : uint8_t { Linear, Nearest };

/// A texture reference's sampler (glTF attaches it to the texture): wrap in u (S) and v (T),
/// filter. The glTF defaults: repeat, linear.
struct TextureSampler {
  TextureWrap wrapS = TextureWrap::Repeat;
  TextureWrap wrapT = TextureWrap::Repeat;
  TextureFilter filter = TextureFilter::Linear;
};

struct Material {
  std::string name;
  glm::vec4 baseColor{1.0f};        // linear RGB, alpha factor
  int baseColorTexture = -1;        // index into Scene::textures, or -1
  TextureSampler baseColorSampler;  // how baseColorTexture is sampled
  AlphaMode alphaMode = AlphaMode::Blend;
  float alphaCutoff = 0.5f;  // AlphaMode::Mask only
  /// KHR_materials_transmission: set when the material declares transmission; the loader folds it
  /// into baseColor.a (alpha = max(floor, 1 - transmissionFactor)) and records the raw factor here.
  std::optional<float> transmission;
  /// glTF `doubleSided`: false lets CullMode::Auto cull the back faces. Formats without the notion
  /// (OBJ, PLY, JSON and procedural scenes) are double-sided.
  bool doubleSided = true;
  /// How the material's fragments blend (scene/blend_mode.hpp): `--blend`, a procedural scene's
  /// `blend=`; files do not say (glTF's BLEND is over).
  BlendMode blend = BlendMode::Over;
};

struct Scene {
  std::string name;  // file path or procedural spec it came from

  std::vector<glm::vec3> positions;  // world space
  std::vector<glm::vec3> normals;    // per vertex, same size as positions (loaders fill flat ones)
  std::vector<glm::vec2> uvs;  // empty, or same size as positions (KHR_texture_transform applied)
  /// Vertex colours (glTF COLOR_0, PLY red/green/blue/alpha): empty, or one per vertex, linear
  /// RGB and alpha, multiplied into the base colour and alpha. A triangle whose three colours are
  /// all exactly white is shaded without them (hasVertexColor), so a scene without colours and the
  /// uncoloured triangles of a scene with some render as they did before colours existed.
  std::vector<glm::vec4> colors;
  std::vector<uint32_t> indices;           // 3 per triangle
  std::vector<uint32_t> triangleMaterial;  // one per triangle, index into materials

  std::vector<Material> materials;
  std::vector<Texture> textures;

  /// The cameras the file defines, in the file's order (may be empty): `--view N` renders
  /// cameras[N] (fileCamera, scene_request.hpp) and `mfr info` lists them.
  std::vector<Camera> cameras;
  /// Empty, or one per camera: why --view refuses that camera ("" where it renders it), e.g. a
  /// glTF orthographic camera or one no node of the scene places. Such a camera's entry in
  /// `cameras` is a placeholder (the default Camera).
  std::vector<std::string> cameraProblems;
  std::optional<Camera> defaultCamera;  // procedural scenes frame themselves

  glm::vec3 background{1.0f, 1.0f, 1.0f};  // linear RGB behind everything
  /// When set, every material's alpha becomes this value and every surface blends with it (the
  /// papers render whole scenes as transparent): Opaque and Blend materials, and the fragments of
  /// Mask materials that pass their alpha test (a cutout keeps its shape; what it cuts away stays
  /// away).
  std::optional<float> alphaOverride;
  /// Primitives of the file that are not surfaces (glTF points and lines): not rendered, and
  /// reported (RenderStats::primitivesSkipped, the CLI's summary line) instead of dropped silently.
  uint64_t primitivesSkipped = 0;
  /// The back faces the engines cull (SceneRequest::cull, `--cull`).
  CullMode cull = CullMode::Auto;

  /// Whether the engines drop the back faces of triangles with material `material`: the scene's
  /// cull mode resolved against the material's doubleSided. The one rule every raster applies.
  bool cullsBackFaces(uint32_t material) const {
    return cull == CullMode::Back || (cull == CullMode::Auto && !materials[material].doubleSided);
  }

  /// Whether the raster multiplies the interpolated vertex colour into triangle `triangle`'s base
  /// colour: some corner's colour is not exactly white (1, 1, 1, 1). The one rule every raster
  /// applies (the GL exact raster's geometry shader evaluates it on the same values).
  bool hasVertexColor(size_t triangle) const {
    if (colors.empty()) return false;
    for (int c = 0; c < 3; ++c)
      if (colors[indices[triangle * 3 + c]] != glm::vec4(1.0f)) return true;
    return false;
  }

  /// The blend modes of the scene's materials, as blendBit masks.
  uint32_t blendModes() const {
    uint32_t modes = 0;
    for (const Material& m : materials) modes |= blendBit(m.blend);
    return modes;
  }

  size_t triangleCount() const { return indices.size() / 3; }
  size_t vertexCount() const { return positions.size(); }
};

struct Bounds {
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};
  glm::vec3 center() const { return 0.5f * (min + max); }
  float radius() const { return 0.5f * glm::length(max - min); }
};

/// Axis-aligned bounds of the vertices referenced by triangles.
Bounds sceneBounds(const Scene& scene);

/// Vertex coordinates beyond this are refused by validateScene: the scene's bounds, the framing
/// camera and clipping square and sum them in single precision (FLT_MAX is 3.4e38).
inline constexpr float kMaxCoordinate = 1e18f;

/// Checks the invariants every consumer relies on (index ranges, sizes, finite values within
/// +-kMaxCoordinate, at least one triangle). The message names the scene.
Result<void> validateScene(const Scene& scene);

/// What a scene costs per vertex and per triangle once loaded and set up for a view: its own arrays
/// (a position, normal, uv and colour, 48 bytes; three indices and a material, 16 bytes) and the
/// CPU raster's copies (RasterFrame::build: a transformed vertex; a triangle set-up and its vertex
/// colours, held twice while the set-ups are gathered). The loaders compute a file's or a
/// procedural scene's vertices and triangles, after node references, instancing and parameters,
/// and check sceneMemoryBytes against the memory limit before they build anything.
inline constexpr uint64_t kSceneBytesPerVertex = 48 + 64;
inline constexpr uint64_t kSceneBytesPerTriangle = 16 + 384;

/// vertices * kSceneBytesPerVertex + triangles * kSceneBytesPerTriangle, saturating.
uint64_t sceneMemoryBytes(uint64_t vertices, uint64_t triangles);

/// checkMemory (mfr/core/memory_limit.hpp) of sceneMemoryBytes: "<what>: its 16777216 vertices and
/// 5592405 triangles need 3.83 GiB (...), more than the memory limit of 256.00 MiB (...)".
Result<void> checkSceneMemory(uint64_t vertices, uint64_t triangles, uint64_t limit,
                              const std::string& what);

/// Fills `normals` with area-weighted vertex normals when empty.
void computeVertexNormals(Scene& scene);

}  // namespace mfr
