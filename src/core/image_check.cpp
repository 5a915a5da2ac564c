// Image files checked as stb_image v2.27 reads them (see include/mfr/core/image_check.hpp). Each
// check follows the loader of /usr/include/stb/stb_image.h step by step: where the loader reads
// its pixel data, the check computes how many bytes that takes (or walks the packets, runs,
// blocks or segments), from the header alone, before anything is allocated.
#include "mfr/core/image_check.hpp"

#include <algorithm>
#include <bit>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "mfr/core/file_access.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/quote.hpp"

#include <stb_image.h>

namespace mfr {

namespace {

// stb_image refuses larger sides itself (STBI_MAX_DIMENSIONS); the products below stay far from
// 2^64 under it
constexpr int64_t kStbMaxDimension = int64_t{1} << 24;

bool stbDecodesSize(int64_t width, int64_t height) {
  return width > 0 && height > 0 && width <= kStbMaxDimension && height <= kStbMaxDimension;
}

/// Bytes as stb_image's memory reader sees them: past the end, every byte reads as zero.
struct Bytes {
  const uint8_t* data;
  size_t size;
  uint32_t at(uint64_t i) const { return i < size ? data[i] : 0u; }
  uint32_t le16(uint64_t i) const { return at(i) | at(i + 1) << 8; }
  uint32_t le32(uint64_t i) const { return le16(i) | le16(i + 2) << 16; }
  uint32_t be16(uint64_t i) const { return at(i) << 8 | at(i + 1); }
  uint32_t be32(uint64_t i) const { return be16(i) << 16 | be16(i + 2); }
  bool has(const char* text, uint64_t i = 0) const {
    for (; *text; ++text, ++i)
      if (at(i) != static_cast<uint8_t>(*text)) return false;
    return true;
  }
};

/// stb_image's reader for the text headers (PNM, HDR): get8 stops at the end and reads zeros.
struct TextCursor {
  const Bytes& b;
  size_t pos = 0;
  bool atEof() const { return pos >= b.size; }
  char get8() { return pos < b.size ? static_cast<char>(b.data[pos++]) : '\0'; }
};

/// "PPM pixel data is 48 of 768 bytes the header declares (truncated?)"; empty when they fit.
std::string shortData(std::string_view format, uint64_t start, uint64_t need, size_t size,
                      std::string_view what = "pixel data") {
  if (start <= size && need <= size - start) return {};
  const uint64_t have = start < size ? size - start : 0;
  return std::string(format) + " " + std::string(what) + " is " + std::to_string(have) + " of " +
         std::to_string(need) + " bytes the header declares (truncated?)";
}

/// "TGA data ends after 60 bytes, inside pixel 17 of 256 (truncated?)"
std::string endsEarly(std::string_view format, size_t size, const std::string& where) {
  return std::string(format) + " data ends after " + std::to_string(size) + " bytes, " + where +
         " (truncated?)";
}

// ---- PNG: every chunk complete, up to IEND (stb_image reads zeros past the end, takes them for
// a chunk of type 0 and fails with an empty reason)
std::string checkPng(const Bytes& b) {
  uint64_t pos = 8;
  for (;;) {
    if (b.size - pos < 12) return endsEarly("PNG", b.size, "before its IEND chunk");
    const uint64_t length = b.be32(pos);
    const std::string type(reinterpret_cast<const char*>(b.data + pos + 4), 4);
    if (length > b.size - pos - 12)
      return endsEarly("PNG", b.size, "inside its " + quoteInput(type) + " chunk");
    pos += 12 + length;
    if (type == "IEND") return {};
  }
}

// ---- BMP (stbi__bmp_parse_header, stbi__bmp_load): uncompressed or bit fields, rows of a
// 4-byte stride from the data offset; palette images must index inside their palette
std::string checkBmp(const Bytes& b) {
  const int64_t offset = static_cast<int32_t>(b.le32(10));
  const uint32_t headerSize = b.le32(14);
  if (offset < 0) return {};  // stb_image: "bad BMP"
  int64_t width = 0, height = 0;
  uint64_t pos = 18;
  if (headerSize == 12) {
    width = b.le16(pos);
    height = b.le16(pos + 2);
    pos += 4;
  } else {
    width = b.le32(pos);
    height = std::abs(int64_t{static_cast<int32_t>(b.le32(pos + 4))});
    pos += 8;
  }
  if (b.le16(pos) != 1) return {};  // planes
  const uint32_t bpp = b.le16(pos + 2);
  int64_t extraRead = 14;
  if (headerSize != 12) {
    const int32_t compress = static_cast<int32_t>(b.le32(pos + 4));
    if (compress == 1 || compress == 2 || compress >= 4) return {};  // RLE, JPEG, PNG: refused
    if (compress == 3 && bpp != 16 && bpp != 32) return {};
    if ((headerSize == 40 || headerSize == 56) && compress == 3) extraRead += 12;  // the masks
  }
  if (!stbDecodesSize(width, height)) return {};
  int64_t rowBytes = 0, paletteSize = 0;
  if (bpp < 16) {
    paletteSize = headerSize == 12 ? (offset - extraRead - 24) / 3  // sic: stb_image's formula
                                   : (offset - extraRead - headerSize) >> 2;
    if (paletteSize == 0 || paletteSize > 256) return {};  // stb_image: "invalid"
    if (paletteSize < 0)
      return "BMP data offset " + std::to_string(offset) + " lies inside its " +
             std::to_string(14 + headerSize) + "-byte header: there is no room for its palette";
    if (bpp == 1)
      rowBytes = (width + 7) >> 3;
    else if (bpp == 4)
      rowBytes = (width + 1) >> 1;
    else if (bpp == 8)
      rowBytes = width;
    else
      return {};  // stb_image: "bad bpp"
  } else {
    if (bpp != 16 && bpp != 24 && bpp != 32) return {};  // stb_image: "bad masks"
    rowBytes = width * (bpp / 8);
  }
  const int64_t stride = (rowBytes + 3) & ~int64_t{3};
  const uint64_t need = static_cast<uint64_t>(stride * (height - 1) + rowBytes);
  if (std::string error = shortData("BMP", static_cast<uint64_t>(offset), need, b.size);
      !error.empty())
    return error;
  if (bpp < 16 && paletteSize < (int64_t{1} << bpp)) {
    // stb_image's palette is an uninitialised array of 256 colours past the file's
    for (int64_t y = 0; y < height; ++y) {
      const uint8_t* row = b.data + offset + y * stride;
      for (int64_t x = 0; x < width; ++x) {
        const int64_t index = bpp == 8   ? row[x]
                              : bpp == 4 ? (row[x >> 1] >> ((x & 1) ? 0 : 4)) & 15
                                         : (row[x >> 3] >> (7 - (x & 7))) & 1;
        if (index >= paletteSize)
          return "BMP pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                 ") of its data is colour " + std::to_string(index) + " of a palette of " +
                 std::to_string(paletteSize) + " colours";
      }
    }
  }
  return {};
}

// ---- GIF (stbi__gif_load_next): stb_image decodes the first image; the blocks are walked to the
// trailer
std::string checkGif(const Bytes& b) {
  if (b.size < 13) return endsEarly("GIF", b.size, "inside its header");
  uint64_t pos = 13;
  const uint32_t flags = b.at(10);
  if (flags & 0x80) pos += 3 * (2u << (flags & 7));  // global colour table
  int images = 0;
  const auto subBlocks = [&]() {  // a chain of sized blocks up to an empty one
    for (;;) {
      if (pos >= b.size) return false;
      const uint32_t length = b.data[pos++];
      if (length == 0) return true;
      pos += length;
    }
  };
  for (;;) {
    if (pos >= b.size)
      return endsEarly("GIF", b.size, images ? "before its trailer" : "before its first image");
    const uint32_t tag = b.data[pos++];
    if (tag == 0x2C) {  // image descriptor, local colour table, LZW code size, data blocks
      const std::string where = "inside image " + std::to_string(images + 1);
      if (b.size - pos < 9) return endsEarly("GIF", b.size, where);
      const uint32_t local = b.data[pos + 8];
      pos += 9;
      if (local & 0x80) pos += 3 * (2u << (local & 7));
      ++pos;
      if (!subBlocks()) return endsEarly("GIF", b.size, where);
      ++images;
    } else if (tag == 0x21) {  // extension
      if (pos >= b.size) return endsEarly("GIF", b.size, "inside an extension");
      if (b.data[pos++] == 0xF9) {  // graphic control: stb_image skips an odd size, no blocks
        if (pos >= b.size) return endsEarly("GIF", b.size, "inside an extension");
        const uint32_t length = b.data[pos++];
        pos += length;
        if (length != 4) continue;
      }
      if (!subBlocks()) return endsEarly("GIF", b.size, "inside an extension");
    } else if (tag == 0x3B) {  // trailer
      // stb_image fails with an empty reason
      return images ? std::string() : std::string("GIF holds no image");
    } else {
      return {};  // stb_image refuses an unknown block before the first image, ignores it after
    }
  }
}

// ---- PSD (stbi__psd_load): three sized sections, then raw planes or PackBits runs per channel
std::string checkPsd(const Bytes& b) {
  if (b.be16(4) != 1) return {};
  const uint32_t channels = b.be16(12);
  const int64_t height = b.be32(14), width = b.be32(18);
  const uint32_t depth = b.be16(22);
  if (channels > 16 || (depth != 8 && depth != 16) || b.be16(24) != 3) return {};
  if (!stbDecodesSize(width, height)) return {};
  uint64_t pos = 26;
  for (int section = 0; section < 3; ++section) {  // mode data, image resources, layers
    if (b.size - std::min<uint64_t>(pos, b.size) < 4)
      return endsEarly("PSD", b.size, "inside its header sections");
    pos += 4 + uint64_t{b.be32(pos)};
  }
  if (pos > b.size || b.size - pos < 2) return endsEarly("PSD", b.size, "before its image data");
  const uint32_t compression = b.be16(pos);
  pos += 2;
  if (compression > 1) return {};
  const uint64_t pixels = static_cast<uint64_t>(width * height);
  const uint64_t planes = std::min<uint32_t>(channels, 4);  // stb_image reads four at most
  if (compression == 0) return shortData("PSD", pos, planes * pixels * (depth / 8), b.size);
  pos += static_cast<uint64_t>(height) * channels * 2;  // the byte counts of the rows
  if (pos > b.size) return endsEarly("PSD", b.size, "inside its RLE byte counts");
  for (uint64_t plane = 0; plane < planes; ++plane) {
    const auto where = [&] {
      return "inside the RLE data of channel " + std::to_string(plane + 1) + " of " +
             std::to_string(planes);
    };
    uint64_t count = 0;
    while (count < pixels) {
      if (pos >= b.size) return endsEarly("PSD", b.size, where());
      const uint32_t length = b.data[pos++];
      if (length == 128) continue;
      const uint64_t run = length < 128 ? length + 1 : 257 - length;
      if (run > pixels - count) return {};  // stb_image: "bad RLE data"
      pos += length < 128 ? run : 1;
      if (pos > b.size) return endsEarly("PSD", b.size, where());
      count += run;
    }
  }
  return {};
}

// ---- PIC (stbi__pic_load): packets of up to four channels, rows raw or run-length coded
std::string checkPic(const Bytes& b) {
  const int64_t width = b.be16(92), height = b.be16(94);
  if (b.size <= 96 || !stbDecodesSize(width, height)) return {};
  uint64_t pos = 104;
  struct Packet {
    uint32_t type, channels;
  };
  std::vector<Packet> packets;
  for (bool chained = true; chained;) {
    if (packets.size() == 10) return {};  // stb_image: "too many packets"
    chained = b.at(pos) != 0;
    const uint32_t bits = b.at(pos + 1), type = b.at(pos + 2), channel = b.at(pos + 3);
    pos += 4;
    if (pos >= b.size) return endsEarly("PIC", b.size, "inside its packets");
    if (bits != 8) return {};
    packets.push_back({type, static_cast<uint32_t>(std::popcount(channel & 0xF0u))});
  }
  for (int64_t y = 0; y < height; ++y) {
    const auto where = [&] {
      return "inside row " + std::to_string(y + 1) + " of " + std::to_string(height);
    };
    for (const Packet& packet : packets) {
      const uint64_t value = packet.channels;  // bytes of one value
      if (packet.type == 0) {
        pos += static_cast<uint64_t>(width) * value;
        if (pos > b.size) return endsEarly("PIC", b.size, where());
        continue;
      }
      if (packet.type > 2) return {};  // stb_image: "packet has bad compression type"
      for (int64_t left = width; left > 0;) {
        // the count, then stb_image's at-end check: it must not be the file's last byte
        if (b.size - std::min<uint64_t>(pos, b.size) < 2) return endsEarly("PIC", b.size, where());
        const uint32_t first = b.data[pos++];
        int64_t count = first;
        uint64_t values = 1;
        if (packet.type == 1) {  // pure runs
          count = std::min(count, left);
        } else if (first >= 128) {  // mixed: a run
          count = first == 128 ? int64_t{b.be16(pos)} : int64_t{first} - 127;
          if (first == 128) pos += 2;
          if (count > left) return {};  // stb_image: "scanline overrun"
        } else {                        // mixed: raw values
          count = int64_t{first} + 1;
          values = static_cast<uint64_t>(count);
          if (count > left) return {};
        }
        pos += values * value;
        if (pos > b.size) return endsEarly("PIC", b.size, where());
        left -= count;
      }
    }
  }
  return {};
}

// ---- JPEG (stbi__decode_jpeg_image): segments and entropy-coded data up to the EOI marker
std::string checkJpeg(const Bytes& b) {
  uint64_t pos = 1;
  while (pos < b.size && b.data[pos] == 0xFF) ++pos;
  ++pos;  // SOI
  const std::string where = "before its EOI marker";
  for (;;) {
    if (pos >= b.size) return endsEarly("JPEG", b.size, where);
    if (b.data[pos] != 0xFF) {  // padding between segments (stb_image refuses most)
      ++pos;
      continue;
    }
    while (pos < b.size && b.data[pos] == 0xFF) ++pos;
    if (pos >= b.size) return endsEarly("JPEG", b.size, where);
    const uint32_t marker = b.data[pos++];
    if (marker == 0xD9) return {};  // EOI
    if (marker == 0x00 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) continue;
    if (b.size - pos < 2) return endsEarly("JPEG", b.size, where);
    const uint32_t length = b.be16(pos);
    if (length < 2) return {};  // stb_image refuses it
    if (length > b.size - pos) return endsEarly("JPEG", b.size, where);
    pos += length;
    if (marker != 0xDA) continue;
    // SOS: entropy-coded data up to a marker (0xFF 0x00 is a 0xFF byte, RSTn restarts)
    for (;;) {
      const void* ff = std::memchr(b.data + pos, 0xFF, b.size - pos);
      if (!ff) return endsEarly("JPEG", b.size, where);
      pos = static_cast<uint64_t>(static_cast<const uint8_t*>(ff) - b.data);
      if (pos + 1 >= b.size) return endsEarly("JPEG", b.size, where);
      const uint32_t next = b.data[pos + 1];
      if (next == 0xFF)
        ++pos;
      else if (next == 0x00 || (next >= 0xD0 && next <= 0xD7))
        pos += 2;
      else
        break;  // a marker: the loop above reads it
    }
  }
}

// ---- binary PGM / PPM (stbi__pnm_info, stbi__pnm_load): the samples follow the header
bool pnmSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}

