// The OpenGL 4.5 engine: scene upload, the count / prefix sum / capture / resolve passes, timing
// and read-back (see include/mfr/gl/gl_engine.hpp and shaders/).
#include "mfr/gl/gl_engine.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>
#include <string_view>
#include <utility>

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
static_assert(kTableWords == kTableBoundBase + 257u && kTableBoundBase == kTableCoarseBase + 4096u);
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

std::string oneLine(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  std::string out;
  for (char c : text) {
    if (c == '\n')
      out += " | ";
    else
      out += c;
  }
  return out;
}

// the fragment stage's raster part (raster_exact.glsl or raster_native.glsl)
const char* rasterPart(GlRaster raster) {
  switch (raster) {
    case GlRaster::Native:
      return "raster_native.glsl";
    case GlRaster::Exact:
      return "raster_exact.glsl";
  }
  return "raster_native.glsl";
}

struct StageFile {
  GLenum stage;
  std::string file;
};

// the vertex [and geometry] stages of a raster program
std::vector<StageFile> rasterStages(GlRaster raster) {
  switch (raster) {
    case GlRaster::Native:
      return {{GL_VERTEX_SHADER, "raster_native.vert"}};
    case GlRaster::Exact:
      return {{GL_VERTEX_SHADER, "raster.vert"}, {GL_GEOMETRY_SHADER, "raster.geom"}};
  }
  return {};
}

// "#version", the prelude, the shared layout, [a raster fragment stage's raster part and the
// common part,] the shader's own text
std::string composeSource(const std::string& file, const char* raster, const std::string& prelude) {
  std::string s = "#version 450 core\n";
  s += prelude;
  s += embeddedShader("shared_layout.h");
  s += "\n";
  s += embeddedShader("method_math.h");  // the methods' maths, shared with the CPU engine
  s += "\n";
  if (raster) {
    s += embeddedShader(raster);
    s += "\n";
    s += embeddedShader("raster_common.glsl");
    s += "\n";
  }
  s += "#line 1\n";
  s += embeddedShader(file);
  return s;
}

Result<GLuint> compileShader(GLenum stage, const std::string& file, const char* raster,
                             const std::string& prelude) {
  if (embeddedShader(file).empty()) return makeError("--engine gl: no embedded shader " + file);
  return compileShaderSource(stage, file, composeSource(file, raster, prelude));
}

// Every program of the engine, in link order (the first that fails is the error): its shader
// file (a raster program is rasterStages() + this fragment shader) and what its
// fragment stage is prefixed with.
enum class Prelude : uint8_t {
  None,
  KBufferSync,  // the k-buffer capture's sync: nothing (spin-lock) or the interlock extension
  Atomic64,     // GL_ARB_gpu_shader_int64 + GL_NV_shader_atomic_int64 (fixed-k 64-bit atomics)
};
struct ProgramRow {
  const char* file;
  bool raster;
  Prelude prelude;
};
constexpr ProgramRow kPrograms[] = {
    {"count.frag", true, Prelude::None},
    {"capture_abuffer.frag", true, Prelude::None},
    {"capture_kbuffer.frag", true, Prelude::KBufferSync},
    {"capture_kbuffer_atomic64.frag", true, Prelude::Atomic64},
    {"swap_node_words.comp", false, Prelude::Atomic64},
    {"depth_range.frag", true, Prelude::None},
    {"occupancy_fill.frag", true, Prelude::None},
    {"nearest_cosine.frag", true, Prelude::None},
    {"wboit.frag", true, Prelude::None},
    {"wboit_resolve.comp", false, Prelude::None},
    {"mboit_moments.frag", true, Prelude::None},
    {"mboit_color.frag", true, Prelude::None},
    {"mboit_resolve.comp", false, Prelude::None},
    {"mlab.frag", true, Prelude::None},
    {"mlab_resolve.comp", false, Prelude::None},
    {"dkb_features.frag", true, Prelude::None},
    {"dkb_infer.comp", false, Prelude::None},
    {"occupancy_count.comp", false, Prelude::None},
    {"prefix_sum.comp", false, Prelude::None},
    {"prefix_sum_add.comp", false, Prelude::None},
    {"resolve.comp", false, Prelude::None},
    {"alloc_histogram.comp", false, Prelude::None},
    {"importance.comp", false, Prelude::None},
    {"importance_total.comp", false, Prelude::None},
    {"alloc_k.comp", false, Prelude::None},
    {"alloc_pack.comp", false, Prelude::None},
};

constexpr const char* kAtomic64Prelude =
    "#extension GL_ARB_gpu_shader_int64 : require\n"
    "#extension GL_NV_shader_atomic_int64 : require\n";

// The k-buffer capture's prelude for a driver's interlock extension (empty: the spin-lock).
std::string interlockPrelude(const std::string& ext) {
  if (ext.empty()) return {};
  std::string prelude = "#extension " + ext + " : require\n";
  if (ext == "GL_ARB_fragment_shader_interlock")
    prelude +=
        "#define MFR_INTERLOCK_BEGIN() beginInvocationInterlockARB()\n"
        "#define MFR_INTERLOCK_END() endInvocationInterlockARB()\n";
  else if (ext == "GL_NV_fragment_shader_interlock")
    prelude +=
        "#define MFR_INTERLOCK_BEGIN() beginInvocationInterlockNV()\n"
        "#define MFR_INTERLOCK_END() endInvocationInterlockNV()\n";
  else  // the ordering lasts to the end of the shader
    prelude +=
        "#define MFR_INTERLOCK_BEGIN() beginFragmentShaderOrderingINTEL()\n"
        "#define MFR_INTERLOCK_END()\n";
  prelude += "#define MFR_INTERLOCK 1\n";
  if (ext != "GL_INTEL_fragment_shader_ordering")
    prelude += "layout(pixel_interlock_ordered) in;\n";
  return prelude;
}

// `prelude`: lines after "#version" in the fragment shader (the interlock's #extension, #define);
// `raster`: the fragment stage's raster part (nullptr: none)
Result<GLuint> linkProgram(const std::string& name, const std::vector<StageFile>& stages,
                           const std::string& prelude = "", const char* raster = nullptr) {
  std::vector<GLuint> shaders;
  auto cleanup = [&] {
    for (GLuint s : shaders) glDeleteShader(s);
  };
  for (const StageFile& sf : stages) {
    const bool fragment = sf.stage == GL_FRAGMENT_SHADER;
    auto shader = compileShader(sf.stage, sf.file, fragment ? raster : nullptr,
                                fragment ? prelude : std::string());
    if (!shader) {
      cleanup();
      return shader.error();
    }
    shaders.push_back(*shader);
  }
  const GLuint program = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(program, s);
  glLinkProgram(program);
  cleanup();
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    glDeleteProgram(program);
    return makeError("--engine gl: program " + name + " does not link: " + oneLine(log.c_str()));
  }
  return program;
}

GLint loc(GLuint program, const char* name) {
  return glGetUniformLocation(program, name);
}

// Buffers of one frame, deleted with it; their sizes go to the ledger. The first buffer GL could
// not allocate is `failure` (later makes return 0; the frame's passes are skipped).
struct FrameBuffers {
  std::vector<GLuint> buffers, textures;
  std::map<std::string, uint64_t>* ledger = nullptr;
  std::optional<Error> failure;
  ~FrameBuffers() {
    if (!buffers.empty()) glDeleteBuffers(static_cast<GLsizei>(buffers.size()), buffers.data());
    if (!textures.empty()) glDeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
  }
  GLuint make(const std::string& name, uint64_t bytes, const void* data = nullptr) {
    if (failure) return 0;
    auto b = createCheckedBuffer(name, bytes, data);
    if (!b) {
      failure = b.error();
      return 0;
    }
    buffers.push_back(*b);
    (*ledger)[name] += bytes;
    return *b;
  }
  // an r32ui imageBuffer view of a buffer, bound to an image unit
  void bindImage(GLuint buffer, GLuint unit) {
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &t);
    glTextureBuffer(t, GL_R32UI, buffer);
    textures.push_back(t);
    glBindImageTexture(unit, t, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  }
};

void clearUint(GLuint buffer, uint32_t value) {
  glClearNamedBufferData(buffer, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
}

// work groups as a 2D grid (each dimension at most 65535); shaders linearise the group id
void dispatchGroups(uint64_t groups) {
  if (groups == 0) return;
  const uint64_t x = std::min<uint64_t>(groups, 65535);
  const uint64_t y = (groups + x - 1) / x;
  glDispatchCompute(static_cast<GLuint>(x), static_cast<GLuint>(y), 1);
}

// runs a pass and appends its wall time (glFinish included) to `passes`
template <class Body>
void timedPass(std::vector<GlPassTime>* passes, const char* name, Body&& body) {
  const auto t0 = std::chrono::steady_clock::now();
  body();
  glFinish();
  if (passes)
    passes->push_back(
        {name, 0.0,
         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()});
}

std::string glErrorText(GLenum e) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%x", e);
  return buf;
}

}  // namespace

