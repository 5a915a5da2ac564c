// LDR-FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating Images", HPG 2020):
// a per-pixel perceptual error map in [0, 1] between a reference and a test image as a viewer
// flipping between them would see it, and its mean. Follows the published algorithm and the
// public FLIP tool (NVlabs/flip) in every stage; see src/metrics/flip.cpp.
#pragma once

#include <vector>

#include "mfr/core/image.hpp"
#include "mfr/core/result.hpp"

namespace mfr {

/// Pixels per degree of visual angle for the FLIP tool's default observer: 0.7 m from a 0.7 m
/// wide display 3840 pixels across (about 67.02).
inline constexpr double kFlipDefaultPixelsPerDegree =
    0.7 * (3840.0 / 0.7) * (3.14159265358979 / 180.0);

struct FlipResult {
  double mean = 0.0;            // arithmetic mean of errorMap (accumulated in double)
  std::vector<float> errorMap;  // width * height values in [0, 1], rows top to bottom
  int width = 0;
  int height = 0;
};

/// LDR-FLIP between two sRGB-encoded 8-bit images (alpha ignored, as the FLIP tool does). Errors:
/// sizes differ (both sizes named), an empty image, or pixel data that does not match the size, or
/// a pixelsPerDegree that is not finite and positive. The result does not depend on the number of
/// threads. LDR-FLIP is symmetric: swapping reference and test gives the same map.
Result<FlipResult> computeFlip(const Image8& reference, const Image8& test,
                               double pixelsPerDegree = kFlipDefaultPixelsPerDegree);

/// The error map through the magma colour map, index round(255 e) as the FLIP tool writes it.
Image8 flipErrorImage(const FlipResult& result);

/// Nearest-rank percentile of the error map: fraction in [0, 1] (0 gives the minimum, 1 the
/// maximum). 0 for an empty map.
double flipPercentile(const FlipResult& result, double fraction);

}  // namespace mfr
