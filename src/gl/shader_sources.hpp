// The OpenGL engine's shader sources, embedded at build time (cmake/mfr_shaders.cmake).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

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

/// One composed shader stage of one program variant, exactly as the engine hands it to the driver.
struct ShaderVariant {
  std::string program;  // the program and its variant, e.g. "capture_kbuffer.frag (lock)"
  std::string file;     // the stage's own file under shaders/
  std::string stage;    // vert, geom, frag or comp (glslangValidator's stage names)
  std::string source;   // complete, from #version
};

/// Every stage of every program in every variant the engine can link (the k-buffer capture's
/// spin-lock and each interlock extension, the 64-bit atomic capture; each program's own switches
/// in every combination, under the engine switches of one sample with and without the scene's
/// features and of four samples in both storages), whatever the driver offers: what
/// `glslangValidator` checks in the tests, so variants llvmpipe cannot run still compile in CI.
/// A stage whose text repeats (a vertex shader, which takes no switches) is listed once.
std::vector<ShaderVariant> shaderVariants();

/// Compiles one shader stage (a GLenum) from `source` (complete, with its #version) on the current
/// context; the error names `name` and carries the info log on one line. The caller owns the
/// returned shader object.
Result<unsigned> compileShaderSource(unsigned stage, const std::string& name,
                                     const std::string& source);

}  // namespace mfr::gl
