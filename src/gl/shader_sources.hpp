// The OpenGL engine's shader sources, embedded at build time (cmake/mfr_shaders.cmake).
#pragma once

#include <cstddef>
#include <string_view>

namespace mfr::gl {

struct EmbeddedShader {
  const char* name;  // file name under shaders/ (and "shared_layout.h")
  const char* text;
};

extern const EmbeddedShader kEmbeddedShaders[];
extern const size_t kEmbeddedShaderCount;

/// The embedded text of a shader file; empty when there is none of that name.
inline std::string_view embeddedShader(std::string_view name) {
  for (size_t i = 0; i < kEmbeddedShaderCount; ++i)
    if (name == kEmbeddedShaders[i].name) return kEmbeddedShaders[i].text;
  return {};
}

}  // namespace mfr::gl
