// The OpenGL 4.5 engine's life and scene: the programs linked, the scene uploaded, the camera
// placed (create), and the single passes count() and nearestCosine(). A frame's passes are in
// gl_frame.cpp, the variable-k allocation on the device in gl_device_alloc.cpp, the program table
// in gl_programs.cpp, the technique table in gl_technique.cpp (see include/mfr/gl/gl_engine.hpp
// and shaders/).
#include "mfr/gl/gl_engine.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string_view>
#include <utility>

#include "gl/gl_state.hpp"
#include "gl/shader_sources.hpp"
#include "mfr/core/color.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/gl/shared_layout.h"
#include "mfr/method/method_math.h"

namespace mfr::gl {

// the node layout the shaders use is mfr::FragmentNode's
static_assert(kNodeBytes == sizeof(FragmentNode));
static_assert(kNodeWords * sizeof(uint32_t) == kNodeBytes);
static_assert(kNodeHiIndex == 0u);
static_assert((static_cast<uint64_t>(kFarDepthBits) << 32) == kFarNode);
static_assert(static_cast<uint32_t>(AlphaMode::Opaque) == kAlphaOpaque);
static_assert(static_cast<uint32_t>(AlphaMode::Mask) == kAlphaMask);
static_assert(blendBit(BlendMode::Over) == 1u << kBlendOver &&
              blendBit(BlendMode::Premultiplied) == 1u << kBlendPremultiplied &&
              blendBit(BlendMode::Additive) == 1u << kBlendAdditive &&
              blendBit(BlendMode::Multiply) == 1u << kBlendMultiply);
static_assert(kTableEncodeBase == kTableLinearBase + 256u &&
              kTableWords == kTableEncodeBase + 2u * 4096u);
static_assert(kAllocHistogramBins == kHistogramBins && kAllocSummaryWords == kHistogramBins + 1);

uint64_t GlRenderOutput::totalBufferBytes() const {
  uint64_t total = 0;
  for (const auto& [name, bytes] : bufferBytes) total += bytes;
  return total;
}

namespace {

// Guard band clamp of the CPU set-up (method_math.h, as setupTriangle in src/cpu/raster_frame.cpp);
// raster.geom clamps to it as the uniform uMaxNdc.
constexpr double kMaxNdc = method_math::kGuardBandMaxNdc;

}  // namespace

GlEngine::State::~State() {
  if (!sceneBuffers.empty())
    glDeleteBuffers(static_cast<GLsizei>(sceneBuffers.size()), sceneBuffers.data());
  if (vao) glDeleteVertexArrays(1, &vao);
  if (fbo) glDeleteFramebuffers(1, &fbo);
  if (query) glDeleteQueries(1, &query);
}

GLuint GlEngine::State::upload(const std::string& name, uint64_t bytes, const void* data) {
  if (uploadFailure) return 0;
  auto b = createCheckedBuffer(name, bytes, data, /*staticDraw=*/true);
  if (!b) {
    uploadFailure = b.error();
    return 0;
  }
  sceneBuffers.push_back(*b);
  sceneBytes[name] += bytes;
  return *b;
}

void GlEngine::State::setRasterUniforms(GLuint p) const {
  glProgramUniformMatrix4fv(p, loc(p, "uViewProj"), 1, GL_FALSE, &viewProj[0][0]);
  glProgramUniformMatrix3fv(p, loc(p, "uViewRot"), 1, GL_FALSE, &viewRot[0][0]);
  glProgramUniform2i(p, loc(p, "uSize"), width, height);
  GLfloat offsets[2 * kMaxSamples] = {};
  const auto pattern = samplePattern(sampling.samples);
  for (size_t i = 0; i < pattern.size(); ++i) {
    offsets[2 * i] = static_cast<float>(pattern[i].x) / 16.0f;
    offsets[2 * i + 1] = static_cast<float>(pattern[i].y) / 16.0f;
  }
  glProgramUniform2fv(p, loc(p, "uSampleOffsets"), kMaxSamples, offsets);
  glProgramUniform1d(p, loc(p, "uMaxNdc"), kMaxNdc);
  glProgramUniform4f(p, loc(p, "uRay"), ray.x, ray.y, ray.z, ray.w);
  glProgramUniform1f(p, loc(p, "uAmbient"), kAmbient);
  glProgramUniform1f(p, loc(p, "uDiffuse"), 1.0f - kAmbient);
  glProgramUniform1f(p, loc(p, "uInv255"), 1.0f / 255.0f);
}

void GlEngine::State::drawScene() const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, rasterWidth, height);
  // per-sample storage: one invocation per covered sample, its inputs at the sample
  if (sampling.storagePerPixel() > 1) {
    glEnable(GL_SAMPLE_SHADING);
    glMinSampleShading(1.0f);
  } else {
    glDisable(GL_SAMPLE_SHADING);
  }
  glDisable(GL_DEPTH_TEST);
  // every material culls back faces: GL culls them before the fragment shader (the native
  // raster's GL front face is the scene's back face, raster_native.glsl); otherwise the fragment
  // shaders discard them per material (surface())
  if (cullEveryBackFace) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT);
  } else {
    glDisable(GL_CULL_FACE);
  }
  glDisable(GL_BLEND);
  glDisable(GL_STENCIL_TEST);
  glBindVertexArray(vao);
  // without vertex colours attribute 3 is not streamed: it reads this constant white
  if (!vertexColors) glVertexAttrib4f(3, 1.0f, 1.0f, 1.0f, 1.0f);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindMaterials, materials);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindTriMaterial, triMaterial);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, colorTables);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindTexels, texels);
  glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
}

