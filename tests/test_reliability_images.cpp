// Image files as stb_image reads them (mfr/core/image_check.hpp): for every format it decodes
// (PNG, BMP, GIF, PSD, PIC, JPEG, PGM/PPM, HDR, TGA), a small valid file loads and every shorter
// cut of it is refused with one line naming the file, before anything is decoded; glTF and OBJ
// textures and `mfr metrics` go through the same checks; nothing uninitialised reaches a texture.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_timeout.hpp"
#include "error_assertions.hpp"
#include "gltf_textured_quad.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/image_check.hpp"
#include "mfr/scene/load.hpp"

#include <stb_image_write.h>  // Debian libstb (linked through the library)

namespace {

namespace fs = std::filesystem;
using mfr::test::cleanError;
using mfr::test::CliRun;
using mfr::test::contains;

fs::path scratch() {
  static const fs::path dir = mfr::test::processTempDir("mfr_reliability_images_test");
  return dir;
}

std::string write(const std::string& name, const std::string& bytes) {
  return mfr::test::writeFile(scratch() / name, bytes);
}

/// An error of the library: one line, "WHAT: <a reason>".
::testing::AssertionResult oneLineNaming(const std::string& message, const std::string& what) {
  if (message.find('\n') != std::string::npos || message.find('\r') != std::string::npos)
    return ::testing::AssertionFailure() << "not one line: " << message;
  if (message.rfind(what + ": ", 0) != 0 || message.size() <= what.size() + 2)
    return ::testing::AssertionFailure()
           << "does not name " << what << " with a reason: '" << message << "'";
  return ::testing::AssertionSuccess();
}

// ---- small valid files of every format

constexpr int kWidth = 16, kHeight = 16;  // wide enough for HDR's run-length scanlines

/// 8-bit RGB texels, a different colour each.
std::vector<uint8_t> texels(int width = kWidth, int height = kHeight) {
  std::vector<uint8_t> rgb(static_cast<size_t>(width) * height * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>(i * 7 + i / 3);
  return rgb;
}

void appendTo(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                             static_cast<size_t>(size));
}

std::string stbPng() {
  std::string out;
  stbi_write_png_to_func(appendTo, &out, kWidth, kHeight, 3, texels().data(), kWidth * 3);
  return out;
}
std::string stbBmp() {  // 24 bits, rows of 48 bytes: no padding
  std::string out;
  stbi_write_bmp_to_func(appendTo, &out, kWidth, kHeight, 3, texels().data());
  return out;
}
std::string stbTgaRle() {
  std::string out;
  stbi_write_tga_with_rle = 1;
  stbi_write_tga_to_func(appendTo, &out, kWidth, kHeight, 3, texels().data());
  return out;
}
std::string stbJpeg() {
  std::string out;
  stbi_write_jpg_to_func(appendTo, &out, kWidth, kHeight, 3, texels().data(), 90);
  return out;
}
std::string stbHdr(int width) {  // width >= 8: run-length scanlines; below: flat
  std::vector<float> values(static_cast<size_t>(width) * kHeight * 3);
  for (size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i % 13) / 4.0f;
  std::string out;
  stbi_write_hdr_to_func(appendTo, &out, width, kHeight, 3, values.data());
  return out;
}

std::string ppm() {
  const std::vector<uint8_t> rgb = texels();
  return "P6\n" + std::to_string(kWidth) + " " + std::to_string(kHeight) + "\n255\n" +
         std::string(rgb.begin(), rgb.end());
}
std::string pgm16() {
  std::string out = "P5 " + std::to_string(kWidth) + " " + std::to_string(kHeight) + " 65535\n";
  for (int i = 0; i < kWidth * kHeight; ++i)
    out += {static_cast<char>(i), static_cast<char>(i * 3)};
  return out;
}

std::string le16(unsigned v) {
  return {static_cast<char>(v & 0xff), static_cast<char>(v >> 8)};
}
std::string be16(unsigned v) {
  return {static_cast<char>(v >> 8), static_cast<char>(v & 0xff)};
}
std::string be32(unsigned v) {
  return be16(v >> 16) + be16(v & 0xffff);
}

std::string tgaRaw() {  // uncompressed true colour, BGR
  std::string out = std::string("\0\0\x02", 3) + std::string(9, '\0') + le16(kWidth) +
                    le16(kHeight) + "\x18\x20";  // top row first
  const std::vector<uint8_t> rgb = texels();
  return out + std::string(rgb.begin(), rgb.end());
}

std::string psd(bool rle) {  // RGB, 8 bits, planar
  std::string out = "8BPS" + be16(1) + std::string(6, '\0') + be16(3) + be32(kHeight) +
                    be32(kWidth) + be16(8) + be16(3) + be32(0) + be32(0) + be32(0) +
                    be16(rle ? 1 : 0);
  const std::vector<uint8_t> rgb = texels();
  if (rle)
    for (int row = 0; row < kHeight * 3; ++row) out += be16(kWidth + 1);  // byte counts
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < kHeight; ++y) {
      if (rle) out += static_cast<char>(kWidth - 1);  // a literal run of the whole row
      for (int x = 0; x < kWidth; ++x)
        out += static_cast<char>(rgb[(static_cast<size_t>(y) * kWidth + x) * 3 + c]);
    }
  return out;
}

