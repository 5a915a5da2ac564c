#include "mfr/metrics/image_metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "mfr/core/color.hpp"
#include "mfr/metrics/magma.hpp"

namespace mfr {

namespace {

std::string sizeText(const Image8& image) {
  std::string s = std::to_string(image.width);
  s += "x";
  s += std::to_string(image.height);
  return s;
}

Result<void> checkPair(const Image8& reference, const Image8& test) {
  if (reference.width != test.width || reference.height != test.height) {
    std::string message = "images differ in size: reference is ";
    message += sizeText(reference);
    message += ", test is ";
    message += sizeText(test);
    return makeError(message);
  }
  const size_t n = static_cast<size_t>(std::max(reference.width, 0)) *
                   static_cast<size_t>(std::max(reference.height, 0));
  if (reference.rgba.size() != n * 4 || test.rgba.size() != n * 4)
    return makeError("image pixel data does not match its size");
  return {};
}

// value of each 8-bit code in the given space
std::array<double, 256> valueTable(MetricSpace space) {
  std::array<double, 256> t;
  for (int c = 0; c < 256; ++c)
    t[c] = space == MetricSpace::Linear ? static_cast<double>(decodeSrgb8(static_cast<uint8_t>(c)))
                                        : c / 255.0;
  return t;
}

// squared difference of each pair of codes, summed over the three channels of a pixel
double pixelSquaredError(const uint8_t* a, const uint8_t* b, const std::array<double, 256>& t) {
  double s = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double d = t[a[c]] - t[b[c]];
    s += d * d;
  }
  return s;
}

}  // namespace

const char* metricSpaceName(MetricSpace space) {
  return space == MetricSpace::Linear ? "linear" : "srgb";
}

double psnrFromMse(double mse) {
  if (mse <= 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(1.0 / mse);
}

Result<double> meanSquaredError(const Image8& reference, const Image8& test, MetricSpace space) {
  MFR_TRY(checkPair(reference, test));
  const size_t n = static_cast<size_t>(reference.width) * static_cast<size_t>(reference.height);
  if (n == 0) return 0.0;
  const std::array<double, 256> t = valueTable(space);
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i)
    sum += pixelSquaredError(&reference.rgba[i * 4], &test.rgba[i * 4], t);
  return sum / (3.0 * static_cast<double>(n));
}

Result<ImageErrorStats> compareImages(const Image8& reference, const Image8& test) {
  ImageErrorStats s;
  s.width = reference.width;
  s.height = reference.height;
  auto linear = meanSquaredError(reference, test, MetricSpace::Linear);
  if (!linear) return linear.error();
  auto srgb = meanSquaredError(reference, test, MetricSpace::Srgb);
  if (!srgb) return srgb.error();
  s.mseLinear = *linear;
  s.mseSrgb = *srgb;
  s.psnrLinear = psnrFromMse(s.mseLinear);
  s.psnrSrgb = psnrFromMse(s.mseSrgb);
  return s;
}

float ErrorMap::maxValue() const {
  float m = 0.0f;
  for (float v : values) m = std::max(m, v);
  return m;
}

Result<ErrorMap> squaredErrorMap(const Image8& reference, const Image8& test, MetricSpace space) {
  MFR_TRY(checkPair(reference, test));
  ErrorMap map;
  map.width = reference.width;
  map.height = reference.height;
  const size_t n = static_cast<size_t>(map.width) * static_cast<size_t>(map.height);
  map.values.resize(n);
  const std::array<double, 256> t = valueTable(space);
  for (size_t i = 0; i < n; ++i)
    map.values[i] =
        static_cast<float>(pixelSquaredError(&reference.rgba[i * 4], &test.rgba[i * 4], t) / 3.0);
  return map;
}

Image8 errorMapImage(const ErrorMap& map, float scale) {
  if (!(scale > 0.0f)) scale = map.maxValue();
  if (!(scale > 0.0f)) scale = 1.0f;
  return magmaImage(map.values, map.width, map.height, scale);
}

}  // namespace mfr
