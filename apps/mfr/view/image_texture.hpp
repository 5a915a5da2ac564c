// The rendered image in the window's GL context: an RGBA8 texture drawn 1:1 (nearest texels) at the
// window's top-left corner, and the read-back of the window for screenshots.
#pragma once

#include <cstdint>

#include "mfr/core/image.hpp"

namespace mfr::view {

class ImageTexture {
 public:
  ImageTexture() = default;
  ~ImageTexture();
  ImageTexture(const ImageTexture&) = delete;
  ImageTexture& operator=(const ImageTexture&) = delete;
  /// Uploads an sRGB8 image (the window's context must be current).
  void upload(const Image8& image);
  /// Queues the image, at its size, on ImGui's background draw list.
  void draw() const;
  int width() const { return width_; }
  int height() const { return height_; }
  /// Frees the texture (the window's context must be current).
  void destroy();

 private:
  uint32_t texture_ = 0;
  int width_ = 0, height_ = 0;
};

/// Reads the top-left w x h pixels of the window's back buffer (rows top to bottom, alpha 255).
Image8 readWindow(int framebufferHeight, int w, int h);

}  // namespace mfr::view