std::string gif() {  // 4 colours; every pixel coded after a clear code (3-bit codes)
  std::string out = "GIF89a" + le16(kWidth) + le16(kHeight) + "\x81" + std::string(2, '\0');
  for (int i = 0; i < 4; ++i)
    out += {static_cast<char>(60 * i), static_cast<char>(200 - 40 * i), static_cast<char>(30 * i)};
  out += "\x2c" + le16(0) + le16(0) + le16(kWidth) + le16(kHeight) + std::string(1, '\0');
  out += '\x02';  // LZW minimum code size: clear 4, end 5
  std::vector<int> codes;
  for (int i = 0; i < kWidth * kHeight; ++i) codes.insert(codes.end(), {4, i % 4});
  codes.push_back(5);
  std::string data;
  uint32_t bits = 0;
  int count = 0;
  for (int code : codes) {
    bits |= static_cast<uint32_t>(code) << count;
    count += 3;
    while (count >= 8) {
      data += static_cast<char>(bits & 0xff);
      bits >>= 8;
      count -= 8;
    }
  }
  if (count) data += static_cast<char>(bits & 0xff);
  for (size_t at = 0; at < data.size(); at += 255) {
    const std::string block = data.substr(at, 255);
    out += static_cast<char>(block.size()) + block;
  }
  return out + std::string(1, '\0') + "\x3b";
}

std::string pic() {  // Softimage PIC: one uncompressed RGB packet
  std::string out = "\x53\x80\xF6\x34" + std::string(84, '\0') + "PICT" + be16(kWidth) +
                    be16(kHeight) + std::string(8, '\0');
  out += std::string("\0\x08\0\xE0", 4);
  const std::vector<uint8_t> rgb = texels();
  return out + std::string(rgb.begin(), rgb.end());
}

struct Sample {
  std::string name;  // file name, format shown in messages
  std::string format;
  std::string bytes;
};

std::vector<Sample> samples() {
  return {{"tex.png", "PNG", stbPng()},    {"tex.bmp", "BMP", stbBmp()},
          {"rle.tga", "TGA", stbTgaRle()}, {"raw.tga", "TGA", tgaRaw()},
          {"tex.jpg", "JPEG", stbJpeg()},  {"rle.hdr", "HDR", stbHdr(kWidth)},
          {"flat.hdr", "HDR", stbHdr(4)},  {"tex.ppm", "PPM", ppm()},
          {"tex.pgm", "PGM", pgm16()},     {"raw.psd", "PSD", psd(false)},
          {"rle.psd", "PSD", psd(true)},   {"tex.gif", "GIF", gif()},
          {"tex.pic", "PIC", pic()}};
}

const uint8_t* data(const std::string& bytes) {
  return reinterpret_cast<const uint8_t*>(bytes.data());
}

// ---- the library