Result<unsigned> createCheckedBuffer(const std::string& name, uint64_t bytes, const void* data,
                                     bool staticDraw) {
  const uint64_t size = std::max<uint64_t>(bytes, 16);
  if (size > static_cast<uint64_t>(INT64_MAX))
    return makeError("--engine gl: the " + name + " buffer needs " + std::to_string(bytes) +
                     " B, beyond GL's buffer sizes");
  GLuint b = 0;
  glCreateBuffers(1, &b);
  glNamedBufferData(b, static_cast<GLsizeiptr>(size), data,
                    staticDraw ? GL_STATIC_DRAW : GL_DYNAMIC_COPY);
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR && b != 0) return b;
  glDeleteBuffers(1, &b);
  while (glGetError() != GL_NO_ERROR) {
  }
  return makeError(
      "--engine gl: out of GPU memory: the " + name + " buffer (" + std::to_string(bytes) +
      " B) could not be allocated (" +
      (e == GL_OUT_OF_MEMORY ? std::string("GL_OUT_OF_MEMORY") : "GL error " + glErrorText(e)) +
      ")");
}

Result<unsigned> compileShaderSource(unsigned stage, const std::string& name,
                                     const std::string& source) {
  const GLuint shader = glCreateShader(stage);
  if (shader == 0) return makeError("--engine gl: shader " + name + ": glCreateShader failed");
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    return makeError("--engine gl: shader " + name + " does not compile: " + oneLine(log.c_str()));
  }
  return shader;
}

namespace {

// What render() makes of a method and its options: which capture and resolve run, with which
// allocation and k.
struct RenderPlan {
  const MethodDesc& method;
  const GlRenderOptions& options;
  const Allocation* alloc;  // the host's per-pixel allocation, or none
  uint32_t pixels;
  bool device;    // the allocation the compute shaders left in the engine's buffers
  bool perPixel;  // a per-pixel allocation (host or device)
  uint64_t allocSlots;
  bool isABuffer, isKBuffer, hybrid;
  bool accumulates, isWboit;  // wboit or mboit: accumulators, no nodes
  uint32_t accumWords;
  bool isMlab;
  uint32_t k;  // the fixed k (0 with a per-pixel allocation)
};

}  // namespace

struct GlEngine::State {
  int width = 0, height = 0;
  Camera camera;
  glm::mat4 viewProj{1.0f};
  glm::mat3 viewRot{1.0f};
  glm::vec4 ray{0.0f};
  GLuint vao = 0;
  std::vector<GLuint> sceneBuffers;
  GLuint triMaterial = 0, materials = 0, colorTables = 0, texels = 0;
  GLsizei indexCount = 0;
  GLuint fbo = 0;
  GLuint progCount = 0, progABuffer = 0, progKBuffer = 0, progScan = 0, progScanAdd = 0,
         progResolve = 0, progDepthRange = 0, progOccFill = 0, progOccCount = 0, progNearest = 0,
         progWboit = 0, progWboitResolve = 0, progMboitMoments = 0, progMboitColor = 0,
         progMboitResolve = 0, progMlab = 0, progMlabResolve = 0, progDkbFeatures = 0,
         progDkbInfer = 0, progAllocHistogram = 0, progImportance = 0, progImportanceTotal = 0,
         progAllocK = 0, progAllocPack = 0;
  // the fixed-k capture with 64-bit atomics (0: the driver lacks GL_NV_shader_atomic_int64)
  GLuint progKBufferAtomic64 = 0, progSwapWords = 0;
  GLuint query = 0;
  // the variable-k allocation the compute shaders computed (countOnDevice, allocateCapped,
  // allocateByImportance), kept for render() and the read-backs of the output
  std::map<std::string, uint64_t> deviceLedger;
  std::unique_ptr<FrameBuffers> device;
  GLuint deviceCounts = 0, deviceCapacity = 0, deviceReserved = 0, deviceWords = 0,
         deviceImportance = 0, deviceNearest = 0;
  uint64_t deviceSlots = 0, deviceReservedSlots = 0;
  bool deviceByImportance = false;
  uint64_t maxBlockBytes = 0;  // GL_MAX_SHADER_STORAGE_BLOCK_SIZE
  GlRaster raster = GlRaster::Native;
  std::map<std::string, uint64_t> sceneBytes;

  ~State() {
    for (GLuint p : {progCount,           progABuffer,         progKBuffer,      progScan,
                     progScanAdd,         progResolve,         progDepthRange,   progOccFill,
                     progOccCount,        progNearest,         progWboit,        progWboitResolve,
                     progMboitMoments,    progMboitColor,      progMboitResolve, progMlab,
                     progMlabResolve,     progDkbFeatures,     progDkbInfer,     progAllocHistogram,
                     progImportance,      progImportanceTotal, progAllocK,       progAllocPack,
                     progKBufferAtomic64, progSwapWords})
      if (p) glDeleteProgram(p);
    if (!sceneBuffers.empty())
      glDeleteBuffers(static_cast<GLsizei>(sceneBuffers.size()), sceneBuffers.data());
    if (vao) glDeleteVertexArrays(1, &vao);
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (query) glDeleteQueries(1, &query);
  }

