// Frame set-up of the CPU rasterizer: vertex transform, homogeneous clipping, triangle set-up in
// 8-bit sub-pixel fixed point, and binning into tiles (see raster_frame.hpp for the rules).
#include "mfr/cpu/raster_frame.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "mfr/method/method_math.h"

namespace mfr {

Result<void> checkThreads(int threads, const std::string& name) {
  if (threads < 0 || threads > kMaxThreads)
    return makeError(name + " " + std::to_string(threads) + ": must be in [0, " +
                     std::to_string(kMaxThreads) + "], 0 = all cores");
  return {};
}

int resolveThreads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? static_cast<int>(hw) : 1;
}

int maxTileWorkers() {
  // MFR_MAX_WORKERS raises the cap above the hardware threads (tests: 8 workers on 2 cores)
  static const int cap = [] {
    const char* env = std::getenv("MFR_MAX_WORKERS");
    const int requested = env ? std::atoi(env) : 0;
    return std::max(resolveThreads(0), std::min(requested, 1024));
  }();
  return cap;
}

int RasterFrame::arenaThreads() const {
  return std::min(threads_, maxTileWorkers());
}

namespace {

struct ClipVertex {
  glm::vec4 clip;
  glm::vec3 normal;  // view space
  glm::vec2 uv;
  glm::vec4 color;  // linear RGBA (white without vertex colours)
};

// what sceneMemoryBytes (mfr/scene/scene.hpp) counts for a frame
static_assert(sizeof(ClipVertex) <= kSceneBytesPerVertex - 48);
static_assert(2 * (sizeof(TriangleSetup) + sizeof(TriangleColors)) <= kSceneBytesPerTriangle - 16);

ClipVertex lerp(const ClipVertex& a, const ClipVertex& b, float t) {
  return {glm::mix(a.clip, b.clip, t), glm::mix(a.normal, b.normal, t), glm::mix(a.uv, b.uv, t),
          glm::mix(a.color, b.color, t)};
}

// x/y guard band in NDC units: keeps fixed-point window coordinates below 2^25 at 16384 pixels
// (method_math.h, shared with shaders/raster.geom).
using method_math::kGuardBand;

// Signed distances to the six clip planes (inside >= 0).
inline float planeDistance(const glm::vec4& c, int plane) {
  switch (plane) {
    case 0:
      return c.z + c.w;  // near
    case 1:
      return c.w - c.z;  // far
    case 2:
      return kGuardBand * c.w + c.x;
    case 3:
      return kGuardBand * c.w - c.x;
    case 4:
      return kGuardBand * c.w + c.y;
    default:
      return kGuardBand * c.w - c.y;
  }
}

// Sutherland-Hodgman against the planes the triangle crosses; returns the polygon size.
int clipPolygon(ClipVertex (&poly)[12], int count, unsigned planes) {
  ClipVertex tmp[12];
  for (int plane = 0; plane < 6 && count > 0; ++plane) {
    if (!(planes & (1u << plane))) continue;
    int out = 0;
    for (int i = 0; i < count; ++i) {
      const ClipVertex& a = poly[i];
      const ClipVertex& b = poly[(i + 1) % count];
      const float da = planeDistance(a.clip, plane), db = planeDistance(b.clip, plane);
      if (da >= 0.0f) tmp[out++] = a;
      if ((da >= 0.0f) != (db >= 0.0f)) tmp[out++] = lerp(a, b, da / (da - db));
    }
    count = out;
    std::copy(tmp, tmp + count, poly);
  }
  return count;
}

struct SetupContext {
  int width, height;
  // the extreme sample offsets (1/256 pixel; 0 with one sample)
  int32_t minOffsetX = 0, maxOffsetX = 0, minOffsetY = 0, maxOffsetY = 0;
};

// Screen-space set-up of one clipped triangle; returns false when it covers no pixel centre (no
// sample position, multisampled) or is a back face that `cullBack` drops.
bool setupTriangle(const SetupContext& ctx, const ClipVertex& v0, const ClipVertex& v1,
                   const ClipVertex& v2, uint32_t prim, uint32_t material, bool cullBack,
                   TriangleSetup& t, TriangleColors& colors) {
  const ClipVertex* v[3] = {&v0, &v1, &v2};
  // Clipping leaves |x/w|, |y/w| <= kGuardBand up to float rounding; under extreme projections
  // (a field of view of 1e-20 degrees, coordinates near the float range) that rounding is large
  // or NaN. Clamping to the guard band keeps the fixed-point set-up below in range.
  constexpr double kMaxNdc = method_math::kGuardBandMaxNdc;
  double sx[3], sy[3];
  for (int i = 0; i < 3; ++i) {
    const glm::vec4& c = v[i]->clip;
    const double invW = 1.0 / static_cast<double>(c.w);
    const double ndcX = static_cast<double>(c.x) * invW, ndcY = static_cast<double>(c.y) * invW;
    if (!(std::isfinite(ndcX) && std::isfinite(ndcY) && std::isfinite(invW))) return false;
    sx[i] = (std::clamp(ndcX, -kMaxNdc, kMaxNdc) * 0.5 + 0.5) * ctx.width;
    sy[i] = (0.5 - std::clamp(ndcY, -kMaxNdc, kMaxNdc) * 0.5) * ctx.height;
    t.x[i] = static_cast<int32_t>(std::llround(sx[i] * 256.0));
    t.y[i] = static_cast<int32_t>(std::llround(sy[i] * 256.0));
    t.z[i] = static_cast<float>(static_cast<double>(c.z) * invW * 0.5 + 0.5);
    t.invW[i] = static_cast<float>(invW);
    t.normalW[i] = v[i]->normal * t.invW[i];
    t.uvW[i] = v[i]->uv * t.invW[i];
    colors.colorW[i] = v[i]->color * t.invW[i];
  }
  int64_t area = (static_cast<int64_t>(t.x[1]) - t.x[0]) * (static_cast<int64_t>(t.y[2]) - t.y[0]) -
                 (static_cast<int64_t>(t.y[1]) - t.y[0]) * (static_cast<int64_t>(t.x[2]) - t.x[0]);
  if (area == 0) return false;
  // Window y runs down, so a front face (counter-clockwise in GL's y-up window) has area < 0
  // here. Clipping keeps the winding (w > 0 inside the near plane): every fan triangle of a
  // clipped back face is a back face.
  if (area > 0 && cullBack) return false;
  if (area < 0) {  // a kept face: flip to a positive orientation
    std::swap(t.x[1], t.x[2]);
    std::swap(t.y[1], t.y[2]);
    std::swap(t.z[1], t.z[2]);
    std::swap(t.invW[1], t.invW[2]);
    std::swap(t.normalW[1], t.normalW[2]);
    std::swap(t.uvW[1], t.uvW[2]);
    std::swap(colors.colorW[1], colors.colorW[2]);
    area = -area;
  }
  t.invArea = static_cast<float>(1.0 / static_cast<double>(area));
  t.topLeft = 0;
  for (int i = 0; i < 3; ++i) {
    const int a = (i + 1) % 3, b = (i + 2) % 3;
    const int32_t dx = t.x[b] - t.x[a], dy = t.y[b] - t.y[a];
    if ((dy == 0 && dx > 0) || dy < 0) t.topLeft |= static_cast<uint8_t>(1u << i);
  }
  // pixels with a sample position c*256+128+offset inside [min, max] of the fixed-point bounds
  const int32_t minFx = std::min({t.x[0], t.x[1], t.x[2]}),
                maxFx = std::max({t.x[0], t.x[1], t.x[2]});
  const int32_t minFy = std::min({t.y[0], t.y[1], t.y[2]}),
                maxFy = std::max({t.y[0], t.y[1], t.y[2]});
  auto ceilDiv = [](int64_t a, int64_t b) { return a >= 0 ? (a + b - 1) / b : -((-a) / b); };
  auto floorDiv = [](int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  t.minX = static_cast<int32_t>(
      std::max<int64_t>(0, ceilDiv(int64_t{minFx} - 128 - ctx.maxOffsetX, 256)));
  t.minY = static_cast<int32_t>(
      std::max<int64_t>(0, ceilDiv(int64_t{minFy} - 128 - ctx.maxOffsetY, 256)));
  t.maxX = static_cast<int32_t>(
      std::min<int64_t>(ctx.width - 1, floorDiv(int64_t{maxFx} - 128 - ctx.minOffsetX, 256)));
  t.maxY = static_cast<int32_t>(
      std::min<int64_t>(ctx.height - 1, floorDiv(int64_t{maxFy} - 128 - ctx.minOffsetY, 256)));
  if (t.minX > t.maxX || t.minY > t.maxY) return false;
  t.prim = prim;
  t.material = material;
  return true;
}

std::vector<ShadeMaterial> resolveMaterials(const Scene& scene) {
  std::vector<ShadeMaterial> out;
  for (const Material& m : scene.materials) {
    ShadeMaterial s;
    s.color = glm::vec3(m.baseColor);
    s.alpha = m.baseColor.a;
    s.texture = m.baseColorTexture >= 0 ? &scene.textures[m.baseColorTexture] : nullptr;
    s.sampler = m.baseColorSampler;
    s.mode = m.alphaMode;
    s.cutoff = m.alphaCutoff;
    s.cullBack = scene.cullsBackFaces(static_cast<uint32_t>(out.size()));
    s.blend = m.blend;
    if (scene.alphaOverride) {
      s.alphaOverridden = true;
      s.overrideAlpha = *scene.alphaOverride;
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace

Result<RasterFrame> RasterFrame::build(const Scene& scene, const Camera& cameraIn,
                                       const RasterOptions& options) {
  if (options.width < 1 || options.height < 1 || options.width > kMaxImageSize ||
      options.height > kMaxImageSize)
    return makeError("image size " + std::to_string(options.width) + "x" +
                     std::to_string(options.height) + ": width and height must be in [1, " +
                     std::to_string(kMaxImageSize) + "]");
  MFR_TRY(checkThreads(options.threads, "threads"));
  if (options.tileSize < 8 || options.tileSize > 1024)
    return makeError("tile size " + std::to_string(options.tileSize) + ": must be in [8, 1024]");
  const std::span<const SampleOffset> pattern = samplePattern(options.samples);
  if (pattern.empty())
    return makeError("samples " + std::to_string(options.samples) + ": expected 1, 2, 4 or 8");
  const int storagePerPixel = options.storage == SampleStorage::Sample ? options.samples : 1;
  if (options.tileSize % storagePerPixel != 0)
    return makeError("tile size " + std::to_string(options.tileSize) +
                     ": must be a multiple of the samples (" + std::to_string(options.samples) +
                     ") under per-sample storage");
  if (static_cast<int64_t>(options.width) * storagePerPixel > (int64_t{1} << 24) ||
      static_cast<int64_t>(options.width) * storagePerPixel * options.height > (int64_t{1} << 31))
    return makeError("image size " + std::to_string(options.width) + "x" +
                     std::to_string(options.height) + " with " + std::to_string(options.samples) +
                     " samples stored per sample: too many storage pixels");
  MFR_TRY(validateScene(scene));
  const Camera& c = cameraIn;
  const bool cameraFinite = std::isfinite(c.eye.x) && std::isfinite(c.eye.y) &&
                            std::isfinite(c.eye.z) && std::isfinite(c.target.x) &&
                            std::isfinite(c.target.y) && std::isfinite(c.target.z) &&
                            std::isfinite(c.up.x) && std::isfinite(c.up.y) && std::isfinite(c.up.z);
  if (!cameraFinite || glm::length(c.target - c.eye) <= 0.0f ||
      glm::length(glm::cross(c.target - c.eye, c.up)) <= 0.0f)
    return makeError(
        "camera: eye, target and up must be finite, eye != target, up not parallel "
        "to the view direction");
  if (!(c.fovYDegrees > 0.0f && c.fovYDegrees < 180.0f))
    return makeError("camera: field of view must be in (0, 180) degrees");
  if (c.zNear < 0.0f || c.zFar < 0.0f || (c.zNear > 0.0f && c.zFar > 0.0f && c.zFar <= c.zNear))
    return makeError("camera: need 0 < near < far (or 0 for automatic)");

  RasterFrame frame;
  frame.imageWidth_ = options.width;
  frame.samples_ = options.samples;
  frame.storage_ = options.storage;
  frame.width_ = options.width * storagePerPixel;
  frame.height_ = options.height;
  frame.threads_ = resolveThreads(options.threads);
  frame.tileSize_ = options.tileSize;
  frame.tilesX_ = (frame.width_ + options.tileSize - 1) / options.tileSize;
  SetupContext ctx{options.width, options.height};
  for (size_t s = 0; s < pattern.size(); ++s) {
    frame.sampleX_[s] = pattern[s].x * 16;  // 1/16 -> 1/256 pixel
    frame.sampleY_[s] = pattern[s].y * 16;
    ctx.minOffsetX = std::min(ctx.minOffsetX, frame.sampleX_[s]);
    ctx.maxOffsetX = std::max(ctx.maxOffsetX, frame.sampleX_[s]);
    ctx.minOffsetY = std::min(ctx.minOffsetY, frame.sampleY_[s]);
    ctx.maxOffsetY = std::max(ctx.maxOffsetY, frame.sampleY_[s]);
  }
  frame.tilesY_ = (options.height + options.tileSize - 1) / options.tileSize;
  frame.camera_ = fitClipPlanes(cameraIn, sceneBounds(scene));
  MFR_TRY(checkProjection(cameraIn, frame.camera_));
  frame.materials_ = resolveMaterials(scene);
  frame.cull_ = scene.cull;
  frame.sceneBytes_ = sceneMemoryBytes(scene.vertexCount(), scene.triangleCount());

  const glm::mat4 view = viewMatrix(frame.camera_);
  const glm::mat4 viewProj = projectionMatrix(frame.camera_, options.width, options.height) * view;
  const glm::mat3 viewRot(view);
  const float tanHalf = std::tan(glm::radians(frame.camera_.fovYDegrees) * 0.5f);
  const float aspect = static_cast<float>(options.width) / static_cast<float>(options.height);
  frame.rayScaleX_ = 2.0f * tanHalf * aspect / static_cast<float>(options.width);
  frame.rayBiasX_ = (1.0f / static_cast<float>(options.width) - 1.0f) * tanHalf * aspect;
  frame.rayScaleY_ = -2.0f * tanHalf / static_cast<float>(options.height);
  frame.rayBiasY_ = (1.0f - 1.0f / static_cast<float>(options.height)) * tanHalf;

  const WorkerLimit workers(frame.arenaThreads());
  tbb::task_arena arena(frame.arenaThreads());
  // vertex transform
  const size_t vertexCount = scene.positions.size();
  std::vector<ClipVertex> vertices(vertexCount);
  arena.execute([&] {
    tbb::parallel_for(size_t{0}, vertexCount, size_t{4096}, [&](size_t begin) {
      const size_t end = std::min(vertexCount, begin + 4096);
      for (size_t i = begin; i < end; ++i) {
        vertices[i].clip = viewProj * glm::vec4(scene.positions[i], 1.0f);
        vertices[i].normal = viewRot * scene.normals[i];
        vertices[i].uv = scene.uvs.empty() ? glm::vec2(0.0f) : scene.uvs[i];
        vertices[i].color = scene.colors.empty() ? glm::vec4(1.0f) : scene.colors[i];
      }
    });
  });

  // clip + set-up, in chunks whose outputs are concatenated in order (deterministic)
  const size_t triangleCount = scene.triangleCount();
  constexpr size_t kChunk = 8192;
  const size_t chunks = (triangleCount + kChunk - 1) / kChunk;
  std::vector<std::vector<TriangleSetup>> chunkSetups(chunks);
  const bool sceneColors = !scene.colors.empty();
  std::vector<std::vector<TriangleColors>> chunkColors(sceneColors ? chunks : 0);
  arena.execute([&] {
    tbb::parallel_for(size_t{0}, chunks, [&](size_t chunk) {
      std::vector<TriangleSetup>& out = chunkSetups[chunk];
      const size_t end = std::min(triangleCount, (chunk + 1) * kChunk);
      out.reserve(end - chunk * kChunk);  // one set-up a triangle, not twice that by doubling
      for (size_t tri = chunk * kChunk; tri < end; ++tri) {
        const uint32_t prim = static_cast<uint32_t>(tri);
        const uint32_t material = scene.triangleMaterial[tri];
        const bool hasColor = scene.hasVertexColor(tri);
        ClipVertex poly[12] = {vertices[scene.indices[tri * 3 + 0]],
                               vertices[scene.indices[tri * 3 + 1]],
                               vertices[scene.indices[tri * 3 + 2]]};
        unsigned crossed = 0;
        bool rejected = false;
        for (int plane = 0; plane < 6; ++plane) {
          int inside = 0;
          for (int i = 0; i < 3; ++i) inside += planeDistance(poly[i].clip, plane) >= 0.0f;
          if (inside == 0) rejected = true;
          if (inside < 3) crossed |= 1u << plane;
        }
        if (rejected) continue;
        const int count = crossed ? clipPolygon(poly, 3, crossed) : 3;
        for (int i = 1; i + 1 < count; ++i) {
          TriangleSetup t;
          TriangleColors colors;
          if (setupTriangle(ctx, poly[0], poly[i], poly[i + 1], prim, material,
                            frame.materials_[material].cullBack, t, colors)) {
            t.hasColor = hasColor;
            out.push_back(t);
            if (sceneColors) chunkColors[chunk].push_back(colors);
          }
        }
      }
    });
  });
  size_t total = 0;
  for (const auto& c : chunkSetups) total += c.size();
  frame.setups_.reserve(total);
  for (auto& c : chunkSetups) {
    frame.setups_.insert(frame.setups_.end(), c.begin(), c.end());
    std::vector<TriangleSetup>().swap(c);
  }
  if (sceneColors) {
    frame.colors_.reserve(total);
    for (auto& c : chunkColors) {
      frame.colors_.insert(frame.colors_.end(), c.begin(), c.end());
      std::vector<TriangleColors>().swap(c);
    }
  }

  // binning: count, prefix sum, fill (primitive order within each tile)
  const int tileSize = frame.tileSize_;
  frame.binOffsets_.assign(static_cast<size_t>(frame.tileCount()) + 1, 0);
  // tiles in storage pixels: image pixel x is storage columns x * per .. x * per + per - 1
  auto forTiles = [&](const TriangleSetup& t, auto&& fn) {
    for (int ty = t.minY / tileSize; ty <= t.maxY / tileSize; ++ty)
      for (int tx = t.minX * storagePerPixel / tileSize;
           tx <= (t.maxX * storagePerPixel + storagePerPixel - 1) / tileSize; ++tx)
        fn(ty * frame.tilesX_ + tx);
  };
  for (const TriangleSetup& t : frame.setups_)
    forTiles(t, [&](int tile) { ++frame.binOffsets_[tile + 1]; });
  for (size_t i = 1; i < frame.binOffsets_.size(); ++i)
    frame.binOffsets_[i] += frame.binOffsets_[i - 1];
  frame.binned_.resize(frame.binOffsets_.back());
  std::vector<uint32_t> cursor(frame.binOffsets_.begin(), frame.binOffsets_.end() - 1);
  for (size_t s = 0; s < frame.setups_.size(); ++s)
    forTiles(frame.setups_[s],
             [&](int tile) { frame.binned_[cursor[tile]++] = static_cast<uint32_t>(s); });
  return frame;
}

}  // namespace mfr