TEST(ReliabilityImages, EveryFormatLoadsWhole) {
  for (const Sample& s : samples()) {
    EXPECT_EQ(mfr::imageFormatName(mfr::identifyImageFormat(data(s.bytes), s.bytes.size())),
              s.format == "PGM" ? "PPM" : s.format)
        << s.name;
    auto image = mfr::decodeImage(data(s.bytes), s.bytes.size(), s.name);
    ASSERT_TRUE(image.ok()) << s.name << ": " << image.error().message;
    EXPECT_EQ(image->width, s.name.ends_with(".hdr") && contains(s.name, "flat") ? 4 : kWidth);
    EXPECT_EQ(image->height, kHeight) << s.name;
    EXPECT_EQ(image->bytes.size(), static_cast<size_t>(image->width) * image->height * 4);
  }
  // the texels where the format keeps them exactly
  for (const std::string name :
       {"tex.png", "tex.bmp", "rle.tga", "raw.tga", "tex.ppm", "raw.psd", "rle.psd", "tex.pic"}) {
    for (const Sample& s : samples()) {
      if (s.name != name) continue;
      auto image = mfr::decodeImage(data(s.bytes), s.bytes.size(), s.name);
      ASSERT_TRUE(image.ok());
      const std::vector<uint8_t> rgb = texels();
      const bool bgr = name == "raw.tga";  // written in file order (BGR), as a TGA holds it
      for (size_t i = 0; i < rgb.size() / 3; ++i)
        for (size_t c = 0; c < 3; ++c)
          ASSERT_EQ(image->bytes[i * 4 + (bgr ? 2 - c : c)], rgb[i * 3 + c]) << name << " " << i;
    }
  }
}

TEST(ReliabilityImages, SixteenBitPgmDecodesItsSamplesMostSignificantByteFirst) {
  // stb_image v2.27 converted a 16-bit PNM's channels with its 8-bit converter when asked for
  // RGBA (the texels came out interleaved with heap memory read past its buffer), and read the
  // samples in the machine's byte order (Netpbm: most significant byte first)
  const std::string bytes = pgm16();
  for (bool keep16 : {false, true}) {
    auto image = mfr::decodeImage(data(bytes), bytes.size(), "tex.pgm", keep16);
    ASSERT_TRUE(image.ok()) << image.error().message;
    ASSERT_EQ(image->bits, keep16 ? 16 : 8);
    ASSERT_EQ(image->fileChannels, 1);
    for (int i = 0; i < kWidth * kHeight; ++i) {
      uint16_t rgba[4];
      for (int c = 0; c < 4; ++c)
        if (keep16)
          std::memcpy(&rgba[c], image->bytes.data() + (i * 4 + c) * 2, 2);
        else
          rgba[c] = image->bytes[static_cast<size_t>(i) * 4 + c];
      const unsigned high = i & 0xff, low = (i * 3) & 0xff;  // the sample's bytes, in file order
      const unsigned grey = keep16 ? (high << 8 | low) : high, opaque = keep16 ? 0xFFFF : 0xFF;
      ASSERT_TRUE(rgba[0] == grey && rgba[1] == grey && rgba[2] == grey && rgba[3] == opaque)
          << i << ": " << rgba[0] << " " << rgba[1] << " " << rgba[2] << " " << rgba[3];
    }
  }
}

TEST(ReliabilityImages, EveryShorterCutOfEveryFormatIsRefusedInOneLine) {
  for (const Sample& s : samples()) {
    for (size_t size = 0; size < s.bytes.size(); ++size) {
      auto image = mfr::decodeImage(data(s.bytes), size, s.name);
      ASSERT_FALSE(image.ok()) << s.name << " cut at " << size << " of " << s.bytes.size();
      ASSERT_TRUE(oneLineNaming(image.error().message, s.name)) << "cut at " << size;
    }
    // cut in its pixel data: refused by the check, naming the format
    const size_t half = s.bytes.size() * 3 / 4;
    auto checked = mfr::checkImageData(data(s.bytes), half, s.name);
    ASSERT_FALSE(checked.ok()) << s.name;
    EXPECT_TRUE(contains(checked.error().message, s.name + ": " + s.format + " ") &&
                contains(checked.error().message, "(truncated?)"))
        << checked.error().message;
    EXPECT_TRUE(mfr::checkImageData(data(s.bytes), s.bytes.size(), s.name).ok()) << s.name;
  }
}

TEST(ReliabilityImages, TruncatedPpmMessageGivesTheBytesTheHeaderDeclares) {
  const std::string bytes = ppm();
  const size_t header = bytes.size() - kWidth * kHeight * 3;
  auto checked = mfr::checkImageData(data(bytes), header + 48, "tex.ppm");
  ASSERT_FALSE(checked.ok());
  EXPECT_EQ(checked.error().message,
            "tex.ppm: PPM pixel data is 48 of 768 bytes the header declares (truncated?)");
}