  std::optional<Error> uploadFailure;  // the first scene buffer GL could not allocate
  GLuint upload(const std::string& name, uint64_t bytes, const void* data) {
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

  void setRasterUniforms(GLuint p) const {
    glProgramUniformMatrix4fv(p, loc(p, "uViewProj"), 1, GL_FALSE, &viewProj[0][0]);
    glProgramUniformMatrix3fv(p, loc(p, "uViewRot"), 1, GL_FALSE, &viewRot[0][0]);
    glProgramUniform2i(p, loc(p, "uSize"), width, height);
    glProgramUniform1d(p, loc(p, "uMaxNdc"), kMaxNdc);
    glProgramUniform4f(p, loc(p, "uRay"), ray.x, ray.y, ray.z, ray.w);
    glProgramUniform1f(p, loc(p, "uAmbient"), kAmbient);
    glProgramUniform1f(p, loc(p, "uDiffuse"), 1.0f - kAmbient);
    glProgramUniform1f(p, loc(p, "uInv255"), 1.0f / 255.0f);
  }

  void drawScene() const {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, width, height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDisable(GL_STENCIL_TEST);
    glBindVertexArray(vao);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindMaterials, materials);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindTriMaterial, triMaterial);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, colorTables);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindTexels, texels);
    glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
  }

  // the CPU engine's camera, matrices and view rays (RasterFrame::build)
  void placeCamera(const Camera& cameraIn, const Scene& scene) {
    camera = fitClipPlanes(cameraIn, sceneBounds(scene));
    const glm::mat4 view = viewMatrix(camera);
    viewProj = projectionMatrix(camera, width, height) * view;
    viewRot = glm::mat3(view);
    const float tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5f);
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    ray.x = 2.0f * tanHalf * aspect / static_cast<float>(width);
    ray.y = (1.0f / static_cast<float>(width) - 1.0f) * tanHalf * aspect;
    ray.z = -2.0f * tanHalf / static_cast<float>(height);
    ray.w = (1.0f - 1.0f / static_cast<float>(height)) * tanHalf;
  }

  // The member that holds each program of kPrograms.
  GLuint* programOf(const char* file) {
    static const std::pair<const char*, GLuint State::*> members[] = {
        {"count.frag", &State::progCount},
        {"capture_abuffer.frag", &State::progABuffer},
        {"capture_kbuffer.frag", &State::progKBuffer},
        {"capture_kbuffer_atomic64.frag", &State::progKBufferAtomic64},
        {"swap_node_words.comp", &State::progSwapWords},
        {"depth_range.frag", &State::progDepthRange},
        {"occupancy_fill.frag", &State::progOccFill},
        {"nearest_cosine.frag", &State::progNearest},
        {"wboit.frag", &State::progWboit},
        {"wboit_resolve.comp", &State::progWboitResolve},
        {"mboit_moments.frag", &State::progMboitMoments},
        {"mboit_color.frag", &State::progMboitColor},
        {"mboit_resolve.comp", &State::progMboitResolve},
        {"mlab.frag", &State::progMlab},
        {"mlab_resolve.comp", &State::progMlabResolve},
        {"dkb_features.frag", &State::progDkbFeatures},
        {"dkb_infer.comp", &State::progDkbInfer},
        {"occupancy_count.comp", &State::progOccCount},
        {"prefix_sum.comp", &State::progScan},
        {"prefix_sum_add.comp", &State::progScanAdd},
        {"resolve.comp", &State::progResolve},
        {"alloc_histogram.comp", &State::progAllocHistogram},
        {"importance.comp", &State::progImportance},
        {"importance_total.comp", &State::progImportanceTotal},
        {"alloc_k.comp", &State::progAllocK},
        {"alloc_pack.comp", &State::progAllocPack},
    };
    for (const auto& [name, member] : members)
      if (std::string_view(name) == file) return &(this->*member);
    MFR_CHECK(false && "a program of kPrograms without its member");
    return nullptr;
  }

  // every program of kPrograms, in its order (the first that fails is the error); the raster
  // programs' uniforms set. The 64-bit atomic capture is linked where the driver offers the
  // extensions: it was never verified on such a driver (llvmpipe has none), so one that announces
  // them but does not compile the shaders keeps the lock (engine_counters.atomic64 says per frame
  // which capture ran) instead of losing the whole engine.
  Result<void> linkPrograms(const GlContext& context, const std::string& kbufferPrelude) {
    // (raster programs: raster_native.vert, or raster.vert + raster.geom, and the fragment shader
    // with its raster part)
    const bool atomic64 = hasAtomic64(context);
    bool atomic64Linked = atomic64;
    for (const ProgramRow& row : kPrograms) {
      if (row.prelude == Prelude::Atomic64 && !atomic64) continue;
      const std::string prelude = row.prelude == Prelude::KBufferSync ? kbufferPrelude
                                  : row.prelude == Prelude::Atomic64  ? kAtomic64Prelude
                                                                      : "";
      std::vector<StageFile> stages = row.raster ? rasterStages(raster) : std::vector<StageFile>{};
      stages.push_back(
          {static_cast<GLenum>(row.raster ? GL_FRAGMENT_SHADER : GL_COMPUTE_SHADER), row.file});
      auto linked =
          linkProgram(row.file, stages, prelude, row.raster ? rasterPart(raster) : nullptr);
      if (!linked && row.prelude == Prelude::Atomic64) {
        atomic64Linked = false;
        continue;
      }
      if (!linked) return linked.error();
      *programOf(row.file) = *linked;
      if (row.raster) setRasterUniforms(*linked);
    }
    if (!atomic64Linked)  // both atomic programs or neither
      for (GLuint* p : {&progKBufferAtomic64, &progSwapWords}) {
        if (*p) glDeleteProgram(*p);
        *p = 0;
      }
    return {};
  }

  // positions, normals, uvs (zeros when the scene has none), indices, the vertex array and the
  // triangles' materials
  void uploadGeometry(const Scene& scene) {
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
    glVertexArrayElementBuffer(vao, indices);
    triMaterial = upload("triangle materials", scene.triangleMaterial.size() * 4,
                         scene.triangleMaterial.data());
  }

  // the textures' texels and the material words, each within one shader storage block
  Result<void> uploadMaterials(const Scene& scene) {
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
    for (const Material& m : scene.materials) {
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
          0u};
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
  void uploadColorTables() {
    auto bits = [](float f) { return std::bit_cast<uint32_t>(f); };
    const ColorTables& tables = ColorTables::get();
    std::vector<uint32_t> tableWords(kTableWords);
    for (int i = 0; i < 256; ++i) tableWords[kTableLinearBase + i] = bits(tables.srgb8ToLinear[i]);
    for (int i = 0; i < 4096; ++i) tableWords[kTableCoarseBase + i] = tables.coarseSrgb8[i];
    for (int i = 0; i < 257; ++i) tableWords[kTableBoundBase + i] = bits(tables.lowerBound[i]);
    colorTables = upload("colour tables", tableWords.size() * 4, tableWords.data());
  }

  // the attachment-less framebuffer of the raster passes and the timer query
  void createFramebufferAndQuery() {
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_WIDTH, width);
    glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_HEIGHT, height);
    glCreateQueries(GL_TIME_ELAPSED, 1, &query);
  }

  // the method's kind and allocation, checked against what the GL engine runs and the block size
  Result<RenderPlan> planRender(const MethodDesc& method, const GlRenderOptions& options) const;
  // every storage buffer must fit one shader storage block (GL clamps the accessible range)
  Error tooLarge(const MethodDesc& method, const std::string& what, uint64_t bytes) const;
  struct FrameRun;

  // exclusive prefix sum of `count` uints of `in` into `out`
  void scan(FrameBuffers& fb, GLuint in, GLuint out, uint32_t count) const {
    constexpr uint32_t perBlock = kScanGroupSize * kScanItemsPerThread;
    const uint32_t blocks = (count + perBlock - 1) / perBlock;
    const GLuint sums = fb.make("prefix sum block sums", uint64_t{blocks} * 4);
    glUseProgram(progScan);
    glProgramUniform1ui(progScan, loc(progScan, "uCount"), count);
    glProgramUniform1ui(progScan, loc(progScan, "uBlocks"), blocks);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanIn, in);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanOut, out);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanSums, sums);
    dispatchGroups(blocks);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    if (blocks <= 1) return;
    const GLuint scanned = fb.make("prefix sum block sums", uint64_t{blocks} * 4);
    scan(fb, sums, scanned, blocks);
    glUseProgram(progScanAdd);
    glProgramUniform1ui(progScanAdd, loc(progScanAdd, "uCount"), count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanOut, out);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanSums, scanned);
    dispatchGroups((count + kScanGroupSize - 1) / kScanGroupSize);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }

  // k(p) by alloc_k.comp (the uniforms set by the caller; `totals` cleared), then the prefix sum
  // and the packed per-pixel words; the totals read back
  Result<GlAllocationTotals> allocateK(FrameBuffers& fb, GLuint totals, GLuint importance,
                                       GLuint total, StoreChoice store,
                                       std::vector<GlPassTime>* passes) {
    const uint32_t pixels = static_cast<uint32_t>(static_cast<uint64_t>(width) * height);
    const uint64_t groups = (uint64_t{pixels} + kResolveGroupSize - 1) / kResolveGroupSize;
    deviceCapacity = device->make("k(p)", uint64_t{pixels} * 4);
    deviceReserved = device->make("k(p) allocated", uint64_t{pixels} * 4);
    if (device->failure) return *device->failure;
    if (fb.failure) return *fb.failure;
    timedPass(passes, "k(p)", [&] {
      glUseProgram(progAllocK);
      glProgramUniform1ui(progAllocK, loc(progAllocK, "uPixels"), pixels);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocCounts, deviceCounts);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocSummary, totals);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocK, deviceCapacity);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocReserved, deviceReserved);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportance, importance);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportanceTotal, total);
      dispatchGroups(groups);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    });
    uint32_t words[kAllocTotalWords] = {};
    glGetNamedBufferSubData(totals, 0, sizeof words, words);
    deviceSlots = (uint64_t{words[1]} << 32) | words[0];
    deviceReservedSlots = (uint64_t{words[3]} << 32) | words[2];
    const GLuint offsets = fb.make("allocation offsets", uint64_t{pixels} * 4);
    timedPass(passes, "prefix sum", [&] { scan(fb, deviceCapacity, offsets, pixels); });
    uint32_t storeMode = 0;
    switch (store) {
      case StoreChoice::MaxHeap:
        storeMode = 1;
        break;
      case StoreChoice::PerPixel:
        storeMode = 2;
        break;
      case StoreChoice::Append:
      case StoreChoice::MaxArray:
      case StoreChoice::MultiLayer:
      case StoreChoice::None:
        storeMode = 0;
        break;
    }
    deviceWords = device->make("allocation", uint64_t{pixels} * 8);
    if (device->failure) return *device->failure;
    if (fb.failure) return *fb.failure;
    timedPass(passes, "allocation words", [&] {
      glUseProgram(progAllocPack);
      glProgramUniform1ui(progAllocPack, loc(progAllocPack, "uPixels"), pixels);
      glProgramUniform1ui(progAllocPack, loc(progAllocPack, "uStore"), storeMode);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocCounts, deviceCounts);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocK, deviceCapacity);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocOffsets, offsets);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocWords, deviceWords);
      dispatchGroups(groups);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                      GL_BUFFER_UPDATE_BARRIER_BIT);
    });
    if (const GLenum e = glGetError(); e != GL_NO_ERROR)
      return makeError("--engine gl: the variable-k allocation failed (GL error " + glErrorText(e) +
                       ")");
    return GlAllocationTotals{deviceSlots, deviceReservedSlots};
  }
};

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

