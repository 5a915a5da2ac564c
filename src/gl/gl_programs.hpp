// The GL engine's programs: one table {id, shader file, stages, prelude} and the composition of
// each stage's source ("#version", the prelude, shared_layout.h, [the raster part and
// raster_common.glsl,] the file), linked once per engine (GlEngine::create) into Programs.
#pragma once

#include <epoxy/gl.h>

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>

#include "mfr/core/result.hpp"
#include "mfr/gl/gl_context.hpp"
#include "mfr/gl/gl_engine.hpp"

namespace mfr::gl {

/// Every program of the engine; kPrograms (gl_programs.cpp) has one row per value, in this order.
enum class ProgramId : uint8_t {
  Count,               // count.frag: n(p)
  ABuffer,             // capture_abuffer.frag
  KBuffer,             // capture_kbuffer.frag (lock or interlock)
  KBufferAtomic64,     // capture_kbuffer_atomic64.frag (fixed k, 64-bit atomicMin)
  SwapNodeWords,       // swap_node_words.comp (the atomic capture's words back to node order)
  DepthRange,          // depth_range.frag (occupancy: the pixel's depth range)
  OccupancyFill,       // occupancy_fill.frag
  NearestCosine,       // nearest_cosine.frag (vkb: the nearest fragment's |n.v|)
  Wboit,               // wboit.frag
  WboitResolve,        // wboit_resolve.comp
  Dfaoit,              // dfaoit.frag
  DfaoitResolve,       // dfaoit_resolve.comp
  MboitMoments,        // mboit_moments.frag
  MboitColor,          // mboit_color.frag
  MboitResolve,        // mboit_resolve.comp
  Mlab,                // mlab.frag
  MlabResolve,         // mlab_resolve.comp
  DkbFeatures,         // dkb_features.frag
  DkbInfer,            // dkb_infer.comp
  OccupancyCount,      // occupancy_count.comp (the k-th occupied bucket)
  PrefixSum,           // prefix_sum.comp
  PrefixSumAdd,        // prefix_sum_add.comp
  Resolve,             // resolve.comp (A-buffer and k-buffer family)
  AllocHistogram,      // alloc_histogram.comp
  Importance,          // importance.comp
  ImportanceTotal,     // importance_total.comp
  AllocK,              // alloc_k.comp
  AllocPack,           // alloc_pack.comp
  AoitVisibility,      // aoit_visibility.frag
  AoitColor,           // aoit_color.frag
  AoitResolve,         // aoit_resolve.comp
  ListCapture,         // capture_list.frag (per-pixel linked lists)
  ListResolve,         // resolve_list.comp
  Peel,                // peel.frag (depth peeling's passes and tail pass)
  PeelStep,            // peel_step.comp (between peel passes)
  PeelResolve,         // peel_resolve.comp
  Stochastic,          // stochastic.frag (its three passes, uPass)
  StochasticResolve,   // stochastic_resolve.comp
  HashedAlpha,         // hashed_alpha.frag
  HashedAlphaResolve,  // hashed_alpha_resolve.comp
};
inline constexpr size_t kProgramCount = static_cast<size_t>(ProgramId::HashedAlphaResolve) + 1;

/// The engine's compile-time switches (shared_layout.h: MFR_SAMPLES .. MFR_BLEND_MODES): the
/// view's sampling and which material features its scene has, the same for every program of one
/// engine. The defaults are shared_layout.h's (one sample, every feature).
struct EngineSwitches {
  int samples = 1;
  bool sampleStorage = false;  // per-sample storage (multisampled)
  bool vertexColors = true;
  bool textures = true;
  bool alphaMask = true;
  uint32_t blendModes = 15;  // blendBit masks

  /// the #define lines
  std::string prelude() const;
};

/// The linked programs of one engine, deleted with it (in the context current then).
class Programs {
 public:
  Programs() { ids_.fill(0); }
  Programs(const Programs&) = delete;
  Programs& operator=(const Programs&) = delete;
  ~Programs();

  /// Links every program of the table for `raster` and the engine's `switches`; the k-buffer
  /// capture takes `kbufferPrelude` (the interlock's lines, or none). The 64-bit atomic programs
  /// are linked where the driver offers the extensions; one that announces them but does not
  /// compile the shaders keeps the lock (those two programs are then 0). `rasterUniforms` is
  /// called on each raster program, also on the variants linked later.
  Result<void> link(const GlContext& context, GlRaster raster, const std::string& kbufferPrelude,
                    const EngineSwitches& switches,
                    const std::function<void(GLuint)>& rasterUniforms);

  GLuint operator[](ProgramId id) const { return ids_[static_cast<size_t>(id)]; }

  /// The program `id` compiled with the #define lines `defines` (its own switches, e.g. the
  /// k-buffer capture's store), linked on first use and kept; empty `defines`: the table's.
  Result<GLuint> variant(ProgramId id, const std::string& defines);

 private:
  Result<GLuint> linkRow(ProgramId id, const std::string& defines) const;

  std::array<GLuint, kProgramCount> ids_;
  std::map<std::pair<ProgramId, std::string>, GLuint> variants_;
  GlRaster raster_ = GlRaster::Native;
  std::string kbufferPrelude_, enginePrelude_;
  std::function<void(GLuint)> rasterUniforms_;
};

/// capture_kbuffer.frag's switches: a per-pixel allocation (else a fixed k in one `store`,
/// kStoreMaxArray or kStoreMaxHeap), occupancy culling, the hybrid tail.
std::string kbufferSwitches(bool perPixel, uint32_t store, bool occupancy, bool hybrid);

/// mboit_moments.frag's and mboit_color.frag's switches: the moment count N (4, 6 or 8),
/// trigonometric moments, 16-bit storage.
std::string mboitSwitches(uint32_t moments, bool trigonometric, bool quantized);

/// The AOIT programs' switch: the node count (4, 8 or 16).
std::string aoitSwitches(uint32_t nodes);

/// stochastic.frag's switches: the pass (0 total alpha, 1 stochastic depth, 2 capture), the
/// stratified masks.
std::string stochasticSwitches(uint32_t pass, bool stratified);

/// Depth peeling's switches: dual peeling, and peel.frag's tail pass / peel_resolve.comp's tail.
std::string peelSwitches(bool dual, bool tail);
std::string peelStepSwitches(bool dual);
std::string peelResolveSwitches(bool dual, bool hybrid);

/// The linked lists' switch (capture_list.frag, resolve_list.comp): the hybrid tail.
std::string listSwitches(bool hybrid);

/// resolve.comp's switches: the node layout (kResolveFixedK, kResolveABuffer, kResolvePerPixel),
/// the hybrid tail, whether every pixel's slots fit the local sort, whether the sorted nodes are
/// written back.
std::string resolveSwitches(uint32_t nodes, bool hybrid, bool localSort, bool writeSorted);

/// The k-buffer capture's prelude: with `interlock`, the driver's interlock extension and its
/// begin / end macros (an error when the driver offers none); empty without.
Result<std::string> kbufferInterlockPrelude(const GlContext& context, bool interlock);

/// Text on one line (" | " for the newlines): GL's info logs in one-line errors.
std::string oneLine(std::string text);

}  // namespace mfr::gl
