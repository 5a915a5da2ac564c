// Two GL contexts on the viewer's thread: the engine's headless EGL context (made current by
// makeGlEngine and by Engine::prepare, and expected current by render and by the destructors of
// its views) and the window's GLFW context (texture upload, ImGui). Only one is current at a time:
// EngineContext::Scope releases the window's context and makes the engine's current for the
// lifetime of the scope, then gives the window its context back. With the CPU engine there is no
// engine context and a Scope only releases and restores the window's context.
#pragma once

struct GLFWwindow;

namespace mfr::view {

class EngineContext {
 public:
  /// Remembers the EGL context current on this thread (the engine's, right after makeEngine).
  void captureCurrent();
  /// Makes no EGL context current (before the window's context is made current).
  void release() const;
  void makeCurrent() const;

  class Scope {
   public:
    Scope(const EngineContext& engine, GLFWwindow* window);
    ~Scope();
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    const EngineContext& engine_;
    GLFWwindow* window_;
  };

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
  void* draw_ = nullptr;
  void* read_ = nullptr;
};

}  // namespace mfr::view
