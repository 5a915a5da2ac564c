// Pixel-wise error metrics of a test image against a reference: mean squared error and PSNR, on
// linear-light values (decoded sRGB) or on the sRGB-encoded values themselves, both in [0, 1].
#pragma once

#include <vector>

#include "mfr/core/image.hpp"
#include "mfr/core/result.hpp"

namespace mfr {

/// Which values the error is measured on: Linear decodes the sRGB8 codes to linear light
/// (IEC 61966-2-1), Srgb uses code / 255.
enum class MetricSpace { Linear, Srgb };

/// "linear" or "srgb".
const char* metricSpaceName(MetricSpace space);

/// PSNR in dB for values in [0, 1] (peak 1): 10 log10(1 / mse); +infinity when mse is 0.
double psnrFromMse(double mse);

/// Mean over pixels and the R, G, B channels of the squared difference (alpha ignored).
/// Errors: sizes differ (both named), or pixel data that does not match the size.
Result<double> meanSquaredError(const Image8& reference, const Image8& test, MetricSpace space);

struct ImageErrorStats {
  int width = 0;
  int height = 0;
  double mseLinear = 0.0;
  double mseSrgb = 0.0;
  double psnrLinear = 0.0;  // +infinity for identical images
  double psnrSrgb = 0.0;
};

/// MSE and PSNR on both linear and sRGB values in one pass. Errors: as meanSquaredError's.
Result<ImageErrorStats> compareImages(const Image8& reference, const Image8& test);

/// Per-pixel squared error averaged over R, G, B.
struct ErrorMap {
  int width = 0;
  int height = 0;
  std::vector<float> values;  // width * height, rows top to bottom, each in [0, 1]

  float maxValue() const;
};

Result<ErrorMap> squaredErrorMap(const Image8& reference, const Image8& test, MetricSpace space);

/// The error map through the magma colour map, values / scale clamped to [0, 1]; scale <= 0 (the
/// default) uses the map's maximum (a zero map is all black-purple).
Image8 errorMapImage(const ErrorMap& map, float scale = 0.0f);

}  // namespace mfr
