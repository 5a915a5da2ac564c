// GlEngine's state (private to src/gl/): the uploaded scene, the camera's matrices, the linked
// programs, and the variable-k allocation the compute shaders left on the device. Its members are
// defined by concern: scene upload and the engine's life in gl_engine.cpp, the frame's passes in
// gl_frame.cpp, the device-side allocation in gl_device_alloc.cpp.
#pragma once

#include <epoxy/gl.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gl/gl_buffers.hpp"
#include "gl/gl_programs.hpp"
#include "mfr/gl/gl_engine.hpp"
#include "mfr/gl/gl_technique.hpp"

namespace mfr::gl {

/// What render() makes of a method and its options: the technique, and for the k-buffer family
/// and mlab the allocation (fixed k or per pixel, from the host or the device).
struct RenderPlan {
  const MethodDesc& method;
  const GlRenderOptions& options;
  GlTechnique technique;
  const Allocation* alloc;  // the host's per-pixel allocation, or none
  uint32_t pixels;
  bool device;    // the allocation the compute shaders left in the engine's buffers
  bool perPixel;  // a per-pixel allocation (host or device)
  uint64_t allocSlots;
  bool hybrid;  // the k-buffer family with the hybrid tail
  uint32_t k;   // the fixed k (0 with a per-pixel allocation)
};

struct GlEngine::State {
  int width = 0, height = 0;  // the storage's (per-sample storage: W * samples x H)
  int rasterWidth = 0;        // the framebuffer's (the image's W)
  GlSampling sampling;
  Camera camera;
  glm::mat4 viewProj{1.0f};
  glm::mat3 viewRot{1.0f};
  glm::vec4 ray{0.0f};
  GLuint vao = 0;
  std::vector<GLuint> sceneBuffers;
  GLuint triMaterial = 0, materials = 0, colorTables = 0, texels = 0;
  GLsizei indexCount = 0;
  GLuint fbo = 0;
  Programs programs;
  BufferPool framePool;  // the last frame's buffers (FrameRun)
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
  bool vertexColors = false;  // the scene has vertex colours (Scene::colors): attribute 3 streams
  bool cullEveryBackFace = false;  // native raster, every material culls back faces: GL_CULL_FACE
  std::map<std::string, uint64_t> sceneBytes;
  std::optional<Error> uploadFailure;  // the first scene buffer GL could not allocate

  State() = default;
  State(const State&) = delete;
  State& operator=(const State&) = delete;
  ~State();

  GLuint program(ProgramId id) const { return programs[id]; }
  uint32_t pixels() const { return static_cast<uint32_t>(static_cast<uint64_t>(width) * height); }

  // --- the scene and camera (gl_engine.cpp) ---
  GLuint upload(const std::string& name, uint64_t bytes, const void* data);
  void setRasterUniforms(GLuint p) const;
  /// draws every triangle with the program in use into the attachment-less framebuffer
  void drawScene() const;
  /// the CPU engine's camera, matrices and view rays (RasterFrame::build)
  void placeCamera(const Camera& cameraIn, const Scene& scene);
  void uploadGeometry(const Scene& scene);
  Result<void> uploadMaterials(const Scene& scene);
  void uploadColorTables();
  void createFramebufferAndQuery();
  /// the count pass: n(p), or with `edges` the fragments that cover part of their pixel
  Result<std::vector<uint32_t>> countPass(bool edges) const;
  /// the framebuffer's samples per pixel and their positions against the standard pattern
  Result<void> checkSamplePattern() const;

  // --- one frame (gl_frame.cpp) ---
  /// the method's technique and allocation, checked against the block size
  Result<RenderPlan> planRender(const MethodDesc& method, const GlRenderOptions& options) const;
  /// every storage buffer must fit one shader storage block (GL clamps the accessible range)
  Error tooLarge(const MethodDesc& method, const std::string& what, uint64_t bytes) const;
  struct FrameRun;

  // --- the device-side allocation (gl_device_alloc.cpp) ---
  /// the nearest fragment's unorm8 |n.v| per pixel into `nearest` (kNearestWords per pixel,
  /// cleared here), under the pixel's spin-lock
  Result<void> nearestPass(FrameBuffers& fb, GLuint nearest, std::vector<GlPassTime>* passes) const;
  /// the |n.v| of a nearest pass's buffer, as floats (unorm8 / 255, mfr::nearestCosine)
  std::vector<float> readCosine(GLuint nearest) const;
  /// exclusive prefix sum of `count` uints of `in` into `out`
  void scan(FrameBuffers& fb, GLuint in, GLuint out, uint32_t count) const;
  /// k(p) by alloc_k.comp (the uniforms set by the caller; `totals` cleared), then the prefix
  /// sum and the packed per-pixel words; the totals read back
  Result<GlAllocationTotals> allocateK(FrameBuffers& fb, GLuint totals, GLuint importance,
                                       GLuint total, StoreChoice store,
                                       std::vector<GlPassTime>* passes);
};

}  // namespace mfr::gl
