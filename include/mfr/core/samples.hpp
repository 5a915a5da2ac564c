// Multisampling (`--samples 1|2|4|8`): where a pixel's samples lie and how a method stores the
// fragments of a multisampled pixel.
//
// Sample positions: the standard multisample patterns of Direct3D 11
// (D3D11_STANDARD_MULTISAMPLE_PATTERN; "D3D11_STANDARD_MULTISAMPLE_QUALITY_LEVELS enumeration",
// Microsoft Learn), which Vulkan adopts as its standard sample locations (Vulkan 1.3
// specification, section 28.4 "Multisampling", table "Standard sample locations",
// `standardSampleLocations`). Offsets are in 1/16 pixel from the pixel centre, x right, y down
// (Direct3D's and Vulkan's framebuffer coordinates, the CPU rasterizer's image coordinates):
//   2: ( 4, 4) (-4,-4)
//   4: (-2,-6) ( 6,-2) (-6, 2) ( 2, 6)
//   8: ( 1,-3) (-1, 3) ( 5, 1) (-3,-5) (-5, 5) (-7,-1) ( 3, 7) ( 7,-7)
// One sample is the pixel centre.
//
// Storage disciplines (SampleStorage, `--sample-storage`):
//   pixel   one node per fragment of a triangle in a pixel, carrying its coverage mask (which
//           samples the triangle covers); the resolve composites each sample from the nodes whose
//           mask holds it, then averages the samples (the box filter). The node keeps its 8 bytes:
//           the mask rides in the low `samples` bits of the depth word (withCoverage), so every
//           store and test works unchanged, at a depth precision of 23 - samples mantissa bits.
//           A node's depth and colour are its triangle's at the first sample it covers.
//   sample  every sample is a pixel of its own: k per sample, shaded at the sample (the image is
//           W*S x H in storage, box-filtered to W x H). The per-sample A-buffer is the ground
//           truth: the exact answer of a render supersampled at these positions.
#pragma once

#include <bit>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

inline constexpr int kMaxSamples = 8;
static_assert(kMaxSamples == method_math::kMaxSampleSums);

/// One sample's offset from the pixel centre, in 1/16 pixel (x right, y down).
struct SampleOffset {
  int8_t x, y;
};

/// The standard pattern of 1, 2, 4 or 8 samples (an empty span for any other count).
std::span<const SampleOffset> samplePattern(int samples);

/// Parses a sample count: 1, 2, 4 or 8; the error names the input as `name`.
Result<int> parseSamples(const std::string& text, const std::string& name);
/// Parses a comma-separated list of distinct sample counts ("1,4,8"); the error names the input as
/// `name` (a bad count, a count listed twice).
Result<std::vector<int>> parseSampleCounts(const std::string& list, const std::string& name);

enum class SampleStorage : uint8_t {
  Pixel,   // one node per fragment with a coverage mask
  Sample,  // nodes per sample
};
/// "pixel", "sample".
const char* toString(SampleStorage storage);
/// Parses toString's names; the error names the input as `name`.
Result<SampleStorage> parseSampleStorage(const std::string& text, const std::string& name);

/// The coverage mask of `samples` samples in the low bits of a depth (per-pixel storage): the
/// depth's low mantissa bits replaced by `mask`, kept below 1 so the unsigned order of depths
/// stays their order.
/// (method_math.h's withCoverageBits, which the GL engine's native raster calls too)
inline float withCoverage(float depth, uint32_t mask, int samples) {
  return std::bit_cast<float>(
      method_math::withCoverageBits(std::bit_cast<uint32_t>(depth), mask, samples));
}
/// The coverage mask withCoverage put in a depth.
inline uint32_t coverageOf(float depth, int samples) {
  return std::bit_cast<uint32_t>(depth) & method_math::sampleBits(samples);
}

}  // namespace mfr
