// The OpenGL 4.5 engine, first slice: count -> prefix sum -> capture (A-buffer, or the fixed-k
// max-array k-buffer with the k+ test and per-pixel spin-locks) -> resolve, on a GlContext.
//
// Both engines produce the same fragments: the vertex shader transforms with the CPU engine's
// matrices (viewMatrix / projectionMatrix of the camera with fitClipPlanes), the geometry shader
// repeats the CPU engine's clipping and fixed-point set-up, and the fragment shader its integer
// edge functions, barycentrics, alpha test, depth and shading (shaders/). GL's rasterizer decides
// which fragment shaders run (the triangles are drawn at their snapped positions); the fragment
// shader keeps exactly the fragments the CPU engine emits among them.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/image.hpp"
#include "mfr/core/result.hpp"
#include "mfr/core/samples.hpp"
#include "mfr/gl/gl_context.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/fragment_node.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::gl {

struct GlPassTime {
  std::string name;
  double gpuMs = 0.0;   // GL_TIME_ELAPSED
  double wallMs = 0.0;  // host time around the pass, glFinish included
};

struct GlRenderOptions {
  glm::vec3 background{1.0f};  // linear RGB
  bool warmUp = true;          // run the passes once untimed first (shader compilation, caches)
  bool readNodes = false;      // read the captured nodes back (tests, tools)
  // variable k (counted, dynamic, importance, optimal): k(p), offsets and store kind per pixel
  // from the shared allocate(); the k-buffer capture and resolve read them per pixel
  const Allocation* allocation = nullptr;
  // n(p) measured before (count()): uploaded instead of running the count pass again
  const std::vector<uint32_t>* counts = nullptr;
  // the allocation the compute shaders left in the engine's buffers (countOnDevice, then
  // allocateCapped or allocateByImportance) and its n(p), instead of `allocation` and `counts`
  bool deviceAllocation = false;
  // linked lists: the pool's nodes (F(M), or every fragment without a budget)
  uint64_t poolNodes = 0;
};

/// What the host reads back of a variable-k allocation computed on the GPU: two totals.
struct GlAllocationTotals {
  uint64_t slots = 0;          // sum of min(k(p), n(p)): the nodes materialised
  uint64_t reservedSlots = 0;  // sum of k(p) as allocated (importance: may exceed n(p))
};

struct GlRenderOutput {
  ImageRGB image;                // linear RGB, rows top to bottom
  std::vector<uint32_t> counts;  // n(p), rows top to bottom
  uint64_t fragments = 0;        // sum of n(p)
  // with readNodes: pixel p's captured nodes nodes[nodeOffsets[p] .. + nodeCounts[p]), sorted
  // nearest first (the resolve sorts them in place)
  std::vector<FragmentNode> nodes;
  std::vector<uint64_t> nodeOffsets;
  std::vector<uint32_t> nodeCounts;
  std::map<std::string, uint64_t> bufferBytes;  // every GL buffer the frame allocated, by name
  uint64_t totalBufferBytes() const;
  uint64_t culledOccupancy = 0;    // k-buffers: rejected by the occupancy test (order-independent)
  uint64_t culledKPlus = 0;        // k-buffers: rejected by the k+ test (depends on arrival order)
  bool atomic64 = false;           // the fixed-k capture took 64-bit atomicMin (no lock)
  std::vector<GlPassTime> passes;  // count, prefix sum, capture, resolve (timed run)
  /// Linked lists: the nodes each pixel's list holds; depth peeling: the fragments peeled per
  /// pixel. And the peel passes run (not the tail's).
  std::vector<uint32_t> held;
  std::optional<uint32_t> peelPasses;
};

/// How the geometry passes make fragments (--gl-raster).
///  - Native: vertex shader, GL's clipper and rasterizer, fragment shader, single precision
///    (shaders/raster_native.vert, raster_native.glsl): what a GPU engine runs; its fragments are
///    the CPU engine's except where a pixel centre lies on a triangle edge (GL's fill rule and
///    sub-pixel snapping decide there) and its attributes agree within float rounding.
///  - Exact: the CPU engine's clipping, 1/256-pixel snapping, fill rule and interpolation in a
///    geometry and fragment shader, partly in double (raster.vert, raster.geom,
///    raster_exact.glsl): bit-identical to the CPU engine, a cross-check rather than a timing.
enum class GlRaster : uint8_t { Native, Exact };
const char* toString(GlRaster raster);
/// "native" or "exact"; anything else is one line naming --gl-raster.
Result<GlRaster> parseGlRaster(std::string_view text);

/// Multisampling of an engine's geometry passes (core/samples.hpp): `samples` per pixel on a
/// multisampled attachment-less framebuffer, whose sample positions must be the standard pattern
/// (GlEngine::create checks them), and the storage discipline: per-pixel nodes carrying coverage
/// masks (gl_SampleMaskIn), or per-sample storage (sample shading at rate 1; the engine's width()
/// is then the storage's W * samples).
struct GlSampling {
  int samples = 1;
  SampleStorage storage = SampleStorage::Pixel;

  /// The storage pixels of one image pixel: the samples under per-sample storage, else 1.
  int storagePerPixel() const { return storage == SampleStorage::Sample ? samples : 1; }
  /// The samples of the coverage masks in the nodes' depths (per-pixel storage), else 1.
  int maskSamples() const { return storage == SampleStorage::Pixel ? samples : 1; }
};

