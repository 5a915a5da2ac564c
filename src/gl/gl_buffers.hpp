// Buffers, dispatch and timing of the GL engine's passes: a frame's buffers with their ledger,
// buffer clears, 2D work-group grids, timed passes (GL_TIME_ELAPSED and wall time).
#pragma once

#include <epoxy/gl.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/gl/gl_engine.hpp"

namespace mfr::gl {

inline GLint loc(GLuint program, const char* name) {
  return glGetUniformLocation(program, name);
}

/// "0x..." for a GL error code.
std::string glErrorText(GLenum e);

/// The buffers of an engine's last frame, kept for its next: a renderer reuses its frame's
/// buffers instead of allocating them anew each frame (a driver that backs a fresh buffer with
/// new pages pays for their first touch in the frame's clears: about 40 ms for a 1024x1024
/// k = 8 k-buffer on llvmpipe). Deleted with the engine (its context current).
struct BufferPool {
  std::multimap<uint64_t, GLuint> free;  // by size in bytes

  BufferPool() = default;
  BufferPool(const BufferPool&) = delete;
  BufferPool& operator=(const BufferPool&) = delete;
  ~BufferPool() { release(); }
  /// deletes the kept buffers
  void release();
};

/// Buffers of one frame, deleted with it, or with a pool kept for the next frame (the pool's
/// buffers this frame did not take are deleted then); their sizes go to the ledger. The first
/// buffer GL could not allocate is `failure` (later makes return 0; the frame's passes are
/// skipped).
struct FrameBuffers {
  std::vector<GLuint> buffers, textures;
  std::map<std::string, uint64_t>* ledger = nullptr;
  std::optional<Error> failure;
  BufferPool* pool = nullptr;

  explicit FrameBuffers(std::map<std::string, uint64_t>* l, BufferPool* p = nullptr)
      : ledger(l), pool(p) {}
  FrameBuffers(const FrameBuffers&) = delete;
  FrameBuffers& operator=(const FrameBuffers&) = delete;
  ~FrameBuffers();
  /// a buffer of `bytes` (at least 16), its contents `data` or undefined
  GLuint make(const std::string& name, uint64_t bytes, const void* data = nullptr);
  /// an r32ui imageBuffer view of a buffer, bound to an image unit
  void bindImage(GLuint buffer, GLuint unit);
  /// a texel buffer view (`format`, e.g. GL_RG32UI) of a buffer, bound to a texture unit
  void bindTexture(GLuint buffer, GLenum format, GLuint unit);
};

void clearUint(GLuint buffer, uint32_t value);

/// work groups as a 2D grid (each dimension at most 65535); shaders linearise the group id
void dispatchGroups(uint64_t groups);

/// Runs a pass and appends its wall time (glFinish included) to `passes` (no GPU time: these are
/// the allocation's passes, reported as host-side passes).
template <class Body>
void timedPass(std::vector<GlPassTime>* passes, const char* name, Body&& body) {
  const auto t0 = std::chrono::steady_clock::now();
  body();
  glFinish();
  if (passes)
    passes->push_back(
        {name, 0.0,
         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()});
}

/// Runs a pass and appends GL's elapsed time (GL_TIME_ELAPSED on `query`) and the wall time
/// around it (glFinish included).
template <class Body>
void timedGpuPass(GLuint query, std::vector<GlPassTime>& passes, const char* name, Body&& body) {
  const auto t0 = std::chrono::steady_clock::now();
  glBeginQuery(GL_TIME_ELAPSED, query);
  body();
  glEndQuery(GL_TIME_ELAPSED);
  glFinish();
  const auto t1 = std::chrono::steady_clock::now();
  GLuint64 ns = 0;
  glGetQueryObjectui64v(query, GL_QUERY_RESULT, &ns);
  passes.push_back({name, static_cast<double>(ns) * 1e-6,
                    std::chrono::duration<double, std::milli>(t1 - t0).count()});
}

}  // namespace mfr::gl