// the capture_kbuffer.frag prelude: with --gl-sync interlock, the driver's interlock extension
// and its begin / end macros; empty without
Result<std::string> kbufferInterlockPrelude(const GlContext& context, bool interlock) {
  if (!interlock) return std::string();
  const std::string ext = interlockExtension(context);
  if (ext.empty())
    return makeError(
        "--gl-sync interlock: the driver offers none of GL_ARB_fragment_shader_interlock, "
        "GL_NV_fragment_shader_interlock, GL_INTEL_fragment_shader_ordering");
  return interlockPrelude(ext);
}

}  // namespace

Result<GlEngine> GlEngine::create(const GlContext& context, const Scene& scene,
                                  const Camera& cameraIn, int width, int height, bool interlock,
                                  GlRaster raster) {
  MFR_TRY(checkCreateArgs(scene, cameraIn, width, height));
  context.makeCurrent();
  MFR_TRY(checkGlLimits(width, height));

  auto s = std::make_unique<State>();
  GLint64 maxBlock = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
  s->maxBlockBytes = static_cast<uint64_t>(maxBlock);
  s->width = width;
  s->height = height;
  s->placeCamera(cameraIn, scene);
  s->raster = raster;
  auto kbufferPrelude = kbufferInterlockPrelude(context, interlock);
  if (!kbufferPrelude) return kbufferPrelude.error();
  MFR_TRY(s->linkPrograms(context, *kbufferPrelude));
  s->uploadGeometry(scene);
  MFR_TRY(s->uploadMaterials(scene));
  s->uploadColorTables();
  s->createFramebufferAndQuery();
  if (s->uploadFailure) return *s->uploadFailure;
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: scene upload failed (GL error 0x" + [&] {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%x", e);
      return std::string(buf);
    }() + ")");
  return GlEngine(std::move(s));
}

// One run of render(): the frame's buffers (freed with it), the passes in order and the read-back.
struct GlEngine::State::FrameRun {
  State& s;
  const RenderPlan& plan;
  GlRenderOutput& out;
  FrameBuffers fb;
  GLuint counts = 0, offsets = 0, nodes = 0, tails = 0, accum = 0, image = 0;
  uint64_t nodeCount = 0;
  bool countInCapture = false;  // the capture adds n(p) (no count pass ran)

  // a capture program: whether it counts n(p), and the counts' image unit
  void useCapture(GLuint program) {
    glUseProgram(program);
    glProgramUniform1ui(program, loc(program, "uCountInCapture"), countInCapture ? 1u : 0u);
    fb.bindImage(counts, kBindCounts);
  }

  FrameRun(State& state, const RenderPlan& p, GlRenderOutput& output)
      : s(state), plan(p), out(output) {
    fb.ledger = &out.bufferBytes;
  }

  // one timed pass: GL's elapsed time and the wall time around it
  template <class Body>
  void pass(const char* name, Body&& body) {
    if (fb.failure) return;  // a buffer GL could not allocate: reported below
    const auto t0 = std::chrono::steady_clock::now();
    glBeginQuery(GL_TIME_ELAPSED, s.query);
    body();
    glEndQuery(GL_TIME_ELAPSED);
    glFinish();
    const auto t1 = std::chrono::steady_clock::now();
    GLuint64 ns = 0;
    glGetQueryObjectui64v(s.query, GL_QUERY_RESULT, &ns);
    out.passes.push_back({name, static_cast<double>(ns) * 1e-6,
                          std::chrono::duration<double, std::milli>(t1 - t0).count()});
  }

  // the per-pixel allocation: (first slot, k(p) | heap bit), a texel buffer
  void bindAllocation() {
    const Allocation* alloc = plan.alloc;
    const uint32_t pixels = plan.pixels;
    const bool device = plan.device;
    const bool perPixel = plan.perPixel;
    if (device) {
      out.bufferBytes["allocation"] += uint64_t{pixels} * 8;
      GLuint t = 0;
      glCreateTextures(GL_TEXTURE_BUFFER, 1, &t);
      glTextureBuffer(t, GL_RG32UI, s.deviceWords);
      fb.textures.push_back(t);
      glBindTextureUnit(kBindAllocation, t);
    } else if (perPixel) {
      std::vector<uint32_t> words(uint64_t{pixels} * 2);
      for (uint32_t p = 0; p < pixels; ++p) {
        words[2 * p] = static_cast<uint32_t>(alloc->offsets[p]);
        words[2 * p + 1] =
            alloc->capacity[p] | (alloc->kind[p] == StoreKind::MaxHeap ? kAllocHeapBit : 0u);
      }
      const GLuint a = fb.make("allocation", uint64_t{pixels} * 8, words.data());
      GLuint t = 0;
      glCreateTextures(GL_TEXTURE_BUFFER, 1, &t);
      glTextureBuffer(t, GL_RG32UI, a);
      fb.textures.push_back(t);
      glBindTextureUnit(kBindAllocation, t);
    }
  }

