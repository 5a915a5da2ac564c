#include "engine_context.hpp"

#include <EGL/egl.h>
#include <GLFW/glfw3.h>

namespace mfr::view {

void EngineContext::captureCurrent() {
  context_ = eglGetCurrentContext();
  if (context_ == EGL_NO_CONTEXT) {
    context_ = nullptr;
    return;
  }
  display_ = eglGetCurrentDisplay();
  draw_ = eglGetCurrentSurface(EGL_DRAW);
  read_ = eglGetCurrentSurface(EGL_READ);
}

void EngineContext::release() const {
  if (context_ != nullptr)
    eglMakeCurrent(static_cast<EGLDisplay>(display_), EGL_NO_SURFACE, EGL_NO_SURFACE,
                   EGL_NO_CONTEXT);
}

void EngineContext::makeCurrent() const {
  if (context_ != nullptr)
    eglMakeCurrent(static_cast<EGLDisplay>(display_), static_cast<EGLSurface>(draw_),
                   static_cast<EGLSurface>(read_), static_cast<EGLContext>(context_));
}

EngineContext::Scope::Scope(const EngineContext& engine, GLFWwindow* window)
    : engine_(engine), window_(window) {
  if (window_ != nullptr) glfwMakeContextCurrent(nullptr);
  engine_.makeCurrent();
}

EngineContext::Scope::~Scope() {
  engine_.release();
  if (window_ != nullptr) glfwMakeContextCurrent(window_);
}

}  // namespace mfr::view
