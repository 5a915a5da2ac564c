#include "mfr/core/image.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "mfr/core/color.hpp"

#include <stb_image.h>
#include <stb_image_write.h>

namespace mfr {

Image8 encodeSrgb(const ImageRGB& image) {
  Image8 out;
  out.width = image.width;
  out.height = image.height;
  out.rgba.resize(image.pixels.size() * 4);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    out.rgba[i * 4 + 0] = encodeSrgb8(image.pixels[i].r);
    out.rgba[i * 4 + 1] = encodeSrgb8(image.pixels[i].g);
    out.rgba[i * 4 + 2] = encodeSrgb8(image.pixels[i].b);
    out.rgba[i * 4 + 3] = 255;
  }
  return out;
}

ImageRGB decodeSrgb(const Image8& image) {
  ImageRGB out(image.width, image.height);
  for (size_t i = 0; i < out.pixels.size(); ++i)
    out.pixels[i] = {decodeSrgb8(image.rgba[i * 4 + 0]), decodeSrgb8(image.rgba[i * 4 + 1]),
                     decodeSrgb8(image.rgba[i * 4 + 2])};
  return out;
}

Result<void> writePng(const std::string& path, const Image8& image) {
  if (image.width <= 0 || image.height <= 0) return makeError(path + ": empty image");
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (!stbi_write_png(path.c_str(), image.width, image.height, 4, image.rgba.data(),
                      image.width * 4))
    return makeError(path + ": cannot write PNG");
  return {};
}

Result<Image8> readPng(const std::string& path) {
  if (!std::filesystem::exists(path)) return makeError(path + ": no such file");
  {
    static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char head[8] = {};
    std::ifstream file(path, std::ios::binary);
    if (!file.read(reinterpret_cast<char*>(head), 8) || !std::equal(head, head + 8, kSignature))
      return makeError(path + ": not a PNG file");
  }
  int w = 0, h = 0, n = 0;
  if (!stbi_info(path.c_str(), &w, &h, &n)) return makeError(path + ": not a readable image");
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 4);
  if (!data) return makeError(path + ": " + stbi_failure_reason());
  Image8 image;
  image.width = w;
  image.height = h;
  image.rgba.assign(data, data + static_cast<size_t>(w) * h * 4);
  stbi_image_free(data);
  return image;
}

}  // namespace mfr
