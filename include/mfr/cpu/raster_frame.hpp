// CPU rasterizer with OpenGL's rules, so the GPU backend can be compared pixel for pixel:
//   - pixel centres at (x + 0.5, y + 0.5); vertices snapped to 1/256 pixel (8 sub-pixel bits);
//   - a fill rule that covers a pixel centre on a shared edge exactly once (top-left in the image's
//     y-down coordinates, which is GL's lower-left-origin rule seen upside down);
//   - clipping in homogeneous clip space against near and far (z = -w, z = w) and an x/y
//     guard band;
//   - perspective-correct attributes (normal, uv, vertex colour), depth = window z in [0, 1]
//     interpolated linearly in screen;
//   - back faces (clockwise in GL's y-up window coordinates) culled at set-up for the triangles
//     whose material Scene::cullsBackFaces says so; every other face is kept, whichever side it
//     shows (transparent geometry shows both sides).
// Set-up transforms, clips and bins the triangles once per frame into square tiles; every capture
// pass then rasterizes tile by tile. A tile is owned by one worker for the whole pass, so per-pixel
// updates need no locks, and within a pixel fragments arrive in primitive order: output is the same
// for any thread count.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/core/result.hpp"
#include "mfr/core/samples.hpp"
#include "mfr/cpu/fragment.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

inline constexpr int kMaxImageSize = 16384;
/// Shading: colour = base * (kAmbient + (1 - kAmbient) * |n.v|) (headlight diffuse).
inline constexpr float kAmbient = 0.2f;

struct RasterOptions {
  int width = 512;
  int height = 512;
  int tileSize = 16;  // pixels per tile side (storage pixels: see samples)
  int threads = 0;    // 0 = all cores
  /// Multisampling (core/samples.hpp): 1, 2, 4 or 8 samples at the standard positions. With more
  /// than one, `storage` decides what a pass sees: Pixel, a width x height frame whose fragments
  /// carry their coverage mask in the depth (withCoverage); Sample, a (width * samples) x height
  /// frame whose storage pixel x * samples + s is sample s of pixel x (the tile size must then be
  /// a multiple of the samples, so a tile holds whole pixels).
  int samples = 1;
  SampleStorage storage = SampleStorage::Pixel;
};

/// Shading inputs of one material, resolved once per frame.
struct ShadeMaterial {
  glm::vec3 color{1.0f};  // linear base colour
  float alpha = 1.0f;     // material alpha (factor, after transmission folding)
  const Texture* texture = nullptr;
  TextureSampler sampler;  // the material's baseColorSampler
  AlphaMode mode = AlphaMode::Opaque;
  float cutoff = 0.5f;
  bool alphaOverridden = false;
  float overrideAlpha = 1.0f;
  bool cullBack = false;              // Scene::cullsBackFaces: back faces dropped at set-up
  BlendMode blend = BlendMode::Over;  // the node word's kind (packBlendedColor)
};

/// Everything the inner loop needs of one (clipped) screen-space triangle.
struct TriangleSetup {
  int32_t x[3], y[3];              // fixed-point window coordinates (1/256 px), y down, area > 0
  int32_t minX, minY, maxX, maxY;  // inclusive pixel bounds of covered centres, clamped to viewport
  float z[3];                      // window depth
  float invW[3];                   // 1 / clip w
  glm::vec3 normalW[3];            // view-space normal / w
  glm::vec2 uvW[3];                // uv / w
  float invArea;                   // 1 / (twice the fixed-point area)
  uint32_t prim;
  uint32_t material;
  uint8_t topLeft;  // bit i set: edge opposite vertex i is a top or left edge
  /// Scene::hasVertexColor of the source triangle: its vertex colours / w are
  /// RasterFrame::vertexColors(this set-up) (kept beside the set-ups, so scenes without colours
  /// pay nothing for them).
  bool hasColor;
};

/// The vertex colours / w of one set-up, in the set-up's vertex order (linear RGBA).
struct TriangleColors {
  glm::vec4 colorW[3];
};

enum class ShadeMode {
  Coverage,  // depth and alpha test only (count / depth-range / occupancy passes)
  Full,      // plus shaded colour and n.v (capture passes)
};

struct TileRect {
  int x0, y0, x1, y1;  // inclusive
};

