// Colour encoding: the fast sRGB encoder must give the correctly rounded code everywhere.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
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

// The 8-lane encode's guess (ColorTables::bucketLowSrgb8) is the code of its bucket's smallest
// input and at most one below the code of any input of the bucket, so one upward correction makes
// it exact: checked on every bucket's smallest and largest input, found by bisection over the
// float bits with the encode's own bucket arithmetic.
TEST(Color, BucketGuessIsAtMostOneBelowEveryInputOfItsBucket) {
  const ColorTables& t = ColorTables::get();
  const auto bucketOf = [](float c) { return static_cast<int32_t>(c * 4095.0f + 0.5f); };
  const auto firstWithBucketAtLeast = [&](int b) {  // float bits in [0, 1]
    uint32_t lo = 0, hi = 0x3f800000u;
    if (bucketOf(1.0f) < b) return hi + 1;
    while (lo < hi) {
      const uint32_t mid = lo + (hi - lo) / 2;
      float c;
      std::memcpy(&c, &mid, sizeof c);
      (bucketOf(c) >= b ? hi : lo) = bucketOf(c) >= b ? mid : mid + 1;
    }
    return lo;
  };
  for (int b = 0; b < 4096; ++b) {
    const uint32_t first = firstWithBucketAtLeast(b), next = firstWithBucketAtLeast(b + 1);
    ASSERT_LT(first, next) << "bucket " << b << " is empty";
    float smallest, largest;
    const uint32_t last = next - 1;
    std::memcpy(&smallest, &first, sizeof smallest);
    std::memcpy(&largest, &last, sizeof largest);
    ASSERT_EQ(bucketOf(smallest), b);
    ASSERT_EQ(bucketOf(largest), b);
    EXPECT_EQ(t.bucketLowSrgb8[b], referenceEncode(smallest)) << "bucket " << b;
    const int spread = referenceEncode(largest) - t.bucketLowSrgb8[b];
    EXPECT_TRUE(spread == 0 || spread == 1)
        << "bucket " << b << " spans " << spread + 1 << " codes";
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
