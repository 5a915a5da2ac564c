// The OpenGL engine's shader sources, embedded at build time (cmake/mfr_shaders.cmake).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "mfr/core/result.hpp"

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

/// Compiles one shader stage (a GLenum) from `source` (complete, with its #version) on the current
/// context; the error names `name` and carries the info log on one line. The caller owns the
/// returned shader object.
Result<unsigned> compileShaderSource(unsigned stage, const std::string& name,
                                     const std::string& source);

}  // namespace mfr::gl
