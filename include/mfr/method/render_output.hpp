// What every engine's render of one frame with one method takes and gives: the options, the
// statistics both engines report (memory as MemoryModel charges it, fragments captured and lost,
// per-pass time) and the output image and maps. Backend-neutral: the CPU engine
// (mfr/cpu/render.hpp) and any other engine (mfr/engine/engine.hpp) fill the same structures.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/image.hpp"
#include "mfr/core/samples.hpp"
#include "mfr/method/fragment_node.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/scene/cull_mode.hpp"

namespace mfr {

class FrameBuffers;  // mfr/cpu/frame_buffers.hpp

enum class CaptureMode : uint8_t {
  TileOwned,         // each tile owned by one worker: no locks, deterministic
  FragmentParallel,  // the paper's algorithm as written: triangles from many threads, per-pixel
                     // spin-locks, culling test outside the critical section and again inside
};

struct RenderOptions {
  std::optional<uint64_t> budgetBytes;  // M; required by bounded presets unless k is explicit
  CaptureMode capture = CaptureMode::TileOwned;
  glm::vec3 background{1.0f};  // linear RGB
  bool keepStores = false;     // keep the captured nodes in the output (tests, tools)
  /// Importance allocation: |n.v| of each pixel's nearest fragment in the previous frame of a
  /// sequence (RenderOutput::nearestCosine of that frame). When absent, a preceding frame from the
  /// same camera is used.
  const std::vector<float>* previousNearestCosine = nullptr;
  /// Memory pre-flight: render() computes the bytes of its buffers before allocating them (the
  /// per-pixel buffers before the first pass, the node pool once the slots are known, the
  /// optimal oracle's A-buffer and error curves) and fails with one line naming the method, the
  /// size, the bytes needed and this limit when they exceed it. None: defaultMemoryLimit()
  /// (mfr/core/memory_limit.hpp, 75% of the physical memory).
  std::optional<uint64_t> memoryLimitBytes;
  /// The CPU engine: buffers kept from the previous render, reused by this one (the same output;
  /// see mfr/cpu/frame_buffers.hpp). CpuEngine passes its own when this is unset.
  FrameBuffers* reuse = nullptr;
  /// Multisampled views (View::samples > 1): how the method stores a pixel's samples
  /// (core/samples.hpp): one node per fragment with its coverage mask, or nodes per sample.
  SampleStorage sampleStorage = SampleStorage::Pixel;
};

struct PassTime {
  std::string name;
  double ms = 0.0;
};

/// What the optimal k-buffer's oracle knows of its allocation (optimal_allocation.hpp). Errors
/// are sums over pixels of the squared linear-RGB distance to the exact A-buffer colour, for the
/// method's compositing rule.
struct OracleReport {
  double error = 0.0;       // of the returned allocation
  double lowerBound = 0.0;  // proven: the minimum when exact, else the Lagrangian bound
  double lagrangianBound = 0.0;
  bool exact = false;
  std::string solver;            // all-fit, hull, hull+dp, greedy
  uint64_t nonconvexPixels = 0;  // covered pixels whose error curve is not convex
  uint64_t corePixels = 0;       // pixels the exact step searched
  double gap() const { return error - lowerBound; }
};

struct RenderStats {
  std::string method;
  std::optional<uint64_t> budgetBytes;
  /// The method's memory as the papers (and a GPU) lay it out: MemoryModel, never above the
  /// budget.
  uint64_t bytesUsed = 0;
  std::map<std::string, uint64_t> bytesByCategory;
  /// What this CPU engine actually allocated for the method's buffers (summed over the frame,
  /// measured at the allocation sites; see docs/MEMORY.md). Not bounded by the budget.
  uint64_t bytesAllocated = 0;
  std::map<std::string, uint64_t> bytesAllocatedByCategory;
  uint64_t fragmentSlots = 0;  // nodes allocated
  uint64_t fragmentsGenerated = 0;
  uint64_t culledOccupancy = 0;  // rejected by the occupancy threshold
  uint64_t culledKPlus = 0;      // rejected by the k+ test before the critical section
  uint64_t rejectedInStore = 0;  // rejected inside the critical section (re-check / full store)
  uint64_t inserted = 0;
  uint64_t evicted = 0;
  uint64_t captured = 0;  // fragments in the final cores
  uint64_t lost = 0;      // generated - captured
  uint64_t coveredPixels = 0;
  uint32_t kMin = 0, kMax = 0;                 // slots over covered pixels
  std::optional<uint32_t> globalK;             // fixed / counted / dynamic k
  std::optional<uint32_t> maxDepthComplexity;  // when a count pass ran
  std::optional<double> meanDepthComplexity;   // over covered pixels
  std::vector<PassTime> passes;
  std::optional<OracleReport> oracle;  // optimal / optimal-greedy
  /// Depth peeling (peel, dual-peel): the geometry passes that peeled layers ("peel 1", ... in
  /// `passes`), not counting the hybrid tail's pass.
  std::optional<uint32_t> peelPasses;
  uint64_t primitivesSkipped = 0;  // the scene's points and lines, not rendered
  CullMode cull = CullMode::Auto;  // the back faces the raster culled (Scene::cull)
  /// Multisampling (core/samples.hpp): samples per pixel and, with more than one, the storage
  /// discipline. Per-sample storage counts its k, slots and covered pixels per sample.
  int samples = 1;
  SampleStorage sampleStorage = SampleStorage::Pixel;
  /// Multisampled renders: the pixels an edge crosses (some fragment covers part of the pixel's
  /// samples) and the fragments lost there and in the other covered pixels (per-pixel counts:
  /// the fragments of the per-pixel storage; per-sample storage: summed over the samples).
  uint64_t edgePixels = 0;
  uint64_t lostAtEdges = 0, lostInside = 0;
  uint64_t fragmentsAtEdges = 0, fragmentsInside = 0;
  /// The engine that rendered (Engine::name) and what only it measures (the CPU engine: threads,
  /// tile_workers), beside the shared fields above.
  std::string engine;
  std::map<std::string, double> engineCounters;
  /// The instruction-set path the CPU engine's capture ran on ("scalar", "avx2": isaName of
  /// core/isa.hpp); empty for an engine that has none (OpenGL).
  std::string isa;
  double lostPercent() const {
    return fragmentsGenerated ? 100.0 * static_cast<double>(lost) / fragmentsGenerated : 0.0;
  }
  double totalMs() const;
};

struct RenderOutput {
  ImageRGB image;                         // linear RGB, composited over the background
  std::vector<uint32_t> kMap;             // slots per pixel
  std::vector<uint32_t> depthComplexity;  // n(p), when a count pass ran (else empty)
  ImportanceMaps importance;              // importance allocation only
  std::vector<float> nearestCosine;       // importance allocation: this frame's nearest |n.v|
  /// Multisampled renders: per pixel, the fragments that got no node (summed over the samples
  /// under per-sample storage; RenderStats::lostAtEdges and lostInside sum it).
  std::vector<uint32_t> lostPerPixel;
  RenderStats stats;
  // with keepStores: pixel p's captured nodes are nodes[offsets[p] .. offsets[p] + counts[p]),
  // unsorted, as the store left them
  std::vector<FragmentNode> nodes;
  std::vector<uint64_t> offsets;
  std::vector<uint32_t> counts;
};

/// Per-sample storage (core/samples.hpp) back to image pixels, for any engine: the W*S x H
/// storage's image box-filtered to W x H (the mean of each pixel's S samples), the importance
/// and |n.v| maps averaged, the counts (n(p), k(p)) summed over the samples. Stores (nodes,
/// offsets, counts) stay per storage pixel.
void toImagePixels(RenderOutput& out, int samples);

/// Multisampled renders, for any engine: the fragments that got no node at the pixels an edge
/// crosses (`edges`, per image pixel) and at the other covered pixels, into the statistics and
/// RenderOutput::lostPerPixel. `n` and `captured` are per storage pixel (`perPixel` storage pixels
/// an image pixel: the samples under per-sample storage, else 1); a storage pixel holds
/// min(captured, n) of its n fragments (every one where `captured` is empty).
void edgeStatistics(const std::vector<uint32_t>& n, const std::vector<uint32_t>& captured,
                    const std::vector<uint8_t>& edges, int perPixel, RenderOutput& out);

}  // namespace mfr
