#include "image_texture.hpp"

#include <cstring>

#include <GLFW/glfw3.h>
#include <imgui.h>

namespace mfr::view {

ImageTexture::~ImageTexture() = default;  // destroy() runs while the window's context is current

void ImageTexture::upload(const Image8& image) {
  if (texture_ == 0) {
    GLuint t = 0;
    glGenTextures(1, &t);
    texture_ = t;
  }
  glBindTexture(GL_TEXTURE_2D, texture_);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               image.rgba.data());
  width_ = image.width;
  height_ = image.height;
}

void ImageTexture::draw() const {
  if (texture_ == 0) return;
  ImGui::GetBackgroundDrawList()->AddImage(
      reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture_)), ImVec2(0.0f, 0.0f),
      ImVec2(static_cast<float>(width_), static_cast<float>(height_)));
}

void ImageTexture::destroy() {
  if (texture_ != 0) {
    GLuint t = texture_;
    glDeleteTextures(1, &t);
  }
  texture_ = 0;
}

Image8 readWindow(int framebufferHeight, int w, int h) {
  Image8 image;
  image.width = w;
  image.height = h;
  image.rgba.resize(static_cast<size_t>(w) * h * 4);
  std::vector<uint8_t> rows(image.rgba.size());
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, framebufferHeight - h, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
  const size_t stride = static_cast<size_t>(w) * 4;
  for (int y = 0; y < h; ++y)  // GL's rows are bottom to top
    std::memcpy(image.rgba.data() + y * stride, rows.data() + (h - 1 - y) * stride, stride);
  for (size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;
  return image;
}

}  // namespace mfr::view