std::string checkPnm(const Bytes& b) {
  TextCursor s{b};
  s.get8();
  const char kind = s.get8();
  const int64_t channels = kind == '6' ? 3 : 1;
  char c = s.get8();
  const auto skipSpace = [&] {
    for (;;) {
      while (!s.atEof() && pnmSpace(c)) c = s.get8();
      if (s.atEof() || c != '#') break;
      while (!s.atEof() && c != '\n' && c != '\r') c = s.get8();
    }
  };
  const auto integer = [&] {  // stb_image's int arithmetic, wrapping as its build does
    uint32_t value = 0;
    while (!s.atEof() && c >= '0' && c <= '9') {
      value = value * 10 + static_cast<uint32_t>(c - '0');
      c = s.get8();
    }
    return static_cast<int32_t>(value);
  };
  skipSpace();
  const int64_t width = integer();
  skipSpace();
  const int64_t height = integer();
  skipSpace();
  const int64_t maxValue = integer();
  if (maxValue > 65535 || !stbDecodesSize(width, height)) return {};
  const uint64_t need = static_cast<uint64_t>(width * height * channels * (maxValue > 255 ? 2 : 1));
  return shortData(kind == '5' ? "PGM" : "PPM", s.pos, need, b.size);
}

// ---- Radiance HDR (stbi__hdr_load): text header, then flat RGBE or run-length scanlines
std::string hdrToken(TextCursor& s) {
  std::string token;
  char c = s.get8();
  while (!s.atEof() && c != '\n') {
    token += c;
    if (token.size() == 1023) {  // STBI__HDR_BUFLEN - 1: the rest of the line is skipped
      while (!s.atEof() && s.get8() != '\n') {
      }
      break;
    }
    c = s.get8();
  }
  return token;
}