// the CPU engine's camera, matrices and view rays (RasterFrame::build)
void GlEngine::State::placeCamera(const Camera& cameraIn, const Scene& scene) {
  camera = fitClipPlanes(cameraIn, sceneBounds(scene));
  const glm::mat4 view = viewMatrix(camera);
  viewProj = projectionMatrix(camera, rasterWidth, height) * view;
  viewRot = glm::mat3(view);
  const float tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5f);
  const float aspect = static_cast<float>(rasterWidth) / static_cast<float>(height);
  ray.x = 2.0f * tanHalf * aspect / static_cast<float>(rasterWidth);
  ray.y = (1.0f / static_cast<float>(rasterWidth) - 1.0f) * tanHalf * aspect;
  ray.z = -2.0f * tanHalf / static_cast<float>(height);
  ray.w = (1.0f - 1.0f / static_cast<float>(height)) * tanHalf;
}

// positions, normals, uvs (zeros when the scene has none), vertex colours (only when the scene has
// them: else attribute 3 is the constant white that drawScene sets), indices, the vertex array and
// the triangles' materials
void GlEngine::State::uploadGeometry(const Scene& scene) {
  const size_t vertices = scene.positions.size();
  const GLuint positions =
      upload("positions", vertices * sizeof(glm::vec3), scene.positions.data());
  const GLuint normals = upload("normals", vertices * sizeof(glm::vec3), scene.normals.data());
  std::vector<glm::vec2> zeroUvs;
  if (scene.uvs.empty()) zeroUvs.assign(vertices, glm::vec2(0.0f));
  const GLuint uvs = upload("uvs", vertices * sizeof(glm::vec2),
                            scene.uvs.empty() ? zeroUvs.data() : scene.uvs.data());
  const GLuint indices =
      upload("indices", scene.indices.size() * sizeof(uint32_t), scene.indices.data());
  indexCount = static_cast<GLsizei>(scene.indices.size());
  glCreateVertexArrays(1, &vao);
  const GLuint vbos[3] = {positions, normals, uvs};
  const GLint sizes[3] = {3, 3, 2};
  for (GLuint i = 0; i < 3; ++i) {
    glVertexArrayVertexBuffer(vao, i, vbos[i], 0, static_cast<GLsizei>(sizes[i] * sizeof(float)));
    glVertexArrayAttribFormat(vao, i, sizes[i], GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, i, i);
    glEnableVertexArrayAttrib(vao, i);
  }
  if (vertexColors) {
    const GLuint colors =
        upload("vertex colours", vertices * sizeof(glm::vec4), scene.colors.data());
    glVertexArrayVertexBuffer(vao, 3, colors, 0, static_cast<GLsizei>(sizeof(glm::vec4)));
    glVertexArrayAttribFormat(vao, 3, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 3, 3);
    glEnableVertexArrayAttrib(vao, 3);
  }
  glVertexArrayElementBuffer(vao, indices);
  triMaterial = upload("triangle materials", scene.triangleMaterial.size() * 4,
                       scene.triangleMaterial.data());
}