TEST(ReliabilityImages, HugePpmHeaderWithAHundredBytesIsRefusedAtOnce) {
  for (const char* maxValue : {"255", "65535"}) {
    const std::string bytes =
        "P6\n16384 16384\n" + std::string(maxValue) + "\n" + std::string(100, '\x7f');
    const auto start = std::chrono::steady_clock::now();
    auto image = mfr::decodeImage(data(bytes), bytes.size(), "huge.ppm");
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_FALSE(image.ok());
    EXPECT_TRUE(contains(image.error().message, "huge.ppm: PPM pixel data is 100 of ") &&
                contains(image.error().message, "(truncated?)"))
        << image.error().message;
    EXPECT_LT(seconds, 0.1);
  }
}

TEST(ReliabilityImages, StbReadingPastTheEndIsRefusedWithoutUninitialisedTexels) {
  // the second line of defence alone: the decoder without the checks before it
  for (const std::string& bytes : {ppm(), tgaRaw(), stbTgaRle(), stbHdr(4)}) {
    auto whole = mfr::decodeImageUnchecked(data(bytes), bytes.size(), "tex");
    ASSERT_TRUE(whole.ok()) << whole.error().message;
    auto cut = mfr::decodeImageUnchecked(data(bytes), bytes.size() - 100, "tex");
    ASSERT_FALSE(cut.ok());
    EXPECT_EQ(cut.error().message, "tex: stb_image read past the end of the data (truncated?)");
  }
}

TEST(ReliabilityImages, BmpPixelsIndexingPastThePaletteAreRefused) {
  // 8 bits a pixel, a palette of 2 colours: stb_image would read colour 5 from uninitialised
  // stack memory
  const int width = 4, height = 2, palette = 2;
  const unsigned offset = 14 + 40 + palette * 4, size = offset + width * height;
  std::string bmp = "BM" + le16(size & 0xffff) + le16(size >> 16) + std::string(4, '\0') +
                    le16(offset) + le16(0) + le16(40) + le16(0) + le16(width) + le16(0) +
                    le16(height) + le16(0) + le16(1) + le16(8) + std::string(24, '\0');
  bmp += std::string("\0\0\0\0\xff\xff\xff\0", 8);
  const std::string pixels("\0\1\0\1\1\0\5\0", 8);
  const std::string good = bmp + std::string("\0\1\0\1\1\0\1\0", 8), bad = bmp + pixels;
  EXPECT_TRUE(mfr::decodeImage(data(good), good.size(), "pal.bmp").ok());
  auto image = mfr::decodeImage(data(bad), bad.size(), "pal.bmp");
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.error().message,
            "pal.bmp: BMP pixel (2, 1) of its data is colour 5 of a palette of 2 colours");
}

TEST(ReliabilityImages, GifWithoutAnImageIsRefusedWithAReason) {
  const std::string bytes = "GIF89a" + le16(1) + le16(1) + std::string(3, '\0') + "\x3b";
  auto image = mfr::decodeImage(data(bytes), bytes.size(), "empty.gif");
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.error().message, "empty.gif: GIF holds no image");
}

// ---- mfr metrics (readPng)

TEST(ReliabilityImages, MetricsOfACutPngGivesAReason) {
  // a cut that leaves no room for the next chunk's header: stb_image read zeros, took them for a
  // chunk of type 0 and gave an empty reason ("mfr: error: trunc.png: ")
  const std::string png = stbPng();
  const std::string whole = write("whole.png", png);
  for (size_t size = 8; size < png.size(); ++size) {
    auto read = mfr::readPng(write("cut.png", png.substr(0, size)));
    ASSERT_FALSE(read.ok());
    ASSERT_TRUE(oneLineNaming(read.error().message, (scratch() / "cut.png").string()))
        << "cut at " << size;
  }
  const std::string cut = write("trunc.png", png.substr(0, png.size() - 12));  // before IEND
  const CliRun r = mfr::test::runCliTimed("metrics " + cut + " " + whole, scratch());
  EXPECT_TRUE(cleanError(r, {"trunc.png: PNG data ends after", "before its IEND chunk"}));
}

// ---- scene textures

/// The textured quad of gltf_textured_quad.hpp with its image in the file `image` next to it.
std::string gltfWithImage(const std::string& name, const std::string& image,
                          const std::string& imageBytes) {
  nlohmann::json doc = nlohmann::json::parse(mfr::test::texturedQuadGltf(nullptr));
  doc["images"][0]["uri"] = image;
  write(image, imageBytes);
  return write(name, doc.dump());
}