std::string checkHdr(const Bytes& b) {
  TextCursor s{b};
  hdrToken(s);
  bool valid = false;
  for (;;) {
    const std::string token = hdrToken(s);
    if (token.c_str()[0] == '\0') break;
    if (std::strcmp(token.c_str(), "FORMAT=32-bit_rle_rgbe") == 0) valid = true;
  }
  if (!valid) return {};
  const std::string line = hdrToken(s);
  const char* token = line.c_str();
  if (std::strncmp(token, "-Y ", 3) != 0) return {};
  char* end = nullptr;
  const int64_t height = static_cast<int>(std::strtol(token + 3, &end, 10));
  token = end;
  while (*token == ' ') ++token;
  if (std::strncmp(token, "+X ", 3) != 0) return {};
  const int64_t width = static_cast<int>(std::strtol(token + 3, nullptr, 10));
  if (!stbDecodesSize(width, height)) return {};
  const uint64_t flat = static_cast<uint64_t>(width * height * 4);
  if (width < 8 || width >= 32768) return shortData("HDR", s.pos, flat, b.size);
  uint64_t pos = s.pos;
  for (int64_t y = 0; y < height; ++y) {
    const auto where = [&] {
      return "inside scanline " + std::to_string(y + 1) + " of " + std::to_string(height);
    };
    if (b.size - std::min<uint64_t>(pos, b.size) < 4) return endsEarly("HDR", b.size, where());
    const uint8_t* head = b.data + pos;
    if (head[0] != 2 || head[1] != 2 || (head[2] & 0x80))  // not run-length coded: stb_image
      return shortData("HDR", pos, flat, b.size);          // reads the whole image flat from here
    if ((int64_t{head[2]} << 8 | head[3]) != width) return {};  // stb_image: "invalid ..."
    pos += 4;
    for (int component = 0; component < 4; ++component)
      for (int64_t x = 0; x < width;) {
        if (pos >= b.size) return endsEarly("HDR", b.size, where());  // stb_image loops forever
        const uint32_t count = b.data[pos++];
        const int64_t run = count > 128 ? count - 128 : count;
        if (run > width - x) return {};  // stb_image: "bad RLE data"
        pos += count > 128 ? 1 : static_cast<uint64_t>(run);
        if (pos > b.size) return endsEarly("HDR", b.size, where());
        x += run;
      }
  }
  return {};
}

