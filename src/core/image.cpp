#include "mfr/core/image.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>

#include "mfr/core/atomic_file.hpp"
#include "mfr/core/color.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/image_check.hpp"
#include "mfr/core/quote.hpp"

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

Result<void> checkFinite(const ImageRGB& image, const std::string& what) {
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = image.pixels[i][c];
      if (std::isfinite(v)) continue;
      const size_t w = static_cast<size_t>(std::max(image.width, 1));
      const char* value = std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
      return makeError(what + ": pixel (" + std::to_string(i % w) + ", " + std::to_string(i / w) +
                       ") is not finite (" + value + " in " + "rgb"[c] +
                       "): the image must hold finite values");
    }
  return {};
}

ImageRGB decodeSrgb(const Image8& image) {
  ImageRGB out(image.width, image.height);
  for (size_t i = 0; i < out.pixels.size(); ++i)
    out.pixels[i] = {decodeSrgb8(image.rgba[i * 4 + 0]), decodeSrgb8(image.rgba[i * 4 + 1]),
                     decodeSrgb8(image.rgba[i * 4 + 2])};
  return out;
}

Result<void> writePng(const std::string& path, const Image8& image) {
  const std::string what = echoPath(path);  // a path of any length, cut for the message
  if (image.width <= 0 || image.height <= 0) return makeError(what + ": empty image");
  // encoded in memory, then written atomically: never a truncated PNG at `path`
  std::string encoded;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &encoded, image.width, image.height, 4, image.rgba.data(),
                              image.width * 4))
    return makeError(what + ": cannot encode PNG");
  auto written = writeFileAtomically(path, encoded);
  if (!written) {  // "PATH: cannot open for writing (...)" -> "PATH: cannot write PNG (...)"
    std::string reason = written.error().message;
    if (reason.rfind(what + ": ", 0) == 0) reason.erase(0, what.size() + 2);
    return makeError(what + ": cannot write PNG: " + reason);
  }
  return {};
}

Result<void> writePfm(const std::string& path, const ImageRGB& image) {
  const std::string what = echoPath(path);
  if (image.width <= 0 || image.height <= 0) return makeError(what + ": empty image");
  std::string bytes =
      "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
  const size_t header = bytes.size(), row = static_cast<size_t>(image.width) * 12;
  bytes.resize(header + row * static_cast<size_t>(image.height));
  for (int y = 0; y < image.height; ++y) {  // the bottom row first
    char* out = bytes.data() + header + row * static_cast<size_t>(image.height - 1 - y);
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c, out += 4) {
        uint32_t word = std::bit_cast<uint32_t>(image.at(x, y)[c]);
        if constexpr (std::endian::native == std::endian::big) word = __builtin_bswap32(word);
        std::memcpy(out, &word, 4);
      }
  }
  auto written = writeFileAtomically(path, bytes);
  if (!written) {
    std::string reason = written.error().message;
    if (reason.rfind(what + ": ", 0) == 0) reason.erase(0, what.size() + 2);
    return makeError(what + ": cannot write PFM: " + reason);
  }
  return {};
}

const char* imageExtension(OutputImageFormat format) {
  return format == OutputImageFormat::Pfm ? ".pfm" : ".png";
}

Result<OutputImageFormat> imageOutputFormat(const std::string& option, const std::string& path,
                                            std::initializer_list<OutputImageFormat> accepted) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status) &&
      !std::filesystem::is_directory(status) && accepted.size() > 0)
    return *accepted.begin();  // /dev/stdout, a pipe: nothing to name the format by
  const std::string ext = lowercaseExtension(path);
  std::string list;
  for (OutputImageFormat f : accepted) {
    if (ext == imageExtension(f)) return f;
    list += (list.empty() ? "" : ", ") + std::string(imageExtension(f));
  }
  const std::string given = std::filesystem::path(path).extension().string();
  return makeError(option + " " + quoteInput(path, 256) + ": " +
                   (given.empty() ? "no image extension"
                                  : "unsupported image extension " + quoteInput(given, 40)) +
                   " (accepted: " + list + ")");
}

Result<void> checkPngChunks(const uint8_t* bytes, size_t size, const std::string& what) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || !std::equal(bytes, bytes + 8, kSignature)) return {};
  size_t offset = 8;
  while (size - offset >= 8) {  // length and type; data and CRC follow
    const uint32_t length = uint32_t{bytes[offset]} << 24 | uint32_t{bytes[offset + 1]} << 16 |
                            uint32_t{bytes[offset + 2]} << 8 | uint32_t{bytes[offset + 3]};
    const std::string_view type(reinterpret_cast<const char*>(bytes + offset + 4), 4);
    const size_t left = size - offset - 8;
    if (length > left || left - length < 4)
      return makeError(what + ": PNG chunk " + quoteInput(type) + " declares " +
                       std::to_string(length) + " bytes, the file has " +
                       std::to_string(left >= 4 ? left - 4 : 0) + " left");
    if (type == "IHDR" && length >= 8) {  // the size, before any decoder sees it
      const uint8_t* d = bytes + offset + 8;
      const uint32_t width =
          uint32_t{d[0]} << 24 | uint32_t{d[1]} << 16 | uint32_t{d[2]} << 8 | d[3];
      const uint32_t height =
          uint32_t{d[4]} << 24 | uint32_t{d[5]} << 16 | uint32_t{d[6]} << 8 | d[7];
      MFR_TRY(checkImageDimensions(
          static_cast<int>(std::min<uint32_t>(width, static_cast<uint32_t>(INT32_MAX))),
          static_cast<int>(std::min<uint32_t>(height, static_cast<uint32_t>(INT32_MAX))), what));
    }
    offset += 12 + size_t{length};
    if (type == "IEND") break;
  }
  return {};
}

Result<Image8> readPng(const std::string& path,
                       const std::function<Result<void>(int width, int height)>& beforeDecode) {
  // a regular file (a FIFO is refused, not waited on) of less than 2 GiB
  const std::string what = echoPath(path);  // a path of any length, cut for the message
  auto bytes = readRegularFileBytes(path, what, std::numeric_limits<int>::max());
  if (!bytes) return bytes.error();
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes->size() < 8 || !std::equal(bytes->begin(), bytes->begin() + 8, kSignature))
    return makeError(what + ": not a PNG file");
  MFR_TRY(checkPngChunks(bytes->data(), bytes->size(), what));
  MFR_TRY(checkImageData(bytes->data(), bytes->size(), what));  // every chunk, up to IEND
  const auto size = static_cast<int>(bytes->size());
  int w = 0, h = 0, n = 0;
  if (!stbi_info_from_memory(bytes->data(), size, &w, &h, &n)) {
    const char* reason = stbi_failure_reason();
    return makeError(what + ": not a readable image" +
                     (reason && *reason ? " (" + oneLine(reason) + ")" : std::string()));
  }
  MFR_TRY(checkImageDimensions(w, h, what));  // from the header, before decoding
  if (beforeDecode) MFR_TRY(beforeDecode(w, h));
  auto decoded = decodeImageUnchecked(bytes->data(), bytes->size(), what);
  if (!decoded) return decoded.error();
  Image8 image;
  image.width = decoded->width;
  image.height = decoded->height;
  image.rgba = std::move(decoded->bytes);
  return image;
}

}  // namespace mfr
