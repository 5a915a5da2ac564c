// Images: linear float RGB for compositing and metrics, sRGB8 RGBA for files.
#pragma once

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/result.hpp"

namespace mfr {

/// Linear-light RGB image, rows top to bottom.
struct ImageRGB {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> pixels;

  ImageRGB() = default;
  ImageRGB(int w, int h, glm::vec3 fill = glm::vec3(0.0f))
      : width(w), height(h), pixels(static_cast<size_t>(w) * static_cast<size_t>(h), fill) {}
  glm::vec3& at(int x, int y) { return pixels[static_cast<size_t>(y) * width + x]; }
  const glm::vec3& at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

/// 8-bit RGBA image as stored in a PNG (sRGB-encoded colour), rows top to bottom.
struct Image8 {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4
};

/// sRGB-encodes a linear image (alpha 255).
Image8 encodeSrgb(const ImageRGB& image);

/// Checks that every value of a linear image is a finite number (a NaN would encode as black and
/// measure as no error at all). Error, naming `what` and the first bad pixel in row order:
/// "test: pixel (3, 0) is not finite (nan in g): the image must hold finite values".
Result<void> checkFinite(const ImageRGB& image, const std::string& what);
/// Decodes an sRGB8 image to linear floats (alpha ignored).
ImageRGB decodeSrgb(const Image8& image);

/// Walks the chunks of a PNG held in memory (after the 8-byte signature, up to IEND): every chunk's
/// declared length must fit in the bytes that follow. stb_image grows its buffer to a chunk's
/// declared length before reading it, so without this a 100-byte file makes it allocate 2 GiB.
/// An IHDR chunk's width and height are checked against kMaxImageDimension here too (stb_image
/// refuses a large header only as an "unknown format"). Not a PNG (no signature): ok, nothing to
/// check. Errors name `what`.
Result<void> checkPngChunks(const uint8_t* bytes, size_t size, const std::string& what);

Result<void> writePng(const std::string& path, const Image8& image);

/// Writes a linear image as a Portable Float Map: "PF\n<width> <height>\n-1.0\n" (the negative
/// scale marks little-endian), then the RGB float32 triples row by row from the bottom row up.
/// The values are written as they are (no sRGB encoding, no clamping). Atomic, as writePng.
Result<void> writePfm(const std::string& path, const ImageRGB& image);

/// The image file formats mfr writes, chosen by a file name's extension.
enum class OutputImageFormat { Png, Pfm };

/// ".png", ".pfm".
const char* imageExtension(OutputImageFormat format);

/// The format of image output `path`, given by option `option` ("--out"), from its extension
/// (case-insensitive) among `accepted`; an existing special file (/dev/stdout, a pipe) takes the
/// first accepted format. Checked before any work, so that no output is written in a format its
/// name does not say. Error (one line, naming the option, the path and the accepted extensions):
/// "--out 'x.exr': unsupported image extension '.exr' (accepted: .png, .pfm)".
Result<OutputImageFormat> imageOutputFormat(const std::string& option, const std::string& path,
                                            std::initializer_list<OutputImageFormat> accepted);

/// `beforeDecode`, when given, is called with the header's width and height before the pixels are
/// decoded (a caller's memory pre-flight): its error is readPng's.
Result<Image8> readPng(const std::string& path,
                       const std::function<Result<void>(int width, int height)>& beforeDecode = {});

}  // namespace mfr