std::string objWithTexture(const std::string& name, const std::string& image,
                           const std::string& imageBytes) {
  write(image, imageBytes);
  write(name + ".mtl", "newmtl m\nKd 1 1 1\nmap_Kd " + image + "\n");
  return write(name, "mtllib " + name +
                         ".mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
                         "vt 0 1\nusemtl m\nf 1/1 2/2 3/3\n");
}

TEST(ReliabilityImages, GltfWithATruncatedTextureIsRefused) {
  const std::string bytes = ppm();
  const size_t header = bytes.size() - kWidth * kHeight * 3;
  const std::string gltf = gltfWithImage("cut_ppm.gltf", "cut.ppm", bytes.substr(0, header + 48));
  auto scene = mfr::loadScene(gltf);
  ASSERT_FALSE(scene.ok());
  EXPECT_TRUE(oneLineNaming(scene.error().message, gltf));
  EXPECT_TRUE(contains(scene.error().message,
                       "image 0 ('cut.ppm'): PPM pixel data is 48 of 768 bytes the header "
                       "declares (truncated?)"))
      << scene.error().message;
  // the whole file loads, as its texels
  const std::string whole = gltfWithImage("whole_ppm.gltf", "whole.ppm", bytes);
  auto loaded = mfr::loadScene(whole);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  ASSERT_EQ(loaded->textures.size(), 1u);
  EXPECT_EQ(loaded->textures[0].rgba[4], texels()[3]);
}

TEST(ReliabilityImages, ObjWithATruncatedTextureIsRefused) {
  const std::string bytes = tgaRaw();
  const std::string obj = objWithTexture("cut_tga.obj", "cut.tga", bytes.substr(0, 18 + 48));
  auto scene = mfr::loadScene(obj);
  ASSERT_FALSE(scene.ok());
  EXPECT_TRUE(oneLineNaming(scene.error().message, obj));
  EXPECT_TRUE(contains(scene.error().message,
                       "map_Kd 'cut.tga': TGA pixel data is 48 of 768 bytes the header declares"))
      << scene.error().message;
}

TEST(ReliabilityImages, RenderingATruncatedTextureUnderMallocPerturbIsRefusedEachTime) {
  // the case: 16 of 256 pixels; the missing texels were heap memory, different each run
  const std::string ppmBytes = ppm(), tgaBytes = tgaRaw();
  const std::string cutPpm = ppmBytes.substr(0, ppmBytes.size() - kWidth * kHeight * 3 + 48);
  const std::string cutTga = tgaBytes.substr(0, 18 + 48);
  for (const auto& [gltf, image] :
       {std::pair{gltfWithImage("perturb_ppm.gltf", "perturb.ppm", cutPpm), "perturb.ppm"},
        std::pair{gltfWithImage("perturb_tga.gltf", "perturb.tga", cutTga), "perturb.tga"}}) {
    for (const char* perturb : {"1", "254"}) {
      const fs::path out = scratch() / "perturb.png";
      fs::remove(out);
      ::setenv("MALLOC_PERTURB_", perturb, 1);
      const CliRun r = mfr::test::runCliTimed(
          "render " + gltf + " --width 32 --height 32 -q -o " + out.string(), scratch());
      ::unsetenv("MALLOC_PERTURB_");
      EXPECT_TRUE(cleanError(r, {gltf, image, "pixel data is 48 of 768 bytes", "(truncated?)"}))
          << "MALLOC_PERTURB_=" << perturb;
      EXPECT_FALSE(fs::exists(out));
    }
  }
}

TEST(ReliabilityImages, HugePpmTextureIsRefusedFastWithoutAllocating) {
  // a header claiming 16384 x 16384 with 100 bytes of data: it cost 1 GB and 14 s (the 16-bit
  // form 1.5 GiB), within the default memory limit of a 4 GiB address space
  for (const char* maxValue : {"255", "65535"}) {
    const std::string bytes =
        "P6\n16384 16384\n" + std::string(maxValue) + "\n" + std::string(100, '\x7f');
    const std::string obj = objWithTexture("huge_" + std::string(maxValue) + ".obj",
                                           "huge_" + std::string(maxValue) + ".ppm", bytes);
    const auto start = std::chrono::steady_clock::now();
    const CliRun r = mfr::test::runCliTimed("info " + obj + " --width 64 --height 64 -q", scratch(),
                                            mfr::test::capped(30, 4u << 20));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_TRUE(cleanError(r, {obj, "PPM pixel data is 100 of ", "(truncated?)"}));
    EXPECT_LT(seconds, 1.0) << maxValue;
  }
}

}  // namespace