  // n(p): the counts given, those on the device, a count pass (the A-buffer needs n(p) before
  // its capture), or counted by the capture itself (countInCapture: no pass of its own)
  void countFragments() {
    const GlRenderOptions& options = plan.options;
    const uint32_t pixels = plan.pixels;
    const bool device = plan.device;
    const bool counted = device || (options.counts && options.counts->size() == pixels);
    counts = fb.make("counts", uint64_t{pixels} * 4,
                     counted && !device ? options.counts->data() : nullptr);
    if (device)  // n(p) of countOnDevice, copied on the GPU
      glCopyNamedBufferSubData(s.deviceCounts, counts, 0, 0, uint64_t{pixels} * 4);
    countInCapture = !counted && !plan.isABuffer;
    if (countInCapture) clearUint(counts, 0);
    if (!counted && plan.isABuffer) {
      clearUint(counts, 0);
      pass("count", [&] {
        glUseProgram(s.progCount);
        fb.bindImage(counts, kBindCounts);
        s.drawScene();
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                        GL_BUFFER_UPDATE_BARRIER_BIT);
      });
    }
  }

  // wboit, mboit: the per-pixel accumulators (mboit: its moments first)
  void captureAccumulators() {
    const uint32_t pixels = plan.pixels;
    const bool isWboit = plan.isWboit;
    const uint32_t accumWords = plan.accumWords;
    accum = fb.make("accumulators", uint64_t{pixels} * accumWords * 4);
    {  // wboit: revealage 1, the rest 0
      std::vector<float> init(uint64_t{pixels} * accumWords, 0.0f);
      if (isWboit)
        for (uint32_t p = 0; p < pixels; ++p) init[uint64_t{p} * accumWords + 4] = 1.0f;
      glNamedBufferSubData(accum, 0, static_cast<GLsizeiptr>(init.size() * 4), init.data());
    }
    const GLuint locks = fb.make("locks", uint64_t{pixels} * 4);
    clearUint(locks, kLockFree);
    auto accumulate = [&](GLuint program, bool capture) {
      if (capture) {
        useCapture(program);
      } else {
        glUseProgram(program);
      }
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    };
    if (!isWboit) pass("moments", [&] { accumulate(s.progMboitMoments, false); });
    pass("capture", [&] { accumulate(isWboit ? s.progWboit : s.progMboitColor, true); });
  }

  // mlab: k nodes per pixel merged in place, their count per pixel
  void captureMlab() {
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    nodes = fb.make("nodes", uint64_t{pixels} * k * kMlabWords * 4);
    accum = fb.make("counters", uint64_t{pixels} * 4);  // nodes in use per pixel
    clearUint(accum, 0);
    const GLuint locks = fb.make("locks", uint64_t{pixels} * 4);
    clearUint(locks, kLockFree);
    pass("capture", [&] {
      const GLuint p = s.progMlab;
      useCapture(p);
      glProgramUniform1ui(p, loc(p, "uK"), k);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindFill, accum);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    });
  }

  // the A-buffer: the prefix sum of n(p), then every fragment into its slot
  Result<void> captureABuffer() {
    const MethodDesc& method = plan.method;
    const uint32_t pixels = plan.pixels;
    offsets = fb.make("offsets", uint64_t{pixels} * 4);
    pass("prefix sum", [&] { s.scan(fb, counts, offsets, pixels); });
    // the total in 64 bits from n(p) itself (the 32-bit scan would wrap silently)
    std::vector<uint32_t> n(pixels);
    glGetNamedBufferSubData(counts, 0, uint64_t{pixels} * 4ll, n.data());
    nodeCount = 0;
    for (uint32_t c : n) nodeCount += c;
    if (nodeCount * kNodeBytes > s.maxBlockBytes)  // (also keeps the uint offsets exact)
      return s.tooLarge(method, "A-buffer node", nodeCount * kNodeBytes);
    nodes = fb.make("nodes", nodeCount * kNodeBytes);
    const GLuint fill = fb.make("fill counters", uint64_t{pixels} * 4);
    clearUint(fill, 0);
    pass("capture", [&] {
      glUseProgram(s.progABuffer);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOffsets, offsets);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindFill, fill);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    });
    return {};
  }

  // occupancy culling: depth range, bitmap fill, k-th occupied bucket; the range buffer
  GLuint occupancyCulling(uint32_t words) {
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    const bool perPixel = plan.perPixel;
    const GLuint range = fb.make("occupancy", uint64_t{pixels} * kOccupancyWords * 4);
    static_assert(kOccupancyWords == 3);
    const uint32_t init[3] = {kFarDepthBits, 0u, kOccupancyNoCulling};
    glClearNamedBufferData(range, GL_RGB32UI, GL_RGB_INTEGER, GL_UNSIGNED_INT, init);
    const GLuint bitmap = fb.make("occupancy", uint64_t{pixels} * words * 4);
    clearUint(bitmap, 0);
    pass("depth range", [&] {
      glUseProgram(s.progDepthRange);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccupancy, range);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    });
    pass("occupancy fill", [&] {
      glUseProgram(s.progOccFill);
      glProgramUniform1ui(s.progOccFill, loc(s.progOccFill, "uWords"), words);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccupancy, range);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccBits, bitmap);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    });
    pass("occupancy count", [&] {
      const GLuint p = s.progOccCount;
      glUseProgram(p);
      glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
      glProgramUniform1ui(p, loc(p, "uWords"), words);
      glProgramUniform1ui(p, loc(p, "uK"), k);
      glProgramUniform1ui(p, loc(p, "uPerPixel"), perPixel ? 1u : 0u);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccBits, bitmap);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccupancy, range);
      dispatchGroups((pixels + kResolveGroupSize - 1) / kResolveGroupSize);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    });
    return range;
  }

  // the k-buffer family: fixed or per-pixel k, max-array or max-heap, optional tail and occupancy
  void captureKBuffer() {
    const MethodDesc& method = plan.method;
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    const bool perPixel = plan.perPixel;
    const bool hybrid = plan.hybrid;
    const uint64_t allocSlots = plan.allocSlots;
    nodeCount = perPixel ? allocSlots : uint64_t{pixels} * k;
    const uint32_t words = static_cast<uint32_t>(method.occupancyWords);
    const GLuint stats = fb.make("capture counters", 8);
    clearUint(stats, 0);
    if (hybrid) {
      tails = fb.make("tails", uint64_t{pixels} * kTailWords * 4);
      clearUint(tails, 0);
    } else {
      tails = stats;  // not read
    }
    GLuint range = stats;
    if (words > 0) range = occupancyCulling(words);
    // a fixed k without tail or occupancy takes 64-bit atomicMin where the driver has them
    const bool atomic = s.progKBufferAtomic64 != 0 && !perPixel && !hybrid && words == 0;
    out.atomic64 = atomic;
    nodes = fb.make("nodes", nodeCount * kNodeBytes);
    // the far node; as uint64 words (colour, depth) for the atomic capture
    const uint32_t far[2] = {atomic ? 0u : kFarDepthBits, atomic ? kFarDepthBits : 0u};
    glClearNamedBufferData(nodes, GL_RG32UI, GL_RG_INTEGER, GL_UNSIGNED_INT, far);
    // (the lock words stay allocated and charged with the atomics: bytes_used does not depend
    // on the capture's synchronisation)
    const GLuint locks = fb.make("locks", uint64_t{pixels} * 4);
    clearUint(locks, kLockFree);
    const GLuint p = atomic ? s.progKBufferAtomic64 : s.progKBuffer;
    glProgramUniform1ui(p, loc(p, "uK"), k);
    glProgramUniform1ui(p, loc(p, "uStore"),
                        method.store == StoreChoice::MaxHeap ? kStoreMaxHeap : kStoreMaxArray);
    glProgramUniform1ui(p, loc(p, "uOccupancyWords"), words);
    glProgramUniform1ui(p, loc(p, "uPerPixel"), perPixel ? 1u : 0u);
    glProgramUniform1ui(p, loc(p, "uHybrid"), hybrid ? 1u : 0u);
    pass("capture", [&] {
      useCapture(p);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccupancy, range);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindTails, tails);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindCaptureStats, stats);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    });
    if (atomic)
      pass("node words", [&] {
        const GLuint q = s.progSwapWords;
        glUseProgram(q);
        glProgramUniform1ui(q, loc(q, "uCount"), static_cast<GLuint>(nodeCount));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
        dispatchGroups((nodeCount + kResolveGroupSize - 1) / kResolveGroupSize);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
      });
    uint32_t culled[2] = {0, 0};
    glGetNamedBufferSubData(stats, 0, 8, culled);
    out.culledOccupancy = culled[0];
    out.culledKPlus = culled[1];
  }

  // the image: each kind's resolve pass
  void resolve() {
    const GlRenderOptions& options = plan.options;
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    const bool perPixel = plan.perPixel;
    const bool hybrid = plan.hybrid;
    const bool isWboit = plan.isWboit;
    const bool isMlab = plan.isMlab;
    const bool accumulates = plan.accumulates;
    image = fb.make("image", uint64_t{pixels} * 12);
    if (isMlab) {
      pass("resolve", [&] {
        const GLuint p = s.progMlabResolve;
        glUseProgram(p);
        glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
        glProgramUniform1ui(p, loc(p, "uK"), k);
        glProgramUniform3f(p, loc(p, "uBackground"), options.background.r, options.background.g,
                           options.background.b);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindFill, accum);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage2, image);
        dispatchGroups((pixels + kResolveGroupSize - 1) / kResolveGroupSize);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
      });
    } else if (accumulates) {
      pass("resolve", [&] {
        const GLuint p = isWboit ? s.progWboitResolve : s.progMboitResolve;
        glUseProgram(p);
        glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
        glProgramUniform3f(p, loc(p, "uBackground"), options.background.r, options.background.g,
                           options.background.b);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage, image);
        dispatchGroups((pixels + kResolveGroupSize - 1) / kResolveGroupSize);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
      });
    } else {
      pass("resolve", [&] {
        const GLuint p = s.progResolve;
        glUseProgram(p);
        glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
        glProgramUniform1ui(p, loc(p, "uK"), k);
        glProgramUniform1ui(p, loc(p, "uHybrid"), hybrid ? 1u : 0u);
        glProgramUniform1ui(p, loc(p, "uPerPixel"), perPixel ? 1u : 0u);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindResolveTails, tails ? tails : counts);
        glProgramUniform3f(p, loc(p, "uBackground"), options.background.r, options.background.g,
                           options.background.b);
        glProgramUniform1f(p, loc(p, "uInv255"), 1.0f / 255.0f);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindCounts, counts);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOffsets, offsets ? offsets : counts);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage, image);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, s.colorTables);
        dispatchGroups((pixels + kResolveGroupSize - 1) / kResolveGroupSize);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
      });
    }
  }

  // a GL error or a buffer GL could not allocate
  Result<void> checkErrors() {
    const MethodDesc& method = plan.method;
    if (const GLenum e = glGetError(); e != GL_NO_ERROR) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%x", e);
      if (fb.failure) return *fb.failure;
      return makeError("--engine gl: " + method.name + " failed (GL error 0x" + buf + ")");
    }
    if (fb.failure) return *fb.failure;
    return {};
  }

  // n(p), the image and, with readNodes, the nodes with their per-pixel ranges
  void readBack() {
    const GlRenderOptions& options = plan.options;
    const uint32_t pixels = plan.pixels;
    const bool isMlab = plan.isMlab;
    out.counts.resize(pixels);
    glGetNamedBufferSubData(counts, 0, uint64_t{pixels} * 4ll, out.counts.data());
    for (uint32_t n : out.counts) out.fragments += n;
    out.image = ImageRGB(s.width, s.height);
    glGetNamedBufferSubData(image, 0, uint64_t{pixels} * 12ll, out.image.pixels.data());
    if (options.readNodes && !isMlab) readNodes();  // (mlab's nodes are not fragment nodes)
  }

  // the nodes, and each pixel's first node and count
  void readNodes() {
    const Allocation* alloc = plan.alloc;
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    const bool device = plan.device;
    const bool isABuffer = plan.isABuffer;
    std::vector<uint32_t> words(nodeCount * 2);
    if (nodeCount > 0)
      glGetNamedBufferSubData(nodes, 0, static_cast<GLsizeiptr>(nodeCount * kNodeBytes),
                              words.data());
    out.nodes.resize(nodeCount);
    for (uint64_t i = 0; i < nodeCount; ++i)
      out.nodes[i] = (static_cast<uint64_t>(words[2 * i + kNodeHiIndex]) << 32) |
                     words[2 * i + 1 - kNodeHiIndex];
    out.nodeOffsets.resize(pixels);
    out.nodeCounts.resize(pixels);
    if (isABuffer) {
      std::vector<uint32_t> off(pixels);
      glGetNamedBufferSubData(offsets, 0, uint64_t{pixels} * 4ll, off.data());
      for (uint32_t p = 0; p < pixels; ++p) {
        out.nodeOffsets[p] = off[p];
        out.nodeCounts[p] = out.counts[p];
      }
    } else {
      std::vector<uint32_t> words;
      if (device) {
        words.resize(uint64_t{pixels} * 2);
        glGetNamedBufferSubData(s.deviceWords, 0, uint64_t{pixels} * 8ll, words.data());
      }
      for (uint32_t p = 0; p < pixels; ++p) {
        const uint64_t first = device ? words[2 * p] : alloc ? alloc->offsets[p] : uint64_t{p} * k;
        const uint32_t capacity = device  ? words[2 * p + 1] & ~kAllocHeapBit
                                  : alloc ? alloc->capacity[p]
                                          : k;
        out.nodeOffsets[p] = first;
        out.nodeCounts[p] = std::min(out.counts[p], capacity);
      }
    }
  }
};

