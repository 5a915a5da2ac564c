// The OpenGL 4.5 engine behind the Engine seam (mfr/engine/engine.hpp): one headless context
// (GlContext), a PreparedView per uploaded view (GlEngine), and the shared allocation, memory model
// and statistics around the GL passes, so `mfr render/compare/info --engine gl` report what the
// CPU engine reports for the same method. Methods the GL passes do not run yet are a one-line
// error naming them (GlEngine::render).
#pragma once

#include <memory>
#include <string>

#include "mfr/core/result.hpp"
#include "mfr/engine/engine.hpp"

namespace mfr::gl {

/// A GL engine on a new headless GL 4.5 core context. Errors (one line): no such context
/// ("--engine gl: no OpenGL 4.5 core context (EGL: ...)"); `sync` not auto, lock or interlock;
/// `raster` not native or exact (GlRaster);
/// interlock asked for on a driver without GL_ARB_fragment_shader_interlock,
/// GL_NV_fragment_shader_interlock or GL_INTEL_fragment_shader_ordering. Use it on the thread that
/// made it.
Result<std::unique_ptr<Engine>> makeGlEngine(const std::string& sync = "auto",
                                             const std::string& raster = "native");

/// Adds "gl" to makeEngine's engines (registerEngine).
void registerGlEngine();

}  // namespace mfr::gl