// ---- TGA (stbi__tga_load): colour map, then raw pixels or run-length packets
int tgaChannels(uint32_t bits, bool grey, bool& rgb16) {
  rgb16 = false;
  switch (bits) {
    case 8:
      return 1;
    case 16:
      if (grey) return 2;
      rgb16 = true;
      return 3;
    case 15:
      rgb16 = true;
      return 3;
    case 24:
    case 32:
      return static_cast<int>(bits / 8);
    default:
      return 0;
  }
}

std::string checkTga(const Bytes& b) {
  const uint32_t idLength = b.at(0), indexed = b.at(1);
  uint32_t type = b.at(2);
  const uint32_t paletteStart = b.le16(3), paletteLength = b.le16(5), paletteBits = b.at(7);
  const int64_t width = b.le16(12), height = b.le16(14);
  const uint32_t bits = b.at(16);
  const bool rle = type >= 8;
  if (rle) type -= 8;
  bool rgb16 = false;
  const int channels =
      indexed ? tgaChannels(paletteBits, false, rgb16) : tgaChannels(bits, type == 3, rgb16);
  if (channels == 0 || !stbDecodesSize(width, height)) return {};
  const uint64_t pixels = static_cast<uint64_t>(width * height);
  uint64_t pos = 18 + idLength;
  if (indexed) {
    if (paletteLength == 0) return {};  // stb_image: "bad palette"
    pos += paletteStart;
    const uint64_t paletteBytes = uint64_t{paletteLength} * (rgb16 ? 2u : uint32_t(channels));
    if (std::string error = shortData("TGA", pos, paletteBytes, b.size, "colour map");
        !error.empty())
      return error;
    pos += paletteBytes;
  }
  const uint64_t pixelBytes = indexed ? (bits == 8 ? 1u : 2u)
                              : rgb16 ? 2u
                                      : static_cast<uint64_t>(channels);
  if (!rle) return shortData("TGA", pos, pixels * pixelBytes, b.size);
  for (uint64_t done = 0; done < pixels;) {
    if (pos >= b.size)
      return endsEarly(
          "TGA", b.size,
          "inside pixel " + std::to_string(done + 1) + " of " + std::to_string(pixels));
    const uint32_t command = b.data[pos++];
    const uint64_t count = std::min<uint64_t>(1 + (command & 127), pixels - done);
    pos += (command & 0x80) ? pixelBytes : count * pixelBytes;
    if (pos > b.size)
      return endsEarly(
          "TGA", b.size,
          "inside pixel " + std::to_string(done + 1) + " of " + std::to_string(pixels));
    done += count;
  }
  return {};
}

