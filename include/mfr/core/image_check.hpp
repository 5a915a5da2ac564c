// Image files before and while stb_image decodes them: the format identified as stb_image would,
// the bytes its pixel data needs computed from the header (a truncated file refused before
// anything is allocated), and a decoder that never lets stb_image's reads past the end reach a
// texture.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "mfr/core/result.hpp"

namespace mfr {

/// The formats stb_image (Debian's libstb, v2.27, every format compiled in) decodes.
enum class ImageFormat { Unknown, Png, Bmp, Gif, Psd, Pic, Jpeg, Pnm, Hdr, Tga };

/// "PNG", "BMP", ...; "PPM" stands for both binary PNM forms (P5 greys, P6 colours).
std::string_view imageFormatName(ImageFormat format);

/// The format stb_image would decode `bytes` as: its own tests in its own order (PNG, BMP, GIF,
/// PSD, PIC, JPEG, PNM, HDR, TGA last, as its test is the weakest).
ImageFormat identifyImageFormat(const uint8_t* bytes, size_t size);

/// Checks, from the header alone and before any decoder allocates, that the file holds all the
/// data its header declares, as stb_image reads it: binary PGM/PPM (width x height x channels x
/// 1 or 2 bytes after the header), TGA (raw size, or its RLE packets walked, the colour map
/// first), BMP (data offset + row stride x |height|), PSD (its sections, then the raw planes or
/// the RLE runs walked), GIF (the blocks walked to the trailer), HDR (flat, or the RLE scanlines
/// walked), PIC (its packets walked), JPEG (the segments and the entropy-coded data walked to the
/// EOI marker) and PNG (the chunks, up to IEND). stb_image reads zeros past the end of a file, and
/// some of its loaders leave the rest of the image as uninitialised heap memory: such a file is
/// refused, one line naming `what`, e.g. "tex.ppm: PPM pixel data is 48 of 768 bytes the header
/// declares (truncated?)". A palette BMP whose pixels index past its palette is refused too
/// (stb_image would read colours from uninitialised stack memory). A header stb_image refuses by
/// itself, or one larger than it decodes (2^24 pixels a side), is left to it: ok.
Result<void> checkImageData(const uint8_t* bytes, size_t size, const std::string& what);

/// A decoded image: 4 channels (RGBA) of 8 or 16 bits, rows top to bottom.
struct DecodedImage {
  int width = 0;
  int height = 0;
  int bits = 8;                // 16: two bytes (native order) a channel
  int fileChannels = 0;        // the channels the file holds (1 grey .. 4 RGBA)
  std::vector<uint8_t> bytes;  // width * height * 4 * bits / 8
};

/// Decodes an image file held in memory with stb_image, after checkPngChunks, checkImageData and
/// the header's size against kMaxImageDimension. `keep16Bits`: a 16-bit PNG, PSD or PGM/PPM keeps
/// its 16 bits (as tinygltf's loader does). A 16-bit PGM/PPM is decoded in its own channels and
/// byte order (most significant first), which stb_image v2.27 gets wrong. Errors are one line
/// naming `what`, and never without a reason (stb_image's can be empty).
Result<DecodedImage> decodeImage(const uint8_t* bytes, size_t size, const std::string& what,
                                 bool keep16Bits = false);

/// The decoding step of decodeImage alone, without its checks (the second line of defence, and
/// what tests exercise it through): stb_image reads the bytes through callbacks that hand it
/// zeros for any read past the end, so that no buffer of it is left uninitialised, and an image
/// for which it read past the end is refused ("stb_image read past the end of the data
/// (truncated?)").
Result<DecodedImage> decodeImageUnchecked(const uint8_t* bytes, size_t size,
                                          const std::string& what, bool keep16Bits = false);

}  // namespace mfr