// the textures' texels and the material words, each within one shader storage block
Result<void> GlEngine::State::uploadMaterials(const Scene& scene) {
  std::vector<uint32_t> texelWords;
  std::vector<uint32_t> textureFirst;
  for (const Texture& t : scene.textures) {
    textureFirst.push_back(static_cast<uint32_t>(texelWords.size()));
    const size_t n = static_cast<size_t>(t.width) * t.height;
    const size_t at = texelWords.size();
    texelWords.resize(at + n);
    std::memcpy(texelWords.data() + at, t.rgba.data(), n * 4);  // R | G << 8 | B << 16 | A << 24
  }
  std::vector<uint32_t> materialWords;
  auto bits = [](float f) { return std::bit_cast<uint32_t>(f); };
  for (uint32_t index = 0; index < scene.materials.size(); ++index) {
    const Material& m = scene.materials[index];
    const bool textured = m.baseColorTexture >= 0;
    const Texture* t = textured ? &scene.textures[m.baseColorTexture] : nullptr;
    const uint32_t words[kMaterialWords] = {
        bits(m.baseColor.r),
        bits(m.baseColor.g),
        bits(m.baseColor.b),
        bits(m.baseColor.a),
        textured ? textureFirst[m.baseColorTexture] : kNoTexture,
        t ? static_cast<uint32_t>(t->width) : 0u,
        t ? static_cast<uint32_t>(t->height) : 0u,
        static_cast<uint32_t>(m.alphaMode),
        bits(m.alphaCutoff),
        scene.alphaOverride ? 1u : 0u,
        bits(scene.alphaOverride ? *scene.alphaOverride : 1.0f),
        (scene.cullsBackFaces(index) ? kMaterialCullBack : 0u) |
            static_cast<uint32_t>(m.baseColorSampler.wrapS) << kMaterialWrapSShift |
            static_cast<uint32_t>(m.baseColorSampler.wrapT) << kMaterialWrapTShift |
            (m.baseColorSampler.filter == TextureFilter::Nearest ? kMaterialNearest : 0u) |
            static_cast<uint32_t>(m.blend) << kMaterialBlendShift};
    materialWords.insert(materialWords.end(), words, words + kMaterialWords);
  }
  for (const auto& [name, bytes] :
       {std::pair<const char*, uint64_t>{"texels", texelWords.size() * 4},
        {"triangle materials", scene.triangleMaterial.size() * 4}})
    if (bytes > maxBlockBytes)
      return makeError("--engine gl: the scene's " + std::string(name) + " need " +
                       std::to_string(bytes) + " B, above GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" +
                       std::to_string(maxBlockBytes) + " B)");
  materials = upload("materials", materialWords.size() * 4, materialWords.data());
  texels = upload("texels", texelWords.size() * 4, texelWords.data());
  return {};
}

// the sRGB8 decode and encode tables of the resolve
void GlEngine::State::uploadColorTables() {
  auto bits = [](float f) { return std::bit_cast<uint32_t>(f); };
  const ColorTables& tables = ColorTables::get();
  std::vector<uint32_t> tableWords(kTableWords);
  for (int i = 0; i < 256; ++i) tableWords[kTableLinearBase + i] = bits(tables.srgb8ToLinear[i]);
  for (int b = 0; b < 4096; ++b) {
    const uint8_t low = tables.bucketLowSrgb8[b];
    tableWords[kTableEncodeBase + 2 * b] = low;
    tableWords[kTableEncodeBase + 2 * b + 1] = bits(tables.lowerBound[low + 1]);
  }
  colorTables = upload("colour tables", tableWords.size() * 4, tableWords.data());
}