/// What a wide (SIMD) rasterizer reads of a frame, besides its set-ups and bins, to shade exactly
/// as RasterFrame does: the materials, the view-ray reconstruction (the view-space direction of
/// pixel centre (x, y) is (x * rayScaleX + rayBiasX, y * rayScaleY + rayBiasY, -1)) and the colour
/// tables. Valid while the frame lives.
struct ShadingInputs {
  const std::vector<ShadeMaterial>* materials = nullptr;
  float rayScaleX = 0, rayBiasX = 0, rayScaleY = 0, rayBiasY = 0;
  const ColorTables* tables = nullptr;
};

/// One view of a scene, set up for the tile passes: what render() (cpu/render.hpp) and
/// runComparison (compare/compare.hpp) take.
///
/// Lifetime: a frame refers to the scene's textures: the Scene must outlive the RasterFrame built
/// from it (and must not change meanwhile). A frame is immutable once built: any number of methods
/// can render it one after the other (runComparison renders every method from one frame).
class RasterFrame {
 public:
  /// Validates the size, fits the clip planes to the scene (the camera's zNear/zFar when non-zero),
  /// transforms, clips and bins every triangle. Errors (one line): width or height outside
  /// [1, kMaxImageSize], a tile size outside [8, 1024], a scene failing validateScene, a camera
  /// with non-finite values, eye == target, up parallel to the view direction, a field of view
  /// outside (0, 180) degrees, or explicit clip planes without 0 < near < far.
  static Result<RasterFrame> build(const Scene& scene, const Camera& camera,
                                   const RasterOptions& options);

  /// The storage size the passes index (pixel = y * width() + x): the image's, except under
  /// per-sample storage, where width() is the image's width times the samples.
  int width() const { return width_; }
  int height() const { return height_; }
  size_t pixelCount() const { return static_cast<size_t>(width_) * height_; }
  /// The image's width (width() / samples() under per-sample storage).
  int imageWidth() const { return imageWidth_; }
  int samples() const { return samples_; }
  SampleStorage sampleStorage() const { return storage_; }
  /// Storage pixels per image pixel: the samples under per-sample storage, else 1.
  int storagePerPixel() const { return storage_ == SampleStorage::Sample ? samples_ : 1; }
  /// Where storage pixel `pixel` is shaded, in pixels from image pixel (0, 0)'s centre: the pixel,
  /// or under per-sample storage its sample's position.
  glm::vec2 shadedPosition(uint32_t pixel) const {
    const uint32_t x = pixel % static_cast<uint32_t>(width_), y = pixel / width_;
    if (storagePerPixel() == 1) return {static_cast<float>(x), static_cast<float>(y)};
    const uint32_t s = x % static_cast<uint32_t>(samples_);
    return {static_cast<float>(x / samples_) + static_cast<float>(sampleX_[s]) / 256.0f,
            static_cast<float>(y) + static_cast<float>(sampleY_[s]) / 256.0f};
  }
  int threads() const { return threads_; }
  /// Workers of the tile passes: the requested threads, at most the hardware's (more would only
  /// queue; the fragment-parallel capture uses the full requested count on its own threads).
  int arenaThreads() const;
  const Camera& camera() const { return camera_; }
  /// The scene's cull mode (Scene::cull), recorded in the statistics.
  CullMode cull() const { return cull_; }
  /// What the scene and this frame's copies of it hold (sceneMemoryBytes of its vertices and
  /// triangles): the render's memory pre-flight counts it beside its own buffers.
  uint64_t sceneBytes() const { return sceneBytes_; }

  int tileSize() const { return tileSize_; }
  int tileCount() const { return tilesX_ * tilesY_; }
  TileRect tileRect(int tile) const;
  /// Triangle set-ups overlapping a tile, in primitive order.
  const uint32_t* tileBegin(int tile) const { return binned_.data() + binOffsets_[tile]; }
  const uint32_t* tileEnd(int tile) const { return binned_.data() + binOffsets_[tile + 1]; }

  const std::vector<TriangleSetup>& setups() const { return setups_; }
  /// The blend modes of the scene's materials (Scene::blendModes).
  uint32_t blendModes() const {
    uint32_t modes = 0;
    for (const ShadeMaterial& m : materials_) modes |= blendBit(m.blend);
    return modes;
  }
  /// The vertex colours / w of set-up `setupIndex` (meaningful when its hasColor is set; the
  /// frame keeps them only when the scene has colours).
  const TriangleColors& vertexColors(size_t setupIndex) const { return colors_[setupIndex]; }

