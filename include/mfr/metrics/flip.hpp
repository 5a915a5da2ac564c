// LDR-FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating Images", HPG 2020):
// a per-pixel perceptual error map in [0, 1] between a reference and a test image as a viewer
// flipping between them would see it, and its mean. Follows the published algorithm and the
// public FLIP tool (NVlabs/flip) in every stage; see src/metrics/flip.cpp.
#pragma once

#include <cstdint>
#include <vector>

#include "mfr/core/image.hpp"
#include "mfr/core/option_name.hpp"
#include "mfr/core/result.hpp"

namespace mfr {

/// Pixels per degree of visual angle for the FLIP tool's default observer: 0.7 m from a 0.7 m
/// wide display 3840 pixels across (about 67.02).
inline constexpr double kFlipDefaultPixelsPerDegree =
    0.7 * (3840.0 / 0.7) * (3.14159265358979 / 180.0);

/// The pixels per degree FLIP accepts. Its filters are sampled at 1 / ppd degrees: the colour
/// filters reach 0.135 ppd pixels either side, the feature filters (sigma 0.041 ppd) 0.123 ppd.
/// Below 2 the feature filters' derivative taps underflow in single precision and the map is NaN;
/// at 1000 the filters are 271 taps wide (15 times the default's work) and no display comes near
/// (the eye resolves about 120 ppd). Outside the range the filters only grow (1e10: 1.3e9 taps,
/// more than the memory) or vanish.
inline constexpr double kFlipMinPixelsPerDegree = 2.0;
inline constexpr double kFlipMaxPixelsPerDegree = 1000.0;

/// Error unless `pixelsPerDegree` is a number in [kFlipMinPixelsPerDegree,
/// kFlipMaxPixelsPerDegree]: "--ppd 1e+10: FLIP's pixels per degree must be in [2, 1000] ..."
/// (`ppd` in Python's spelling). computeFlip and runComparison check it; front ends check it
/// before any work.
Result<void> checkFlipPixelsPerDegree(double pixelsPerDegree, Spelling spelling = Spelling::Cli);

/// The bytes computeFlip allocates for two width x height images (its planes, the error map):
/// what a caller pre-flights against a memory limit before decoding the images.
uint64_t flipWorkingBytes(int width, int height);

struct FlipResult {
  double mean = 0.0;            // arithmetic mean of errorMap (accumulated in double)
  std::vector<float> errorMap;  // width * height values in [0, 1], rows top to bottom
  int width = 0;
  int height = 0;
};

/// LDR-FLIP between two sRGB-encoded 8-bit images (alpha ignored, as the FLIP tool does). Errors:
/// sizes differ (both sizes named), an empty image, or pixel data that does not match the size, or
/// a pixelsPerDegree outside the range (checkFlipPixelsPerDegree). The result does not depend on
/// the number of threads. LDR-FLIP is symmetric: swapping reference and test gives the same map.
Result<FlipResult> computeFlip(const Image8& reference, const Image8& test,
                               double pixelsPerDegree = kFlipDefaultPixelsPerDegree);

/// The error map through the magma colour map, index round(255 e) as the FLIP tool writes it.
Image8 flipErrorImage(const FlipResult& result);

/// Nearest-rank percentile of the error map: fraction in [0, 1] (0 gives the minimum, 1 the
/// maximum). 0 for an empty map.
double flipPercentile(const FlipResult& result, double fraction);

}  // namespace mfr