// the attachment-less framebuffer of the raster passes and the timer query
void GlEngine::State::createFramebufferAndQuery() {
  glCreateFramebuffers(1, &fbo);
  glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_WIDTH, rasterWidth);
  glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_HEIGHT, height);
  if (sampling.samples > 1)
    glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_SAMPLES, sampling.samples);
  glCreateQueries(GL_TIME_ELAPSED, 1, &query);
}

namespace {

// The sample-pattern probe: one pixel covered whole, each sample's invocation (sample shading)
// records its position in 1/16 pixel, every invocation its coverage mask. GL window y is the
// image's y (raster_native.vert negates clip y), so a position is the image's offset + 8/16.
constexpr const char* kProbeVertex = R"(#version 450 core
void main() {
  const vec2 corner[3] = vec2[](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
  gl_Position = vec4(corner[gl_VertexID], 0.0, 1.0);
}
)";
constexpr const char* kProbeFragment = R"(#version 450 core
layout(std430, binding = 0) buffer Probe {
  uint mask;
  uint positions[];  // x | y << 8, in 1/16 pixel from the pixel's corner
};
void main() {
  atomicOr(mask, uint(gl_SampleMaskIn[0]));
  positions[gl_SampleID] =
      uint(gl_SamplePosition.x * 16.0 + 0.5) | (uint(gl_SamplePosition.y * 16.0 + 0.5) << 8);
}
)";

std::string offsetText(int x, int y) {
  std::string text = std::to_string(x);
  text += ", ";
  text += std::to_string(y);
  text.insert(0, 1, '(');
  text += ")/16";
  return text;
}

}  // namespace

Result<void> GlEngine::State::checkSamplePattern() const {
  const int samples = sampling.samples;
  const std::string what = "--engine gl: --samples " + std::to_string(samples);
  GLint maxSamples = 0;
  glGetIntegerv(GL_MAX_FRAMEBUFFER_SAMPLES, &maxSamples);
  if (samples > maxSamples)
    return makeError(what + ": above this GL's GL_MAX_FRAMEBUFFER_SAMPLES (" +
                     std::to_string(maxSamples) + ")");
  auto vs = compileShaderSource(GL_VERTEX_SHADER, "sample pattern probe", kProbeVertex);
  if (!vs) return vs.error();
  auto fs = compileShaderSource(GL_FRAGMENT_SHADER, "sample pattern probe", kProbeFragment);
  if (!fs) return fs.error();
  const GLuint program = glCreateProgram();
  glAttachShader(program, *vs);
  glAttachShader(program, *fs);
  glLinkProgram(program);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  std::vector<uint32_t> words(1 + kMaxSamples, 0xffffffffu);
  words[0] = 0;
  GLuint buffer = 0;
  glCreateBuffers(1, &buffer);
  glNamedBufferData(buffer, static_cast<GLsizeiptr>(words.size() * 4), words.data(),
                    GL_DYNAMIC_COPY);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffer);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, 1, 1);
  glEnable(GL_SAMPLE_SHADING);
  glMinSampleShading(1.0f);
  glUseProgram(program);
  glBindVertexArray(vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(words.size() * 4), words.data());
  glDisable(GL_SAMPLE_SHADING);
  glUseProgram(0);
  glDeleteBuffers(1, &buffer);
  glDeleteProgram(program);
  const int got = std::popcount(words[0]);
  if (got != samples)
    return makeError(what + ": this GL rasterizes " + std::to_string(got) +
                     " samples per pixel for " + std::to_string(samples) +
                     " (GL_MAX_FRAMEBUFFER_SAMPLES " + std::to_string(maxSamples) + ")");
  const auto pattern = samplePattern(samples);
  for (int i = 0; i < samples; ++i) {
    const int x = static_cast<int>(words[1 + i] & 0xffu) - 8;
    const int y = static_cast<int>((words[1 + i] >> 8) & 0xffu) - 8;
    if (x != pattern[i].x || y != pattern[i].y)
      return makeError(what + ": this GL's sample " + std::to_string(i) + " lies at " +
                       offsetText(x, y) + " from the pixel centre, not at the standard " +
                       offsetText(pattern[i].x, pattern[i].y));
  }
  return {};
}