  /// Rasterizes every triangle binned to `tile`, restricted to the tile. For each covered pixel
  /// centre that survives the alpha test it calls sink.accept(pixel, depth) (an early test before
  /// shading, like early-z), and when that returns true, shades (Full mode) and calls
  /// sink.emit(const Fragment&).
  template <ShadeMode Mode, class Sink>
  void rasterizeTile(int tile, Sink&& sink) const;

  /// Rasterizes one set-up triangle over the whole viewport (fragment-parallel capture).
  template <ShadeMode Mode, class Sink>
  void rasterizeTriangle(size_t setupIndex, Sink&& sink) const;

  /// The shading inputs of a wide rasterizer (cpu/raster_span_avx2.hpp).
  ShadingInputs shadingInputs() const {
    return {&materials_, rayScaleX_, rayBiasX_, rayScaleY_, rayBiasY_, colorTables_};
  }

  /// Runs fn(tile) for every tile on the frame's worker threads, each tile on one worker.
  template <class Fn>
  void forEachTile(Fn&& fn) const;

 private:
  template <ShadeMode Mode, class Sink>
  void rasterizeRect(const TriangleSetup& t, int x0, int y0, int x1, int y1, Sink& sink) const;
  // the same with coverage at the sample positions (samples_ > 1): image pixel rectangle
  template <ShadeMode Mode, class Sink>
  void rasterizeRectSamples(const TriangleSetup& t, int x0, int y0, int x1, int y1,
                            Sink& sink) const;
  // alpha test and base colour (texture x factor); false when the fragment is discarded
  template <ShadeMode Mode>
  bool surface(const TriangleSetup& t, const ShadeMaterial& m, float l0, float l1, float l2,
               glm::vec4& base) const;
  // colour and n.v of a surviving fragment
  // (px, py): the image position shaded, in pixels from pixel (0, 0)'s centre
  void shade(const TriangleSetup& t, float l0, float l1, float l2, float px, float py,
             const glm::vec4& base, Fragment& f) const;

  int width_ = 0, height_ = 0, threads_ = 1, tileSize_ = 32, tilesX_ = 0, tilesY_ = 0;
  int imageWidth_ = 0, samples_ = 1;
  SampleStorage storage_ = SampleStorage::Pixel;
  int32_t sampleX_[kMaxSamples] = {}, sampleY_[kMaxSamples] = {};  // offsets in 1/256 pixel
  Camera camera_;
  CullMode cull_ = CullMode::Auto;
  uint64_t sceneBytes_ = 0;
  std::vector<TriangleSetup> setups_;
  std::vector<TriangleColors>
      colors_;  // one per set-up when the scene has vertex colours, else empty
  std::vector<uint32_t> binned_;
  std::vector<uint32_t> binOffsets_;
  std::vector<ShadeMaterial> materials_;
  const ColorTables* colorTables_ = &ColorTables::get();
  // view-ray reconstruction: direction of pixel centre (x, y) in view space is
  // (x * rayScaleX + rayBiasX, y * rayScaleY + rayBiasY, -1)
  float rayScaleX_ = 0, rayBiasX_ = 0, rayScaleY_ = 0, rayBiasY_ = 0;
};

/// Adapts a callable taking a Fragment to the sink protocol (accepts everything).
template <class F>
struct EmitAll {
  F fn;
  bool accept(uint32_t, float) const { return true; }
  void emit(const Fragment& f) { fn(f); }
};
template <class F>
EmitAll(F) -> EmitAll<F>;

/// Adapts a callable taking (pixel, depth) to the sink protocol, for Coverage-mode passes.
template <class F>
struct CoverageAll {
  F fn;
  bool accept(uint32_t, float) const { return true; }
  void emit(const Fragment& f) { fn(f.pixel, f.depth); }
};
template <class F>
CoverageAll(F) -> CoverageAll<F>;

/// Most worker threads a run may ask for.
inline constexpr int kMaxThreads = 1024;

/// Checks a requested number of threads: [0, kMaxThreads], 0 meaning all cores. The error names
/// the parameter as `name` ("--threads 2000: must be in [0, 1024], 0 = all cores").
Result<void> checkThreads(int threads, const std::string& name);

/// Resolves a number of threads: 0 means all hardware threads.
int resolveThreads(int threads);

/// Most workers a tile pass runs: the hardware threads, or MFR_MAX_WORKERS when larger (so that
/// tests can run 8 real workers on a 2-core machine).
int maxTileWorkers();

}  // namespace mfr

#include "mfr/cpu/raster_frame_impl.hpp"