// ---- stb_image reading through callbacks (the second line of defence)
struct CallbackSource {
  const uint8_t* data;
  size_t size;
  size_t pos = 0;
  const char* refillBuffer = nullptr;  // stb_image's own 128-byte buffer
  bool pastEnd = false;
};

int readCallback(void* user, char* out, int n) {
  auto& source = *static_cast<CallbackSource*>(user);
  if (!source.refillBuffer) source.refillBuffer = out;  // the first read fills stb's buffer
  const size_t wanted = static_cast<size_t>(std::max(n, 0));
  const size_t left = source.pos < source.size ? source.size - source.pos : 0;
  const size_t take = std::min(left, wanted);
  if (take) std::memcpy(out, source.data + source.pos, take);
  source.pos += take;
  if (take == wanted) return n;
  if (out == source.refillBuffer) {  // a short refill is the end; an empty one, a read past it
    if (take == 0) source.pastEnd = true;
    return static_cast<int>(take);
  }
  // stbi__getn: the rest would stay uninitialised (it ignores the failure in places)
  std::memset(out + take, 0, wanted - take);
  source.pastEnd = true;
  return n;
}

void skipCallback(void* user, int n) {
  if (n > 0) static_cast<CallbackSource*>(user)->pos += static_cast<size_t>(n);
}

