// The deep k-buffer's feature pass (DHOIT sec. 3.1.1); normalisations in dkb_features.hpp.
#include "mfr/method/dkb_features.hpp"

#include <algorithm>
#include <cmath>

#include "mfr/core/color.hpp"

namespace mfr {
namespace {

glm::vec3 premultiplied(uint32_t rgba) {
  const ColorTables& t = ColorTables::get();
  const float alpha = static_cast<float>(rgba >> 24) / 255.0f;
  return glm::vec3(t.srgb8ToLinear[rgba & 0xff], t.srgb8ToLinear[(rgba >> 8) & 0xff],
                   t.srgb8ToLinear[(rgba >> 16) & 0xff]) *
         alpha;
}

}  // namespace

void FeatureAccumulator::add(float depth, uint32_t rgba) {
  ++n;
  nearest = std::min(nearest, makeNode(depth, rgba));
  farthest = std::max(farthest, depth);
  premultipliedSum += premultiplied(rgba);
}

void ImageFeatureStats::add(const FeatureAccumulator& a) {
  if (a.n == 0) return;
  fragments += a.n;
  ++coveredPixels;
  nearest = std::min(nearest, nodeDepth(a.nearest));
  farthest = std::max(farthest, a.farthest);
}

void ImageFeatureStats::merge(const ImageFeatureStats& o) {
  fragments += o.fragments;
  coveredPixels += o.coveredPixels;
  nearest = std::min(nearest, o.nearest);
  farthest = std::max(farthest, o.farthest);
}

PixelFeatures pixelFeatures(const FeatureAccumulator& pixel, const ImageFeatureStats& image,
                            uint64_t slots) {
  PixelFeatures f{};
  if (pixel.n == 0 || image.fragments == 0) return f;
  const double meanN = static_cast<double>(image.fragments) / image.coveredPixels;
  f[0] = static_cast<float>(std::log2(1.0 + pixel.n / meanN));
  const float range = image.farthest - image.nearest;
  const auto relativeDepth = [&](float z) {
    return range > 0.0f ? std::clamp((z - image.nearest) / range, 0.0f, 1.0f) : 0.0f;
  };
  f[1] = relativeDepth(nodeDepth(pixel.nearest));
  f[2] = relativeDepth(pixel.farthest);
  const glm::vec3 nearest = premultiplied(nodeColor(pixel.nearest));
  const glm::vec3 mean = pixel.premultipliedSum / static_cast<float>(pixel.n);
  for (int c = 0; c < 3; ++c) {
    f[3 + c] = nearest[c];
    f[6 + c] = mean[c];
  }
  f[9] = static_cast<float>(std::min(1.0, static_cast<double>(slots) / image.fragments));
  f[10] = image.nearest;
  f[11] = image.farthest;
  return f;
}

ImageFeatureStats imageFeatureStats(const std::vector<FeatureAccumulator>& pixels) {
  ImageFeatureStats s;
  for (const FeatureAccumulator& a : pixels) s.add(a);
  return s;
}

}  // namespace mfr