/// One scene and view uploaded to GL once; render() runs a method on it any number of times.
/// Supported methods: `abuffer` (unbounded, append), fixed-k max-array or max-heap
/// k-buffers with an explicit k, and any k-buffer with a per-pixel allocation
/// (GlRenderOptions::allocation) (`fkb`, `kplus-array`, `kplus-heap`, `zbuffer`; the k+ test runs
/// for all of them: it changes no captured set), optionally with occupancy culling (`+occupancy`,
/// d = occupancyWords), with kbuffer or hybrid compositing; anything else is an error naming the
/// method. The
/// engine must be used on the thread where its context is current, and the context must outlive it.
class GlEngine {
 public:
  /// Errors (one line): the size outside [1, 16384] or above GL's limits, a scene failing
  /// validateScene, a shader that does not compile or link (its name and info log).
  /// `interlock`: the k-buffer capture orders a pixel's fragments with the driver's fragment
  /// shader interlock (interlockExtension(context) must name one) instead of the spin-lock.
  /// `raster`: GL's own pipeline (native) or the CPU engine's emulated (exact), see GlRaster.
  /// `sampling`: more than one sample needs the native raster, a framebuffer of that many samples
  /// and the standard sample positions (else one line naming --samples and what this GL offers).
  static Result<GlEngine> create(const GlContext& context, const Scene& scene, const Camera& camera,
                                 int width, int height, bool interlock = false,
                                 GlRaster raster = GlRaster::Native, GlSampling sampling = {});

  GlEngine(GlEngine&&) noexcept;
  GlEngine& operator=(GlEngine&&) noexcept;
  ~GlEngine();

  Result<GlRenderOutput> render(const MethodDesc& method, const GlRenderOptions& options = {});

  /// The count pass alone: n(p), rows top to bottom (what a variable-k allocation needs first).
  Result<std::vector<uint32_t>> count();
  /// Multisampled with per-pixel storage: 1 at the pixels some fragment covers only in part (an
  /// edge crosses them), else 0 (the count pass counting those fragments).
  Result<std::vector<uint8_t>> edgePixels();
  /// The nearest fragment's |n.v| per pixel, quantised to unorm8 / 255 like mfr::nearestCosine
  /// (0 where nothing is covered).
  Result<std::vector<float>> nearestCosine();
  /// The deep k-buffer's importance I(p): the feature pass (shaders/dkb_features.frag), the image
  /// statistics from its accumulators on the host, features and network per pixel in a compute
  /// shader (shaders/dkb_infer.comp). `layers` {12, 128, 64, 1}, `weights` Eigen's column-major
  /// W0, b0, W1, b1, W2, b2 flattened; `slots` = F(M). `passes` gets the passes' wall times.
  Result<std::vector<float>> dkbImportance(const std::vector<float>& weights, uint64_t slots,
                                           std::vector<GlPassTime>* passes = nullptr);

  /// Variable k on the GPU, step 1: the count pass into a buffer the engine keeps, and the
  /// histogram of n(p) and its maximum in a compute shader (alloc_histogram.comp); the host reads
  /// kHistogramBins + 1 words (mfr::boundedK picks the dynamic k from them).
  Result<CountSummary> countOnDevice(std::vector<GlPassTime>* passes = nullptr);
  /// Step 2, counted or dynamic k: k(p) = min(n(p), k) (alloc_k.comp), its prefix sum
  /// (prefix_sum.comp) and the per-pixel words (alloc_pack.comp; `store` as mfr::allocate's).
  Result<GlAllocationTotals> allocateCapped(uint32_t k, StoreChoice store,
                                            std::vector<GlPassTime>* passes = nullptr);
  /// Step 2, the variable k-buffer: the nearest |n.v| pass, the importance map
  /// (importance.comp; `previousCosine` when it has a value per pixel, else this frame's |n.v|),
  /// I_tot (importance_total.comp), k(p) = floor(I(p) / I_tot * slots) (alloc_k.comp), prefix
  /// sum and per-pixel words. `slots` = F(M).
  Result<GlAllocationTotals> allocateByImportance(const ImportanceParams& params,
                                                  const std::vector<float>& previousCosine,
                                                  uint64_t slots, StoreChoice store,
                                                  std::vector<GlPassTime>* passes = nullptr);
  /// The device allocation read back (k(p), offsets, store kinds, reserved k(p) for importance,
  /// the totals; no globalK): the output's k map and statistics.
  Result<Allocation> readDeviceAllocation();
  /// The importance maps and the nearest |n.v| of allocateByImportance, read back for the output.
  Result<ImportanceMaps> readImportance();
  Result<std::vector<float>> readNearestCosine();

  GlRaster raster() const;
  /// The storage's size: the image's, or W * samples x H under per-sample storage.
  int width() const;
  int height() const;
  const GlSampling& sampling() const;
  /// The camera with the fitted clip planes (what RasterFrame::build uses).
  const Camera& camera() const;

 private:
  struct State;
  explicit GlEngine(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

/// A GL buffer of `bytes` (at least 16) with `data` (or undefined contents), checked with
/// glGetError: when GL cannot allocate it (GL_OUT_OF_MEMORY), one line naming the buffer and its
/// bytes. Every buffer of the engine is made through it. Needs the context current.
Result<unsigned> createCheckedBuffer(const std::string& name, uint64_t bytes,
                                     const void* data = nullptr, bool staticDraw = false);

/// True when the context offers 64-bit atomics on storage buffers (GL_NV_shader_atomic_int64 with
/// GL_ARB_gpu_shader_int64): the fixed-k k-buffer (no tail, no occupancy) then captures with
/// atomicMin instead of the spin-lock (capture_kbuffer_atomic64.frag).
bool hasAtomic64(const GlContext& context);

/// The fragment shader interlock extension the context offers, in the order
/// GL_ARB_fragment_shader_interlock, GL_NV_fragment_shader_interlock,
/// GL_INTEL_fragment_shader_ordering; empty when it offers none.
std::string interlockExtension(const GlContext& context);

}  // namespace mfr::gl
