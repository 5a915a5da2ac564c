// The GL engine's buffers, clears and dispatch (gl_buffers.hpp) and createCheckedBuffer
// (mfr/gl/gl_engine.hpp).
#include "gl/gl_buffers.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>

namespace mfr::gl {

void BufferPool::release() {
  for (const auto& [bytes, b] : free) glDeleteBuffers(1, &b);
  free.clear();
}

FrameBuffers::~FrameBuffers() {
  if (pool) {  // this frame's buffers are the pool's now; those it did not take go
    pool->release();
    for (GLuint b : buffers) {
      GLint64 size = 0;
      glGetNamedBufferParameteri64v(b, GL_BUFFER_SIZE, &size);
      pool->free.emplace(static_cast<uint64_t>(size), b);
    }
  } else if (!buffers.empty()) {
    glDeleteBuffers(static_cast<GLsizei>(buffers.size()), buffers.data());
  }
  if (!textures.empty()) glDeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
}

GLuint FrameBuffers::make(const std::string& name, uint64_t bytes, const void* data) {
  if (failure) return 0;
  const uint64_t size = std::max<uint64_t>(bytes, 16);
  GLuint b = 0;
  if (pool) {
    if (const auto it = pool->free.find(size); it != pool->free.end()) {
      b = it->second;
      pool->free.erase(it);
      if (data && bytes > 0) glNamedBufferSubData(b, 0, static_cast<GLsizeiptr>(bytes), data);
    }
  }
  if (!b) {
    auto created = createCheckedBuffer(name, bytes, data);
    if (!created && pool && !pool->free.empty()) {  // the kept buffers' memory, then again
      pool->release();
      created = createCheckedBuffer(name, bytes, data);
    }
    if (!created) {
      failure = created.error();
      return 0;
    }
    b = *created;
  }
  buffers.push_back(b);
  (*ledger)[name] += bytes;
  return b;
}

void FrameBuffers::bindImage(GLuint buffer, GLuint unit) {
  GLuint t = 0;
  glCreateTextures(GL_TEXTURE_BUFFER, 1, &t);
  glTextureBuffer(t, GL_R32UI, buffer);
  textures.push_back(t);
  glBindImageTexture(unit, t, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
}

void FrameBuffers::bindTexture(GLuint buffer, GLenum format, GLuint unit) {
  GLuint t = 0;
  glCreateTextures(GL_TEXTURE_BUFFER, 1, &t);
  glTextureBuffer(t, format, buffer);
  textures.push_back(t);
  glBindTextureUnit(unit, t);
}

void clearUint(GLuint buffer, uint32_t value) {
  glClearNamedBufferData(buffer, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
}

void dispatchGroups(uint64_t groups) {
  if (groups == 0) return;
  const uint64_t x = std::min<uint64_t>(groups, 65535);
  const uint64_t y = (groups + x - 1) / x;
  glDispatchCompute(static_cast<GLuint>(x), static_cast<GLuint>(y), 1);
}

std::string glErrorText(GLenum e) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%x", e);
  return buf;
}

Result<unsigned> createCheckedBuffer(const std::string& name, uint64_t bytes, const void* data,
                                     bool staticDraw) {
  const uint64_t size = std::max<uint64_t>(bytes, 16);
  if (size > static_cast<uint64_t>(INT64_MAX))
    return makeError("--engine gl: the " + name + " buffer needs " + std::to_string(bytes) +
                     " B, beyond GL's buffer sizes");
  GLuint b = 0;
  glCreateBuffers(1, &b);
  // (the data's own bytes: a buffer rounded up to 16 B reads no further than they go)
  glNamedBufferData(b, static_cast<GLsizeiptr>(size), size == bytes ? data : nullptr,
                    staticDraw ? GL_STATIC_DRAW : GL_DYNAMIC_COPY);
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR && data && size != bytes && bytes > 0)
    glNamedBufferSubData(b, 0, static_cast<GLsizeiptr>(bytes), data);
  if (e == GL_NO_ERROR && b != 0) return b;
  glDeleteBuffers(1, &b);
  while (glGetError() != GL_NO_ERROR) {
  }
  return makeError(
      "--engine gl: out of GPU memory: the " + name + " buffer (" + std::to_string(bytes) +
      " B) could not be allocated (" +
      (e == GL_OUT_OF_MEMORY ? std::string("GL_OUT_OF_MEMORY") : "GL error " + glErrorText(e)) +
      ")");
}

}  // namespace mfr::gl
