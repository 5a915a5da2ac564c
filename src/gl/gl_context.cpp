// Headless OpenGL 4.5 core context: EGL (surfaceless Mesa platform, EGL device, default display)
// through libepoxy, made current without a surface.
#include "mfr/gl/gl_context.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>
#include <cstring>
#include <utility>

namespace mfr::gl {
namespace {

std::string eglErrorName(EGLint code) {
  switch (code) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "EGL error 0x%x", static_cast<unsigned>(code));
      return buf;
    }
  }
}

bool hasToken(const char* list, const char* name) {
  if (list == nullptr) return false;
  const size_t len = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += len)
    if ((p == list || p[-1] == ' ') && (p[len] == ' ' || p[len] == '\0')) return true;
  return false;
}

struct Candidate {
  std::string name;
  EGLDisplay display;
};

// A context on `display` and its GL strings; false (with a note) when there is none.
bool tryDisplay(EGLDisplay display, EGLContext& context, std::string& note) {
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    note = "eglInitialize: " + eglErrorName(eglGetError());
    return false;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    note = "EGL " + std::to_string(major) + "." + std::to_string(minor) +
           ", no desktop OpenGL API (" + eglErrorName(eglGetError()) + ")";
    return false;
  }
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!epoxy_has_egl_extension(display, "EGL_KHR_no_config_context")) {
    const EGLint attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, attribs, &config, 1, &count) || count < 1) {
      note = "no EGL config with EGL_OPENGL_BIT";
      return false;
    }
  }
  const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                   4,
                                   EGL_CONTEXT_MINOR_VERSION,
                                   5,
                                   EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                   EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                   EGL_NONE};
  context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttribs);
  if (context == EGL_NO_CONTEXT) {
    note = "EGL " + std::to_string(major) + "." + std::to_string(minor) + " (" +
           (eglQueryString(display, EGL_VENDOR) ? eglQueryString(display, EGL_VENDOR) : "?") +
           "), eglCreateContext 4.5 core: " + eglErrorName(eglGetError());
    return false;
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    note = "eglMakeCurrent without a surface: " + eglErrorName(eglGetError());
    eglDestroyContext(display, context);
    return false;
  }
  if (epoxy_gl_version() < 45) {
    note = std::string("GL ") + reinterpret_cast<const char*>(glGetString(GL_VERSION));
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display, context);
    return false;
  }
  return true;
}

}  // namespace

Result<GlContext> GlContext::create() {
  std::vector<Candidate> candidates;
  std::vector<std::string> notes;
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const bool platformBase = hasToken(clientExtensions, "EGL_EXT_platform_base");
  if (platformBase && hasToken(clientExtensions, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d =
        eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d != EGL_NO_DISPLAY)
      candidates.push_back({"surfaceless", d});
    else
      notes.push_back("surfaceless: no display");
  }
  if (platformBase && hasToken(clientExtensions, "EGL_EXT_platform_device") &&
      hasToken(clientExtensions, "EGL_EXT_device_enumeration")) {
    EGLDeviceEXT devices[8];
    EGLint count = 0;
    if (eglQueryDevicesEXT(8, devices, &count) && count > 0) {
      for (EGLint i = 0; i < count; ++i) {
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (d != EGL_NO_DISPLAY) candidates.push_back({"device " + std::to_string(i), d});
      }
    } else {
      notes.push_back("device: none");
    }
  }
  if (EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY); d != EGL_NO_DISPLAY)
    candidates.push_back({"default display", d});
  else
    notes.push_back("default display: none");

  for (const Candidate& c : candidates) {
    EGLContext context = EGL_NO_CONTEXT;
    std::string note;
    if (!tryDisplay(c.display, context, note)) {
      notes.push_back(c.name + ": " + note);
      continue;
    }
    GlContext out;
    out.display_ = c.display;
    out.context_ = context;
    out.platform_ = c.name;
    auto str = [](GLenum e) {
      const GLubyte* s = glGetString(e);
      return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
    };
    out.renderer_ = str(GL_RENDERER);
    out.version_ = str(GL_VERSION);
    out.vendor_ = str(GL_VENDOR);
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; ++i)
      out.extensionList_.emplace_back(
          reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i))));
    out.extensions_.arbFragmentShaderInterlock =
        out.hasExtension("GL_ARB_fragment_shader_interlock");
    out.extensions_.nvFragmentShaderInterlock = out.hasExtension("GL_NV_fragment_shader_interlock");
    out.extensions_.intelFragmentShaderOrdering =
        out.hasExtension("GL_INTEL_fragment_shader_ordering");
    out.extensions_.arbGpuShaderInt64 = out.hasExtension("GL_ARB_gpu_shader_int64");
    out.extensions_.nvShaderAtomicInt64 = out.hasExtension("GL_NV_shader_atomic_int64");
    return out;
  }
  std::string found;
  for (const std::string& n : notes) found += (found.empty() ? "" : "; ") + n;
  if (found.empty()) found = "no display";
  return makeError("--engine gl: no OpenGL 4.5 core context (EGL: " + found + ")");
}

GlContext::GlContext(GlContext&& other) noexcept {
  *this = std::move(other);
}

GlContext& GlContext::operator=(GlContext&& other) noexcept {
  if (this != &other) {
    release();
    display_ = std::exchange(other.display_, nullptr);
    context_ = std::exchange(other.context_, nullptr);
    renderer_ = std::move(other.renderer_);
    version_ = std::move(other.version_);
    vendor_ = std::move(other.vendor_);
    platform_ = std::move(other.platform_);
    extensionList_ = std::move(other.extensionList_);
    extensions_ = other.extensions_;
  }
  return *this;
}

GlContext::~GlContext() {
  release();
}

void GlContext::release() {
  if (display_ == nullptr) return;
  // the display stays initialised: EGL displays are per process, and eglTerminate would also end
  // every other context on it
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (context_ != nullptr) eglDestroyContext(display_, context_);
  display_ = nullptr;
  context_ = nullptr;
}

bool GlContext::hasExtension(const std::string& name) const {
  for (const std::string& e : extensionList_)
    if (e == name) return true;
  return false;
}

void GlContext::makeCurrent() const {
  if (display_ != nullptr) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
}

}  // namespace mfr::gl