GlEngine::GlEngine(std::unique_ptr<State> state) : state_(std::move(state)) {}
GlEngine::GlEngine(GlEngine&&) noexcept = default;
GlEngine& GlEngine::operator=(GlEngine&&) noexcept = default;
GlEngine::~GlEngine() = default;

const char* toString(GlRaster raster) {
  switch (raster) {
    case GlRaster::Native:
      return "native";
    case GlRaster::Exact:
      return "exact";
  }
  return "native";
}

Result<GlRaster> parseGlRaster(std::string_view text) {
  if (text == "native") return GlRaster::Native;
  if (text == "exact") return GlRaster::Exact;
  return makeError("--gl-raster '" + std::string(text) + "': expected native or exact");
}

GlRaster GlEngine::raster() const {
  return state_->raster;
}
int GlEngine::width() const {
  return state_->width;
}
int GlEngine::height() const {
  return state_->height;
}
const GlSampling& GlEngine::sampling() const {
  return state_->sampling;
}
const Camera& GlEngine::camera() const {
  return state_->camera;
}

namespace {

// the image size, the scene and the camera, before any GL call
Result<void> checkCreateArgs(const Scene& scene, const Camera& cameraIn, int width, int height) {
  if (width < 1 || height < 1 || width > kMaxImageSize || height > kMaxImageSize)
    return makeError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     ": width and height must be in [1, " + std::to_string(kMaxImageSize) + "]");
  MFR_TRY(validateScene(scene));
  const Camera& c = cameraIn;
  if (glm::length(c.target - c.eye) <= 0.0f ||
      glm::length(glm::cross(c.target - c.eye, c.up)) <= 0.0f ||
      !(c.fovYDegrees > 0.0f && c.fovYDegrees < 180.0f))
    return makeError(
        "camera: eye != target, up not parallel to the view direction and a field "
        "of view in (0, 180) degrees needed");
  MFR_TRY(checkProjection(c, fitClipPlanes(c, sceneBounds(scene))));  // as RasterFrame::build
  return {};
}

// the image within this GL's framebuffer and texel-buffer limits (the context current)
Result<void> checkGlLimits(int width, int height) {
  GLint maxFbWidth = 0, maxFbHeight = 0, maxTexelBuffer = 0;
  glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &maxFbWidth);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_HEIGHT, &maxFbHeight);
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &maxTexelBuffer);
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  if (width > maxFbWidth || height > maxFbHeight || pixels > static_cast<uint64_t>(maxTexelBuffer))
    return makeError("--engine gl: image size " + std::to_string(width) + "x" +
                     std::to_string(height) + " above this GL's limits (framebuffer " +
                     std::to_string(maxFbWidth) + "x" + std::to_string(maxFbHeight) +
                     ", texel buffer " + std::to_string(maxTexelBuffer) + ")");
  return {};
}

// what the engine's shaders compile in: the view's sampling and the scene's material features
EngineSwitches engineSwitches(const Scene& scene, GlSampling sampling) {
  EngineSwitches e;
  e.samples = sampling.samples;
  e.sampleStorage = sampling.storage == SampleStorage::Sample;
  e.vertexColors = !scene.colors.empty();
  e.textures = false;
  e.alphaMask = false;
  for (const Material& m : scene.materials) {
    e.textures = e.textures || m.baseColorTexture >= 0;
    e.alphaMask = e.alphaMask || m.alphaMode == AlphaMode::Mask;
  }
  e.blendModes = scene.blendModes();
  return e;
}

}  // namespace