Result<RenderPlan> GlEngine::State::planRender(const MethodDesc& method,
                                               const GlRenderOptions& options) const {
  const State& s = *this;
  const bool isABuffer =
      method.allocation == AllocationPolicy::Unbounded && method.store == StoreChoice::Append;
  const Allocation* alloc = options.allocation;
  const uint32_t pixels = static_cast<uint32_t>(static_cast<uint64_t>(s.width) * s.height);
  // the allocation the compute shaders left in the engine's buffers (allocateCapped,
  // allocateByImportance), else the host's
  const bool device = options.deviceAllocation;
  if (device && !s.device)
    return makeError("--engine gl: " + method.name + ": no allocation on the device");
  const bool perPixel = alloc != nullptr || device;
  const uint64_t allocSlots = device ? s.deviceSlots : alloc ? alloc->slots : 0;
  if (alloc && (alloc->capacity.size() != pixels || alloc->offsets.size() != pixels ||
                alloc->kind.size() != pixels))
    return makeError("--engine gl: " + method.name + ": an allocation of another size");
  const bool isKBuffer =
      (perPixel && method.allocation != AllocationPolicy::Unbounded &&
       method.allocation != AllocationPolicy::NoNodes &&
       (method.store == StoreChoice::MaxArray || method.store == StoreChoice::MaxHeap ||
        method.store == StoreChoice::PerPixel)) ||
      (!perPixel && method.allocation == AllocationPolicy::FixedK &&
       (method.store == StoreChoice::MaxArray || method.store == StoreChoice::MaxHeap) &&
       method.k && *method.k > 0);
  const bool hybrid = isKBuffer && method.compositing == Compositing::Hybrid;
  const bool accumulates = (method.compositing == Compositing::WeightedBlended ||
                            method.compositing == Compositing::MomentBased) &&
                           method.allocation == AllocationPolicy::NoNodes &&
                           method.store == StoreChoice::None && method.occupancyWords == 0;
  const bool isWboit = accumulates && method.compositing == Compositing::WeightedBlended;
  const uint32_t accumWords = !accumulates ? 0u : isWboit ? kWboitWords : kMboitWords;
  const bool isMlab = !perPixel && method.allocation == AllocationPolicy::FixedK &&
                      method.store == StoreChoice::MultiLayer &&
                      method.compositing == Compositing::MultiLayerAlpha && method.k &&
                      *method.k > 0 && method.occupancyWords == 0;
  if (accumulates || isMlab) {
    // weighted blended or moment-based OIT: no nodes, the accumulators; mlab: its own nodes
  } else if ((!isABuffer && !isKBuffer) || (isABuffer && method.occupancyWords != 0) ||
             method.occupancyWords < 0 || method.occupancyWords > 64 ||
             (method.compositing != Compositing::KBuffer && !hybrid))
    return makeError("--engine gl: method " + method.name +
                     " is not in the GL engine yet (abuffer, fixed-k max-array or max-heap "
                     "k-buffers with an explicit k, k-buffers with a per-pixel allocation, "
                     "wboit, mboit, mlab)");
  const uint32_t k = (isKBuffer && !perPixel) || isMlab ? *method.k : 0u;
  const uint64_t perPixelBytes =
      std::max<uint64_t>({accumulates ? accumWords * 4 : 12, hybrid ? kTailWords * 4 : 0,
                          perPixel ? 8 : uint64_t{k} * (isMlab ? kMlabWords * 4 : kNodeBytes),
                          static_cast<uint64_t>(std::max(method.occupancyWords, 0)) * 4});
  if (uint64_t{pixels} * perPixelBytes > s.maxBlockBytes)
    return tooLarge(method, "per-pixel", uint64_t{pixels} * perPixelBytes);
  if (perPixel && allocSlots * kNodeBytes > s.maxBlockBytes)  // (keeps the uint offsets exact)
    return tooLarge(method, "node", allocSlots * kNodeBytes);
  return RenderPlan{method,      options,    alloc,      pixels,    device,
                    perPixel,    allocSlots, isABuffer,  isKBuffer, hybrid,
                    accumulates, isWboit,    accumWords, isMlab,    k};
}

Error GlEngine::State::tooLarge(const MethodDesc& method, const std::string& what,
                                uint64_t bytes) const {
  return makeError("--engine gl: " + method.name + " at " + std::to_string(width) + "x" +
                   std::to_string(height) + ": the " + what + " buffer needs " +
                   std::to_string(bytes) + " B, above GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" +
                   std::to_string(maxBlockBytes) + " B)");
}

Result<GlRenderOutput> GlEngine::render(const MethodDesc& method, const GlRenderOptions& options) {
  State& s = *state_;
  auto plan = s.planRender(method, options);
  if (!plan) return plan.error();
  GlRenderOutput out;
  for (int run = options.warmUp ? 0 : 1; run < 2; ++run) {
    const bool timed = run == 1;
    out.bufferBytes = s.sceneBytes;
    out.passes.clear();
    State::FrameRun frame(s, *plan, out);
    frame.bindAllocation();
    frame.countFragments();
    if (plan->accumulates) {
      frame.captureAccumulators();
    } else if (plan->isMlab) {
      frame.captureMlab();
    } else if (plan->isABuffer) {
      MFR_TRY(frame.captureABuffer());
    } else {
      frame.captureKBuffer();
    }
    frame.resolve();
    MFR_TRY(frame.checkErrors());
    if (timed) frame.readBack();
  }
  return out;
}

Result<std::vector<uint32_t>> GlEngine::count() {
  State& s = *state_;
  const uint64_t pixels = static_cast<uint64_t>(s.width) * s.height;
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb;
  fb.ledger = &ledger;
  const GLuint counts = fb.make("counts", pixels * 4);
  clearUint(counts, 0);
  glUseProgram(s.progCount);
  fb.bindImage(counts, kBindCounts);
  s.drawScene();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  if (fb.failure) return *fb.failure;
  std::vector<uint32_t> n(pixels);
  glGetNamedBufferSubData(counts, 0, static_cast<GLsizeiptr>(pixels * 4), n.data());
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the count pass failed (GL error " + std::to_string(e) + ")");
  return n;
}

Result<std::vector<float>> GlEngine::nearestCosine() {
  State& s = *state_;
  const uint64_t pixels = static_cast<uint64_t>(s.width) * s.height;
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb;
  fb.ledger = &ledger;
  const GLuint nearest = fb.make("nearest", pixels * kNearestWords * 4);
  static_assert(kNearestWords == 3);
  const uint32_t init[3] = {kFarDepthBits, 0u, 0u};
  glClearNamedBufferData(nearest, GL_RGB32UI, GL_RGB_INTEGER, GL_UNSIGNED_INT, init);
  const GLuint locks = fb.make("locks", pixels * 4);
  if (fb.failure) return *fb.failure;
  clearUint(locks, kLockFree);
  glUseProgram(s.progNearest);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNearest, nearest);
  fb.bindImage(locks, kBindLocks);
  s.drawScene();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  std::vector<uint32_t> words(pixels * kNearestWords);
  glGetNamedBufferSubData(nearest, 0, static_cast<GLsizeiptr>(words.size() * 4), words.data());
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the nearest |n.v| pass failed (GL error " + std::to_string(e) +
                     ")");
  std::vector<float> cosine(pixels);
  for (uint64_t p = 0; p < pixels; ++p)
    cosine[p] = static_cast<float>(words[p * kNearestWords + 2]) / 255.0f;
  return cosine;
}

