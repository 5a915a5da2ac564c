// The GL engine's programs: one table {id, shader file, stages, prelude} and the composition of
// each stage's source ("#version", the prelude, shared_layout.h, [the raster part and
// raster_common.glsl,] the file), linked once per engine (GlEngine::create) into Programs.
#pragma once

#include <epoxy/gl.h>

#include <array>
#include <cstdint>
#include <functional>
#include <string>

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

/// The linked programs of one engine, deleted with it (in the context current then).
class Programs {
 public:
  Programs() { ids_.fill(0); }
  Programs(const Programs&) = delete;
  Programs& operator=(const Programs&) = delete;
  ~Programs();

  /// Links every program of the table for `raster`; the k-buffer capture takes `kbufferPrelude`
  /// (the interlock's lines, or none). The 64-bit atomic programs are linked where the driver
  /// offers the extensions; one that announces them but does not compile the shaders keeps the
  /// lock (those two programs are then 0). `rasterUniforms` is called on each raster program.
  Result<void> link(const GlContext& context, GlRaster raster, const std::string& kbufferPrelude,
                    const std::function<void(GLuint)>& rasterUniforms);

  GLuint operator[](ProgramId id) const { return ids_[static_cast<size_t>(id)]; }

 private:
  std::array<GLuint, kProgramCount> ids_;
};

/// The k-buffer capture's prelude: with `interlock`, the driver's interlock extension and its
/// begin / end macros (an error when the driver offers none); empty without.
Result<std::string> kbufferInterlockPrelude(const GlContext& context, bool interlock);

/// Text on one line (" | " for the newlines): GL's info logs in one-line errors.
std::string oneLine(std::string text);

}  // namespace mfr::gl
