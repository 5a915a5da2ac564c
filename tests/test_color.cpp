// Colour encoding: the fast sRGB encoder must give the correctly rounded code everywhere.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mfr/core/color.hpp"
#include "mfr/core/units.hpp"

namespace mfr {
namespace {

int referenceEncode(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  const double e =
      linear <= 0.0031308 ? linear * 12.92 : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
  return static_cast<int>(std::lround(e * 255.0));
}

TEST(Color, FastSrgbEncodeMatchesTheFormulaOnADenseSweep) {
  int mismatches = 0;
  for (int i = 0; i <= 2000000; ++i) {
    const float v = static_cast<float>(i) / 2000000.0f;
    mismatches += encodeSrgb8(v) != referenceEncode(v);
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(Color, FastSrgbEncodeIsExactAtEveryCodeBoundary) {
  for (int c = 1; c < 256; ++c) {
    const double e = (c - 0.5) / 255.0;
    const double boundary = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
    const float below = std::nextafter(static_cast<float>(boundary), 0.0f);
    const float above = std::nextafter(static_cast<float>(boundary), 1.0f);
    EXPECT_EQ(encodeSrgb8(below), referenceEncode(below)) << c;
    EXPECT_EQ(encodeSrgb8(above), referenceEncode(above)) << c;
  }
}

TEST(Color, EncodeClampsOutOfRangeAndNaN) {
  EXPECT_EQ(encodeSrgb8(-1.0f), 0);
  EXPECT_EQ(encodeSrgb8(7.0f), 255);
  EXPECT_EQ(encodeSrgb8(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(encodeSrgb8(std::numeric_limits<float>::infinity()), 255);
}

TEST(Color, DecodeInvertsEncodeForEveryCode) {
  for (int c = 0; c < 256; ++c) EXPECT_EQ(encodeSrgb8(decodeSrgb8(static_cast<uint8_t>(c))), c);
}

TEST(Color, FragmentColourWordIsRgbaWithRedInTheLowByte) {
  const uint32_t word = packFragmentColor({1.0f, 0.0f, 0.0f}, 0.5f);
  EXPECT_EQ(word & 0xffu, 255u);
  EXPECT_EQ((word >> 8) & 0xffu, 0u);
  EXPECT_EQ(word >> 24, 128u);
  const glm::vec4 back = unpackFragmentColor(word);
  EXPECT_NEAR(back.r, 1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(back.a, 128.0f / 255.0f);
}

TEST(Units, ByteSizesUseBinaryUnits) {
  EXPECT_EQ(parseByteSize("20MB").value(), 20ull << 20);
  EXPECT_EQ(parseByteSize("512kib").value(), 512ull << 10);
  EXPECT_EQ(parseByteSize("1.5GB").value(), 3ull << 29);
  EXPECT_EQ(parseByteSize("4096").value(), 4096u);
}

TEST(Units, RejectsMalformedAndAbsurdSizes) {
  for (const char* bad : {"", "MB", "-5MB", "20XB", "nan", "1e999", "2TB", "0", "0.1"}) {
    auto r = parseByteSize(bad);
    EXPECT_FALSE(r.ok()) << bad;
    if (!r.ok()) {
      EXPECT_NE(r.error().message.find(std::string("'") + bad + "'"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace mfr