Result<std::vector<float>> GlEngine::dkbImportance(const std::vector<float>& weights,
                                                   uint64_t slots,
                                                   std::vector<GlPassTime>* passes) {
  constexpr size_t kWeights = 128 * 12 + 128 + 64 * 128 + 64 + 64 + 1;
  if (weights.size() != kWeights)
    return makeError("--engine gl: the deep k-buffer's network must be 12-128-64-1 on GL");
  State& s = *state_;
  const uint64_t pixels = static_cast<uint64_t>(s.width) * s.height;
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb;
  fb.ledger = &ledger;
  auto timed = [&](const char* name, auto&& body) {
    const auto t0 = std::chrono::steady_clock::now();
    body();
    glFinish();
    if (passes)
      passes->push_back(
          {name, 0.0,
           std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
               .count()});
  };
  const GLuint acc = fb.make("features", pixels * kDkbAccWords * 4);
  const GLuint locks = fb.make("locks", pixels * 4);
  const GLuint net = fb.make("network", weights.size() * 4, weights.data());
  const GLuint importance = fb.make("importance", pixels * 4);
  if (fb.failure) return *fb.failure;
  std::vector<uint32_t> words(pixels * kDkbAccWords);
  timed("features", [&] {
    static_assert(kDkbAccWords == 7);
    std::vector<uint32_t> init(pixels * kDkbAccWords, 0u);
    for (uint64_t p = 0; p < pixels; ++p) init[p * kDkbAccWords + 1] = kFarDepthBits;
    glNamedBufferSubData(acc, 0, static_cast<GLsizeiptr>(init.size() * 4), init.data());
    clearUint(locks, kLockFree);
    glUseProgram(s.progDkbFeatures);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDkbAcc, acc);
    fb.bindImage(locks, kBindLocks);
    s.drawScene();
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    glGetNamedBufferSubData(acc, 0, static_cast<GLsizeiptr>(words.size() * 4), words.data());
  });
  std::vector<float> out(pixels, 0.0f);
  timed("inference", [&] {
    // the image's statistics (mfr::ImageFeatureStats) on the host: four numbers
    uint64_t fragments = 0, covered = 0;
    float nearest = 1.0f, farthest = 0.0f;
    for (uint64_t p = 0; p < pixels; ++p) {
      const uint32_t* a = &words[p * kDkbAccWords];
      if (a[0] == 0) continue;
      fragments += a[0];
      ++covered;
      nearest = std::min(nearest, std::bit_cast<float>(a[1]));
      farthest = std::max(farthest, std::bit_cast<float>(a[3]));
    }
    if (fragments == 0) return;
    const GLuint p = s.progDkbInfer;
    glUseProgram(p);
    glProgramUniform1ui(p, loc(p, "uPixels"), static_cast<GLuint>(pixels));
    glProgramUniform1d(p, loc(p, "uMeanN"), static_cast<double>(fragments) / covered);
    glProgramUniform1f(p, loc(p, "uNearest"), nearest);
    glProgramUniform1f(p, loc(p, "uFarthest"), farthest);
    glProgramUniform1f(p, loc(p, "uSlotShare"),
                       static_cast<float>(std::min(1.0, static_cast<double>(slots) / fragments)));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDkbAcc, acc);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDkbWeights, net);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDkbImportance, importance);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, s.colorTables);
    dispatchGroups((pixels + kResolveGroupSize - 1) / kResolveGroupSize);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(importance, 0, static_cast<GLsizeiptr>(pixels * 4), out.data());
  });
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the deep k-buffer's importance failed (GL error " +
                     std::to_string(e) + ")");
  return out;
}

Result<CountSummary> GlEngine::countOnDevice(std::vector<GlPassTime>* passes) {
  State& s = *state_;
  const uint32_t pixels = static_cast<uint32_t>(static_cast<uint64_t>(s.width) * s.height);
  s.device = std::make_unique<FrameBuffers>();
  s.deviceLedger.clear();
  s.device->ledger = &s.deviceLedger;
  s.deviceCapacity = s.deviceReserved = s.deviceWords = s.deviceImportance = s.deviceNearest = 0;
  s.deviceSlots = s.deviceReservedSlots = 0;
  s.deviceByImportance = false;
  s.deviceCounts = s.device->make("counts", uint64_t{pixels} * 4);
  if (s.device->failure) return *s.device->failure;
  clearUint(s.deviceCounts, 0);
  timedPass(passes, "count", [&] {
    glUseProgram(s.progCount);
    s.device->bindImage(s.deviceCounts, kBindCounts);
    s.drawScene();
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  });
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb;
  fb.ledger = &ledger;
  const GLuint summary = fb.make("histogram", kAllocSummaryWords * 4);
  if (fb.failure) return *fb.failure;
  clearUint(summary, 0);
  std::vector<uint32_t> words(kAllocSummaryWords);
  timedPass(passes, "histogram", [&] {
    glUseProgram(s.progAllocHistogram);
    glProgramUniform1ui(s.progAllocHistogram, loc(s.progAllocHistogram, "uPixels"), pixels);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocCounts, s.deviceCounts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocSummary, summary);
    dispatchGroups((uint64_t{pixels} + kResolveGroupSize - 1) / kResolveGroupSize);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(summary, 0, kAllocSummaryWords * 4, words.data());
  });
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the count pass failed (GL error " + glErrorText(e) + ")");
  CountSummary out;
  out.histogram.assign(words.begin(), words.begin() + kAllocHistogramBins);
  out.maxN = words[kAllocHistogramBins];
  out.covered = pixels - out.histogram[0];
  return out;
}

Result<GlAllocationTotals> GlEngine::allocateCapped(uint32_t k, StoreChoice store,
                                                    std::vector<GlPassTime>* passes) {
  State& s = *state_;
  if (!s.device) return makeError("--engine gl: allocateCapped before countOnDevice");
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb;
  fb.ledger = &ledger;
  const GLuint totals = fb.make("allocation totals", kAllocTotalWords * 4);
  clearUint(totals, 0);
  glProgramUniform1ui(s.progAllocK, loc(s.progAllocK, "uMode"), kAllocCapped);
  glProgramUniform1ui(s.progAllocK, loc(s.progAllocK, "uK"), k);
  s.deviceByImportance = false;
  return s.allocateK(fb, totals, totals, totals, store, passes);  // (no importance: unread)
}

