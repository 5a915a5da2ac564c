// What the GL tests behind the Engine seam share: a GL engine, or the test skipped with the reason
// (failed under CI=true, where a GL 4.5 context must exist), and a file's bytes.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "mfr/gl/gl_render_engine.hpp"

// `name`: a std::unique_ptr<mfr::Engine> from makeGlEngine(sync, raster) ("auto", "exact": the
// CPU engine's raster, bit for bit; "native": GL's own)
#define MFR_GL_ENGINE_OR_SKIP(name, sync, raster)                              \
  auto name##Made = ::mfr::gl::makeGlEngine(sync, raster);                     \
  if (!name##Made) {                                                           \
    const char* ci = std::getenv("CI");                                        \
    if (ci && std::string(ci) == "true") FAIL() << name##Made.error().message; \
    GTEST_SKIP() << name##Made.error().message;                                \
  }                                                                            \
  std::unique_ptr<::mfr::Engine> name = std::move(name##Made.value())

namespace mfr::gl::test {

inline std::string fileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace mfr::gl::test