Result<GlEngine> GlEngine::create(const GlContext& context, const Scene& scene,
                                  const Camera& cameraIn, int width, int height, bool interlock,
                                  GlRaster raster, GlSampling sampling) {
  MFR_TRY(checkCreateArgs(scene, cameraIn, width, height));
  if (samplePattern(sampling.samples).empty())
    return makeError("--samples " + std::to_string(sampling.samples) + ": expected 1, 2, 4 or 8");
  if (sampling.samples > 1 && raster == GlRaster::Exact)
    return makeError("--gl-raster exact: --samples " + std::to_string(sampling.samples) +
                     ": the exact raster emulates one sample per pixel (use --gl-raster native)");
  if (sampling.samples == 1) sampling.storage = SampleStorage::Pixel;
  const int per = sampling.storagePerPixel();
  if (static_cast<int64_t>(width) * per > kMaxImageSize)
    return makeError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     " with per-sample storage of " + std::to_string(per) +
                     " samples: the storage's width must be at most " +
                     std::to_string(kMaxImageSize));
  context.makeCurrent();
  MFR_TRY(checkGlLimits(width * per, height));

  auto s = std::make_unique<State>();
  GLint64 maxBlock = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
  s->maxBlockBytes = static_cast<uint64_t>(maxBlock);
  s->width = width * per;
  s->rasterWidth = width;
  s->height = height;
  s->sampling = sampling;
  s->placeCamera(cameraIn, scene);
  s->raster = raster;
  s->vertexColors = !scene.colors.empty();
  // (the exact raster's geometry shader culls at set-up, as the CPU engine)
  s->cullEveryBackFace = raster == GlRaster::Native && !scene.materials.empty();
  for (uint32_t m = 0; m < scene.materials.size(); ++m)
    s->cullEveryBackFace = s->cullEveryBackFace && scene.cullsBackFaces(m);
  auto kbufferPrelude = kbufferInterlockPrelude(context, interlock);
  if (!kbufferPrelude) return kbufferPrelude.error();
  State& st = *s;
  MFR_TRY(st.programs.link(context, raster, *kbufferPrelude, engineSwitches(scene, sampling),
                           [&st](GLuint p) { st.setRasterUniforms(p); }));
  s->uploadGeometry(scene);
  MFR_TRY(s->uploadMaterials(scene));
  s->uploadColorTables();
  s->createFramebufferAndQuery();
  if (s->uploadFailure) return *s->uploadFailure;
  if (sampling.samples > 1) MFR_TRY(s->checkSamplePattern());
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: scene upload failed (GL error " + glErrorText(e) + ")");
  return GlEngine(std::move(s));
}

Result<std::vector<uint32_t>> GlEngine::count() {
  return state_->countPass(false);
}

Result<std::vector<uint8_t>> GlEngine::edgePixels() {
  if (state_->sampling.maskSamples() == 1)
    return makeError("--engine gl: edge pixels need a multisampled view with per-pixel storage");
  auto partial = state_->countPass(true);
  if (!partial) return partial.error();
  std::vector<uint8_t> edges(partial->size());
  for (size_t p = 0; p < edges.size(); ++p) edges[p] = (*partial)[p] > 0 ? 1 : 0;
  return edges;
}

Result<std::vector<uint32_t>> GlEngine::State::countPass(bool edges) const {
  const State& s = *this;
  const uint64_t pixels = s.pixels();
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb(&ledger);
  const GLuint counts = fb.make("counts", pixels * 4);
  clearUint(counts, 0);
  const GLuint program = s.program(ProgramId::Count);
  glProgramUniform1ui(program, loc(program, "uEdges"), edges ? 1u : 0u);
  glUseProgram(program);
  fb.bindImage(counts, kBindCounts);
  s.drawScene();
  glProgramUniform1ui(program, loc(program, "uEdges"), 0u);  // the other count passes count all
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  if (fb.failure) return *fb.failure;
  std::vector<uint32_t> n(pixels);
  glGetNamedBufferSubData(counts, 0, static_cast<GLsizeiptr>(pixels * 4), n.data());
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the count pass failed (GL error " + glErrorText(e) + ")");
  return n;
}

Result<std::vector<float>> GlEngine::nearestCosine() {
  State& s = *state_;
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb(&ledger);
  const GLuint nearest = fb.make("nearest", uint64_t{s.pixels()} * kNearestWords * 4);
  if (fb.failure) return *fb.failure;
  MFR_TRY(s.nearestPass(fb, nearest, nullptr));
  return s.readCosine(nearest);
}

}  // namespace mfr::gl