int eofCallback(void* user) {
  const auto& source = *static_cast<CallbackSource*>(user);
  return source.pos >= source.size;
}

/// Grey, grey + alpha, RGB or RGBA samples as RGBA (stb_image's own conversion).
template <typename T>
void expandToRgba(const T* in, size_t count, int channels, T opaque, uint8_t* out) {
  for (size_t i = 0; i < count; ++i) {
    const T* p = in + i * static_cast<size_t>(channels);
    const T rgba[4] = {p[0], channels >= 3 ? p[1] : p[0], channels >= 3 ? p[2] : p[0],
                       channels == 2   ? p[1]
                       : channels == 4 ? p[3]
                                       : opaque};
    std::memcpy(out + i * sizeof rgba, rgba, sizeof rgba);
  }
}

std::string stbReason() {
  const char* reason = stbi_failure_reason();
  // an unknown PNG chunk's reason starts with its type's bytes, possibly zero
  if (!reason || !*reason) return "stb_image gives no reason";
  return oneLine(reason, 200);
}

}  // namespace

std::string_view imageFormatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::Png:
      return "PNG";
    case ImageFormat::Bmp:
      return "BMP";
    case ImageFormat::Gif:
      return "GIF";
    case ImageFormat::Psd:
      return "PSD";
    case ImageFormat::Pic:
      return "PIC";
    case ImageFormat::Jpeg:
      return "JPEG";
    case ImageFormat::Pnm:
      return "PPM";
    case ImageFormat::Hdr:
      return "HDR";
    case ImageFormat::Tga:
      return "TGA";
    case ImageFormat::Unknown:
      break;
  }
  return "unknown";
}

