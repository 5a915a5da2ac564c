// The GL engine's techniques: what a method becomes on the GPU. In the spirit of nvpro's
// vk_order_independent_transparency (common.h's OIT_ algorithm list and the per-algorithm switch of
// its renderer), one enum names every technique the GL engine runs, classifyGl() maps a method to
// it (and owns the "not in the GL engine" error), and every phase of a frame dispatches with one
// switch over the technique that lists every case, so the compiler (-Wswitch) finds a phase that
// forgets a new technique. The table (glTechniques(), kTechniques in src/gl/gl_technique.cpp) says
// what each technique runs: its passes, programs and per-pixel memory (docs/GL_ENGINE.md prints
// it).
//
// Adding a technique: one GlTechnique value, one row of kTechniques, its shaders (and their rows
// in the program table, src/gl/gl_programs.cpp), and a case in each phase's switch
// (src/gl/gl_frame.cpp), which the compiler lists.
#pragma once

#include <cstdint>
#include <span>

#include "mfr/core/result.hpp"
#include "mfr/method/method.hpp"

namespace mfr::gl {

enum class GlTechnique : uint8_t {
  ABuffer,  // exact A-buffer: count pass, prefix sum, append capture, sort + front-to-back resolve
  KBuffer,  // k-buffer family: fixed k or a per-pixel k(p) (host or device allocation), max-array
            // or max-heap with the k+ test, optional occupancy culling and hybrid tail
  Wboit,    // weighted blended OIT: one accumulation pass, weighted-average resolve
  Mboit,    // moment-based OIT: moments pass, colour pass, reconstruction resolve
  Mlab,     // multi-layer alpha blending: merge capture of k nodes, front-to-back resolve
  Aoit,     // adaptive transparency: visibility pass (N nodes), colour pass, composite
  LinkedList,  // per-pixel linked lists: pool counter + head exchange capture, walk-sort resolve
  Peel,    // depth peeling and dual depth peeling: peel passes (geometry + per-pixel step) until
           // none remains or --max-peels, [tail pass], composite
  Dfaoit,  // deep and fast approximate OIT: one accumulation pass, the network in the resolve
  Stochastic,   // stochastic transparency (plain, stratified): total alpha, stochastic depth,
                // visibility-weighted capture, alpha-corrected resolve
  HashedAlpha,  // hashed alpha testing: one pass into a z-buffer of the kept fragments
};

/// One row of the technique table.
struct GlTechniqueInfo {
  GlTechnique technique;
  const char* name;
  const char* passes;    // the geometry and compute passes of one frame, in order
  const char* capture;   // the capture shader(s)
  const char* resolve;   // the resolve shader
  const char* perPixel;  // per-pixel memory of the frame (docs/GL_ENGINE.md draws the layouts)
  const char* presets;   // the presets that run as this technique
};

/// Every technique, in the enum's order.
std::span<const GlTechniqueInfo> glTechniques();
const GlTechniqueInfo& techniqueInfo(GlTechnique technique);
const char* toString(GlTechnique technique);

/// The technique a method runs as on the GL engine; a method outside it is one line naming it:
/// "--engine gl: method NAME is not in the GL engine (...)". Depends on the method alone (whether
/// a k-buffer's k is fixed or per pixel is the frame's allocation, not the technique).
Result<GlTechnique> classifyGl(const MethodDesc& method);

}  // namespace mfr::gl
