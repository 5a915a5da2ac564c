// Occupancy-map culling (occupancy paper sec. 2): Lemma 2.1 -- the k nearest fragments of a pixel
// always survive -- over random and degenerate depth sets, the bucket function's contract, and that
// the culling does reject fragments when the depths are spread out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "mfr/cpu/occupancy_map.hpp"

namespace mfr {
namespace {

// Runs the three passes (depth range, fill, count) of one map over per-pixel depth sets.
OccupancyMap buildMap(const std::vector<std::vector<float>>& depths, int words,
                      const std::vector<uint32_t>& k) {
  OccupancyMap map(depths.size(), words);
  for (uint32_t p = 0; p < depths.size(); ++p)
    for (const float z : depths[p]) map.expandRange(p, z);
  for (uint32_t p = 0; p < depths.size(); ++p)
    for (const float z : depths[p]) map.mark(p, z);
  for (uint32_t p = 0; p < depths.size(); ++p) map.resolveThreshold(p, k[p]);
  return map;
}

std::string describe(const std::vector<float>& depths, uint32_t k, int words) {
  std::string s = "k=";
  s += std::to_string(k);
  s += " d=";
  s += std::to_string(words);
  s += " depths:";
  for (size_t i = 0; i < depths.size() && i < 12; ++i) {
    s += ' ';
    s += std::to_string(depths[i]);
  }
  if (depths.size() > 12) s += " ...";
  return s;
}

// Checks Lemma 2.1 on one pixel: none of the k nearest is culled (nor anything as near as the
// k-th), culling is monotone in depth, and the survivors fill exactly the first min(k, occupied)
// occupied buckets.
void checkPixel(const OccupancyMap& map, uint32_t p, const std::vector<float>& depths, uint32_t k,
                int words) {
  const std::string what = describe(depths, k, words);
  std::vector<float> sorted = depths;
  std::sort(sorted.begin(), sorted.end());
  const size_t keep = std::min<size_t>(k, sorted.size());
  for (size_t i = 0; i < keep; ++i)
    ASSERT_FALSE(map.culls(p, sorted[i])) << what << ": the " << i << "-th nearest is culled";
  for (const float z : sorted)
    if (keep > 0 && z <= sorted[keep - 1]) {
      ASSERT_FALSE(map.culls(p, z)) << what;
    }
  for (size_t i = 1; i < sorted.size(); ++i)
    if (map.culls(p, sorted[i - 1])) {
      ASSERT_TRUE(map.culls(p, sorted[i])) << what << ": not monotone";
    }
  std::set<uint32_t> occupied, surviving;
  for (const float z : depths) {
    const uint32_t b = map.bucket(p, z);
    ASSERT_LT(b, map.buckets()) << what;
    occupied.insert(b);
    if (!map.culls(p, z)) surviving.insert(b);
  }
  std::set<uint32_t> firstK;
  for (const uint32_t b : occupied)
    if (firstK.size() < k) firstK.insert(b);
  EXPECT_EQ(surviving, firstK) << what;
}

std::vector<float> randomDepths(std::mt19937& rng, int flavour) {
  const uint32_t n = 1 + rng() % 90;
  std::vector<float> d;
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float specials[] = {0.0f, std::numeric_limits<float>::denorm_min(), 1e-40f, 1.0f,
                            std::nextafter(1.0f, 0.0f)};
  for (uint32_t i = 0; i < n; ++i) {
    switch (flavour) {
      case 0:
        d.push_back(unit(rng));
        break;  // spread
      case 1:
        d.push_back(rng() % 4 == 0 ? specials[rng() % 5] : unit(rng));
        break;  // extremes
      case 2:
        d.push_back(0.3f + 1e-6f * static_cast<float>(rng() % 5));
        break;  // narrow range
      case 3:
        d.push_back(0.5f);
        break;  // zero range
      case 4:
        d.push_back(static_cast<float>(rng() % 3) / 2.0f);
        break;  // 0, 0.5, 1
      default:
        d.push_back(unit(rng) * unit(rng) * unit(rng));
        break;  // clustered near
    }
  }
  return d;
}

TEST(OccupancyMap, NeverCullsOneOfTheKNearestOnRandomDepthSets) {
  std::mt19937 rng(2015);
  for (const int words : {1, 2, 4}) {
    // many pixels in one map, each with its own depth set and k (also k above the number of
    // occupied buckets, and k above the number of fragments)
    std::vector<std::vector<float>> depths;
    std::vector<uint32_t> k;
    for (int i = 0; i < 600; ++i) {
      depths.push_back(randomDepths(rng, i % 6));
      const uint32_t choices[] = {1, 2, 3, 4, 8, 16, 31, 32, 33, 64, 100, 200};
      k.push_back(choices[rng() % 12]);
    }
    const OccupancyMap map = buildMap(depths, words, k);
    for (uint32_t p = 0; p < depths.size(); ++p) {
      checkPixel(map, p, depths[p], k[p], words);
      if (HasFatalFailure()) return;
    }
  }
}

TEST(OccupancyMap, FarBoundMapsIntoTheLastBucketAndNearBoundIntoTheFirst) {
  for (const int words : {1, 2, 4}) {
    const std::vector<std::vector<float>> depths = {
        {0.2f, 0.9f}, {0.0f, 1.0f}, {0.0f, std::numeric_limits<float>::denorm_min()}};
    const OccupancyMap map = buildMap(depths, words, {1, 1, 1});
    for (uint32_t p = 0; p < depths.size(); ++p) {
      EXPECT_EQ(map.bucket(p, depths[p][0]), 0u) << p;
      EXPECT_EQ(map.bucket(p, depths[p][1]), map.buckets() - 1) << p;
      EXPECT_FALSE(map.culls(p, depths[p][0]));
      EXPECT_TRUE(map.culls(p, depths[p][1])) << "k = 1: the far one is in a later bucket";
    }
  }
}

TEST(OccupancyMap, ZeroDepthRangeCullsNothing) {
  for (const int words : {1, 2, 4})
    for (const float z : {0.0f, std::numeric_limits<float>::denorm_min(), 0.5f, 1.0f}) {
      const std::vector<std::vector<float>> depths = {std::vector<float>(50, z)};
      const OccupancyMap map = buildMap(depths, words, {1});
      EXPECT_EQ(map.bucket(0, z), 0u);
      EXPECT_FALSE(map.culls(0, z)) << z;
    }
}

TEST(OccupancyMap, KAboveTheOccupiedBucketsCullsNothing) {
  for (const int words : {1, 2, 4}) {
    // five distinct depths, at most five occupied buckets
    const std::vector<float> d = {0.1f, 0.3f, 0.5f, 0.7f, 0.9f, 0.9f, 0.1f, 0.5f};
    const OccupancyMap map = buildMap({d, d}, words, {6, 5});
    for (const float z : d) {
      EXPECT_FALSE(map.culls(0, z));
      EXPECT_FALSE(map.culls(1, z)) << "k equal to the occupied buckets keeps all of them";
    }
  }
}

TEST(OccupancyMap, CullsMostOfASpreadOutStream) {
  for (const int words : {1, 2, 4}) {
    std::vector<float> d;
    for (int i = 0; i < 256; ++i) d.push_back(static_cast<float>(i) / 255.0f);
    const uint32_t k = 4;
    const OccupancyMap map = buildMap({d}, words, {k});
    size_t culled = 0;
    for (const float z : d) culled += map.culls(0, z);
    // S >= 32 buckets of about 8 fragments each: the first 4 occupied buckets hold about k * 256/S
    // fragments, so at least half of the stream goes
    EXPECT_GE(culled, d.size() / 2) << "d=" << words;
    EXPECT_LE(culled, d.size() - k);
    checkPixel(map, 0, d, k, words);
  }
}

TEST(OccupancyMap, PixelsAreIndependent) {
  // a far fragment in one pixel must not change another pixel's range or buckets
  const int words = 2;
  const std::vector<std::vector<float>> depths = {{0.1f, 0.2f, 0.3f}, {0.5f, 0.6f, 0.7f}, {}};
  const OccupancyMap map = buildMap(depths, words, {1, 1, 1});
  EXPECT_EQ(map.bucket(0, 0.1f), 0u);
  EXPECT_EQ(map.bucket(1, 0.5f), 0u);
  EXPECT_EQ(map.bucket(0, 0.3f), map.buckets() - 1);
  EXPECT_EQ(map.bucket(1, 0.7f), map.buckets() - 1);
  EXPECT_TRUE(map.culls(0, 0.2f));
  EXPECT_FALSE(map.culls(1, 0.5f));
  EXPECT_FALSE(map.culls(2, 0.5f)) << "an empty pixel culls nothing";
}

TEST(OccupancyMap, BytesPerPixelFollowTheLayout) {
  EXPECT_EQ(OccupancyMap::bytesPerPixel(1), 16u);  // zn, zf, j_k, one 32-bit word
  EXPECT_EQ(OccupancyMap::bytesPerPixel(2), 20u);
  EXPECT_EQ(OccupancyMap::bytesPerPixel(4), 28u);
  EXPECT_EQ(OccupancyMap(1, 4).buckets(), 128u);
}

}  // namespace
}  // namespace mfr