ImageFormat identifyImageFormat(const uint8_t* bytes, size_t size) {
  const Bytes b{bytes, size};
  if (b.has("\x89PNG\r\n\x1a\n")) return ImageFormat::Png;
  if (b.has("BM")) {
    const uint32_t header = b.le32(14);
    if (header == 12 || header == 40 || header == 56 || header == 108 || header == 124)
      return ImageFormat::Bmp;
  }
  if (b.has("GIF8") && (b.at(4) == '7' || b.at(4) == '9') && b.at(5) == 'a')
    return ImageFormat::Gif;
  if (b.has("8BPS")) return ImageFormat::Psd;
  if (b.has("\x53\x80\xF6\x34") && b.has("PICT", 88)) return ImageFormat::Pic;
  if (b.at(0) == 0xFF) {  // stbi__get_marker: fill bytes, then SOI
    size_t i = 1;
    while (i < size && b.at(i) == 0xFF) ++i;
    if (b.at(i) == 0xD8) return ImageFormat::Jpeg;
  }
  if (b.at(0) == 'P' && (b.at(1) == '5' || b.at(1) == '6')) return ImageFormat::Pnm;
  if (b.has("#?RADIANCE\n") || b.has("#?RGBE\n")) return ImageFormat::Hdr;
  // stbi__tga_test
  const uint32_t mapType = b.at(1), type = b.at(2), bits = b.at(16);
  const auto oneOf = [](uint32_t v, std::initializer_list<uint32_t> set) {
    return std::find(set.begin(), set.end(), v) != set.end();
  };
  if (mapType > 1) return ImageFormat::Unknown;
  if (mapType == 1 && (!oneOf(type, {1, 9}) || !oneOf(b.at(7), {8, 15, 16, 24, 32})))
    return ImageFormat::Unknown;
  if (mapType == 0 && !oneOf(type, {2, 3, 10, 11})) return ImageFormat::Unknown;
  if (b.le16(12) < 1 || b.le16(14) < 1) return ImageFormat::Unknown;
  if (mapType == 1 && bits != 8 && bits != 16) return ImageFormat::Unknown;
  if (!oneOf(bits, {8, 15, 16, 24, 32})) return ImageFormat::Unknown;
  return ImageFormat::Tga;
}

Result<void> checkImageData(const uint8_t* bytes, size_t size, const std::string& what) {
  const Bytes b{bytes, size};
  std::string error;
  switch (identifyImageFormat(bytes, size)) {
    case ImageFormat::Png:
      error = checkPng(b);
      break;
    case ImageFormat::Bmp:
      error = checkBmp(b);
      break;
    case ImageFormat::Gif:
      error = checkGif(b);
      break;
    case ImageFormat::Psd:
      error = checkPsd(b);
      break;
    case ImageFormat::Pic:
      error = checkPic(b);
      break;
    case ImageFormat::Jpeg:
      error = checkJpeg(b);
      break;
    case ImageFormat::Pnm:
      error = checkPnm(b);
      break;
    case ImageFormat::Hdr:
      error = checkHdr(b);
      break;
    case ImageFormat::Tga:
      error = checkTga(b);
      break;
    case ImageFormat::Unknown:
      break;  // stb_image refuses it: "unknown image type"
  }
  if (error.empty()) return {};
  return makeError(what + ": " + error);
}

