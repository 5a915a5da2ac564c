// A headless OpenGL 4.5 core context through EGL and libepoxy: no window, no X11 or Wayland. The
// display is the Mesa surfaceless platform when offered, else the first EGL device, else
// eglGetDisplay(EGL_DEFAULT_DISPLAY); the context is made current without a surface.
#pragma once

#include <string>
#include <vector>

#include "mfr/core/result.hpp"

namespace mfr::gl {

/// Optional extensions the GL engine's later passes may use.
struct GlExtensions {
  bool arbFragmentShaderInterlock = false;   // GL_ARB_fragment_shader_interlock
  bool nvFragmentShaderInterlock = false;    // GL_NV_fragment_shader_interlock
  bool intelFragmentShaderOrdering = false;  // GL_INTEL_fragment_shader_ordering
  bool arbGpuShaderInt64 = false;            // GL_ARB_gpu_shader_int64
  bool nvShaderAtomicInt64 = false;          // GL_NV_shader_atomic_int64
};

/// Owns the EGL display connection and context; current on the thread that created it (the
/// engine's calls must come from that thread). Move-only.
class GlContext {
 public:
  /// Errors (one line): "--engine gl: no OpenGL 4.5 core context (EGL: <what was found>)".
  static Result<GlContext> create();

  GlContext(GlContext&& other) noexcept;
  GlContext& operator=(GlContext&& other) noexcept;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;
  ~GlContext();

  const std::string& renderer() const { return renderer_; }  // GL_RENDERER
  const std::string& version() const { return version_; }    // GL_VERSION
  const std::string& vendor() const { return vendor_; }      // GL_VENDOR
  const std::string& eglPlatform() const { return platform_; }
  const std::vector<std::string>& extensionList() const { return extensionList_; }
  bool hasExtension(const std::string& name) const;
  const GlExtensions& extensions() const { return extensions_; }

  /// Makes the context current on the calling thread again (after another context was used).
  void makeCurrent() const;

 private:
  GlContext() = default;
  void release();

  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  std::string renderer_, version_, vendor_, platform_;
  std::vector<std::string> extensionList_;
  GlExtensions extensions_;
};

}  // namespace mfr::gl