Result<GlAllocationTotals> GlEngine::allocateByImportance(const ImportanceParams& params,
                                                          const std::vector<float>& previousCosine,
                                                          uint64_t slots, StoreChoice store,
                                                          std::vector<GlPassTime>* passes) {
  State& s = *state_;
  if (!s.device) return makeError("--engine gl: allocateByImportance before countOnDevice");
  const uint32_t pixels = static_cast<uint32_t>(static_cast<uint64_t>(s.width) * s.height);
  const uint64_t groups = (uint64_t{pixels} + kResolveGroupSize - 1) / kResolveGroupSize;
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb;
  fb.ledger = &ledger;
  // this frame's nearest |n.v| (the output's, and the Fresnel term's unless a previous frame's
  // is given)
  static_assert(kNearestWords == 3);
  s.deviceNearest = s.device->make("nearest", uint64_t{pixels} * kNearestWords * 4);
  const uint32_t init[3] = {kFarDepthBits, 0u, 0u};
  glClearNamedBufferData(s.deviceNearest, GL_RGB32UI, GL_RGB_INTEGER, GL_UNSIGNED_INT, init);
  const GLuint locks = fb.make("locks", uint64_t{pixels} * 4);
  if (s.device->failure) return *s.device->failure;
  if (fb.failure) return *fb.failure;
  clearUint(locks, kLockFree);
  timedPass(passes, "nearest_normal", [&] {
    glUseProgram(s.progNearest);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNearest, s.deviceNearest);
    fb.bindImage(locks, kBindLocks);
    s.drawScene();
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  });
  const bool previous = previousCosine.size() == pixels;
  const GLuint cosine = previous
                            ? fb.make("previous |n.v|", uint64_t{pixels} * 4, previousCosine.data())
                            : s.deviceNearest;
  s.deviceImportance = s.device->make("importance", uint64_t{pixels} * kImportanceWords * 4);
  const GLuint p = s.progImportance;
  const float width = static_cast<float>(s.width), height = static_cast<float>(s.height);
  // the host's constants of mfr::computeImportance, rounded as there
  const glm::vec2 fovea = params.fovea.value_or(glm::vec2(s.width * 0.5f, s.height * 0.5f));
  const float diagonal = 1.1f * std::sqrt(width * width + height * height);
  const float d = params.peripheryExponent;
  const int dInt = d >= 0.0f && d <= 64.0f && std::floor(d) == d ? static_cast<int>(d) : -1;
  const uint64_t seedMix = params.seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
  glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
  glProgramUniform1ui(p, loc(p, "uWidth"), static_cast<GLuint>(s.width));
  glProgramUniform1f(p, loc(p, "uAlpha"), params.alpha);
  glProgramUniform1f(p, loc(p, "uOneMinusAlpha"), 1.0f - params.alpha);
  glProgramUniform1f(p, loc(p, "uNLimit"), params.nLimit);
  glProgramUniform2f(p, loc(p, "uFovea"), fovea.x, fovea.y);
  glProgramUniform1f(p, loc(p, "uDiagonal"), diagonal);
  glProgramUniform1f(p, loc(p, "uExponent"), d);
  glProgramUniform1i(p, loc(p, "uExponentInt"), dInt);
  glProgramUniform1f(p, loc(p, "uNoise"), params.noise);
  glProgramUniform2ui(p, loc(p, "uSeedMix"), static_cast<GLuint>(seedMix),
                      static_cast<GLuint>(seedMix >> 32));
  glProgramUniform1ui(p, loc(p, "uUse"),
                      (params.useDepth ? 1u : 0u) | (params.usePeriphery ? 2u : 0u) |
                          (params.useFresnel ? 4u : 0u) | (params.useNoise ? 8u : 0u));
  glProgramUniform1ui(p, loc(p, "uCosine"), previous ? kCosineFloats : kCosineNearest);
  timedPass(passes, "importance", [&] {
    glUseProgram(p);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocCounts, s.deviceCounts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportance, s.deviceImportance);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindCosine, cosine);
    dispatchGroups(groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  });
  const GLuint total = fb.make("importance total", 8);
  if (s.device->failure) return *s.device->failure;
  if (fb.failure) return *fb.failure;
  timedPass(passes, "importance total", [&] {
    const GLuint q = s.progImportanceTotal;
    glUseProgram(q);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportance, s.deviceImportance);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportanceTotal, total);
    // in order, kTotalChunk pixels per dispatch (the running sum stays in `total`)
    for (uint32_t first = 0; first < pixels; first += std::min(kTotalChunk, pixels - first)) {
      glProgramUniform1ui(q, loc(q, "uFirst"), first);
      glProgramUniform1ui(q, loc(q, "uEnd"), first + std::min(kTotalChunk, pixels - first));
      glDispatchCompute(1, 1, 1);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
  });
  const GLuint totals = fb.make("allocation totals", kAllocTotalWords * 4);
  clearUint(totals, 0);
  glProgramUniform1ui(s.progAllocK, loc(s.progAllocK, "uMode"), kAllocByImportance);
  glProgramUniform1d(s.progAllocK, loc(s.progAllocK, "uSlots"), static_cast<double>(slots));
  s.deviceByImportance = true;
  return s.allocateK(fb, totals, s.deviceImportance, total, store, passes);
}

Result<Allocation> GlEngine::readDeviceAllocation() {
  State& s = *state_;
  if (!s.device || !s.deviceWords) return makeError("--engine gl: no allocation on the device");
  const uint64_t pixels = static_cast<uint64_t>(s.width) * s.height;
  std::vector<uint32_t> words(pixels * 2);
  glGetNamedBufferSubData(s.deviceWords, 0, static_cast<GLsizeiptr>(pixels * 8), words.data());
  Allocation a;
  a.capacity.resize(pixels);
  a.offsets.resize(pixels);
  a.kind.resize(pixels);
  for (uint64_t p = 0; p < pixels; ++p) {
    a.offsets[p] = words[2 * p];
    a.capacity[p] = words[2 * p + 1] & ~kAllocHeapBit;
    a.kind[p] = (words[2 * p + 1] & kAllocHeapBit) ? StoreKind::MaxHeap : StoreKind::MaxArray;
  }
  a.slots = s.deviceSlots;
  a.reservedSlots = s.deviceByImportance ? s.deviceReservedSlots : s.deviceSlots;
  if (s.deviceByImportance) {
    a.reservedK.resize(pixels);
    glGetNamedBufferSubData(s.deviceReserved, 0, static_cast<GLsizeiptr>(pixels * 4),
                            a.reservedK.data());
  }
  return a;
}

Result<ImportanceMaps> GlEngine::readImportance() {
  State& s = *state_;
  if (!s.device || !s.deviceImportance)
    return makeError("--engine gl: no importance map on the device");
  const uint64_t pixels = static_cast<uint64_t>(s.width) * s.height;
  std::vector<float> words(pixels * kImportanceWords);
  glGetNamedBufferSubData(s.deviceImportance, 0, static_cast<GLsizeiptr>(words.size() * 4),
                          words.data());
  ImportanceMaps m;
  for (std::vector<float>* v : {&m.importance, &m.depth, &m.periphery, &m.fresnel, &m.noise})
    v->resize(pixels);
  for (uint64_t p = 0; p < pixels; ++p) {
    const float* w = &words[p * kImportanceWords];
    m.importance[p] = w[0];
    m.depth[p] = w[1];
    m.periphery[p] = w[2];
    m.fresnel[p] = w[3];
    m.noise[p] = w[4];
  }
  return m;
}

Result<std::vector<float>> GlEngine::readNearestCosine() {
  State& s = *state_;
  if (!s.device || !s.deviceNearest) return makeError("--engine gl: no nearest pass on the device");
  const uint64_t pixels = static_cast<uint64_t>(s.width) * s.height;
  std::vector<uint32_t> words(pixels * kNearestWords);
  glGetNamedBufferSubData(s.deviceNearest, 0, static_cast<GLsizeiptr>(words.size() * 4),
                          words.data());
  std::vector<float> cosine(pixels);
  for (uint64_t p = 0; p < pixels; ++p)
    cosine[p] = static_cast<float>(words[p * kNearestWords + 2]) / 255.0f;
  return cosine;
}

bool hasAtomic64(const GlContext& context) {
  return context.extensions().arbGpuShaderInt64 && context.extensions().nvShaderAtomicInt64;
}

std::string interlockExtension(const GlContext& context) {
  const GlExtensions& e = context.extensions();
  if (e.arbFragmentShaderInterlock) return "GL_ARB_fragment_shader_interlock";
  if (e.nvFragmentShaderInterlock) return "GL_NV_fragment_shader_interlock";
  if (e.intelFragmentShaderOrdering) return "GL_INTEL_fragment_shader_ordering";
  return {};
}

std::vector<ShaderVariant> shaderVariants() {
  std::vector<ShaderVariant> out;
  const auto add = [&](const std::string& program, const std::string& file, const char* stage,
                       const char* raster, const std::string& prelude) {
    out.push_back({program, file, stage, composeSource(file, raster, prelude)});
  };
  for (const ProgramRow& row : kPrograms) {
    std::vector<std::pair<std::string, std::string>> preludes;  // variant name, prelude
    switch (row.prelude) {
      case Prelude::None:
        preludes = {{"", ""}};
        break;
      case Prelude::KBufferSync:
        preludes = {{" (lock)", ""}};
        for (const char* ext :
             {"GL_ARB_fragment_shader_interlock", "GL_NV_fragment_shader_interlock",
              "GL_INTEL_fragment_shader_ordering"})
          preludes.push_back({std::string(" (") + ext + ")", interlockPrelude(ext)});
        break;
      case Prelude::Atomic64:
        preludes = {{" (64-bit atomics)", kAtomic64Prelude}};
        break;
    }
    for (const auto& [variant, prelude] : preludes) {
      const std::string program = std::string(row.file) + variant;
      if (!row.raster) {
        add(program, row.file, "comp", nullptr, prelude);
        continue;
      }
      for (const GlRaster raster : {GlRaster::Native, GlRaster::Exact}) {
        const std::string named = program + " [" + toString(raster) + "]";
        for (const StageFile& sf : rasterStages(raster))
          add(named, sf.file, sf.stage == GL_VERTEX_SHADER ? "vert" : "geom", nullptr, "");
        add(named, row.file, "frag", rasterPart(raster), prelude);
      }
    }
  }
  return out;
}

}  // namespace mfr::gl