Result<DecodedImage> decodeImageUnchecked(const uint8_t* bytes, size_t size,
                                          const std::string& what, bool keep16Bits) {
  if (size > static_cast<size_t>(INT_MAX))
    return makeError(what + ": " + std::to_string(size) +
                     " bytes: too large for the image decoder (2 GiB at most)");
  const stbi_io_callbacks callbacks{&readCallback, &skipCallback, &eofCallback};
  CallbackSource source{bytes, size};
  DecodedImage image;
  // A PGM/PPM in its own channels (no req_comp): v2.27 converts a 16-bit one's channels with its
  // 8-bit converter, and its 16-to-8 step then reads twice the buffer (heap memory in a texture).
  // It also reads their 16-bit samples in the machine's byte order, where Netpbm puts the most
  // significant byte first: those are read in 16 bits and swapped here. Other formats: RGBA from
  // stb_image (without req_comp, a PIC whose packets fail trips an assertion in it).
  const bool sixteenBits = stbi_is_16_bit_from_memory(bytes, static_cast<int>(size)) != 0;
  const bool pnm = identifyImageFormat(bytes, size) == ImageFormat::Pnm;
  const bool pnm16 = sixteenBits && pnm;
  const int request = pnm ? 0 : 4;
  void* pixels = nullptr;
  int channels = 0;
  if (sixteenBits && (keep16Bits || pnm16)) {
    pixels = stbi_load_16_from_callbacks(&callbacks, &source, &image.width, &image.height,
                                         &channels, request);
    image.bits = 16;
  } else {
    pixels = stbi_load_from_callbacks(&callbacks, &source, &image.width, &image.height, &channels,
                                      request);
  }
  if (!pixels) return makeError(what + ": cannot decode the image: " + stbReason());
  image.fileChannels = channels;
  const int decoded = request ? request : channels;
  const bool pastEnd = source.pastEnd;
  if (!pastEnd && image.width > 0 && image.height > 0 && decoded >= 1 && decoded <= 4) {
    const size_t count = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
    if (image.bits == 16) {
      auto* samples = static_cast<uint16_t*>(pixels);
      const size_t n = count * static_cast<size_t>(decoded);
      if (pnm16 && std::endian::native == std::endian::little)
        for (size_t i = 0; i < n; ++i)
          samples[i] = static_cast<uint16_t>(samples[i] << 8 | samples[i] >> 8);
      if (!keep16Bits) {  // stb_image's 16-to-8 bits: the high byte
        auto* reduced = static_cast<uint8_t*>(pixels);
        for (size_t i = 0; i < n; ++i) reduced[i] = static_cast<uint8_t>(samples[i] >> 8);
        image.bits = 8;
      }
    }
    image.bytes.resize(count * 4 * (image.bits / 8));
    if (image.bits == 16)
      expandToRgba(static_cast<const uint16_t*>(pixels), count, decoded, uint16_t{0xFFFF},
                   image.bytes.data());
    else
      expandToRgba(static_cast<const uint8_t*>(pixels), count, decoded, uint8_t{0xFF},
                   image.bytes.data());
  }
  stbi_image_free(pixels);
  if (pastEnd) return makeError(what + ": stb_image read past the end of the data (truncated?)");
  if (image.bytes.empty())
    return makeError(what + ": invalid image of " + std::to_string(image.width) + " x " +
                     std::to_string(image.height) + " pixels, " + std::to_string(channels) +
                     " channels");
  return image;
}

Result<DecodedImage> decodeImage(const uint8_t* bytes, size_t size, const std::string& what,
                                 bool keep16Bits) {
  MFR_TRY(checkPngChunks(bytes, size, what));
  MFR_TRY(checkImageData(bytes, size, what));
  int width = 0, height = 0, channels = 0;
  if (size <= static_cast<size_t>(INT_MAX) &&
      stbi_info_from_memory(bytes, static_cast<int>(size), &width, &height, &channels))
    MFR_TRY(checkImageDimensions(width, height, what));  // from the header, before decoding
  return decodeImageUnchecked(bytes, size, what, keep16Bits);
}

}  // namespace mfr
