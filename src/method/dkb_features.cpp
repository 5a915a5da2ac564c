// The deep k-buffer's feature pass (DHOIT sec. 3.1.1); normalisations in dkb_features.hpp.
#include "mfr/method/dkb_features.hpp"

#include <algorithm>
#include <cmath>

#include "mfr/core/color.hpp"
#include "mfr/method/dkb_curve.hpp"

namespace mfr {
namespace {

float alphaOf(uint32_t rgba) {
  return static_cast<float>(rgba >> 24) / 255.0f;
}

glm::vec3 premultiplied(uint32_t rgba) {
  const ColorTables& t = ColorTables::get();
  return glm::vec3(t.srgb8ToLinear[rgba & 0xff], t.srgb8ToLinear[(rgba >> 8) & 0xff],
                   t.srgb8ToLinear[(rgba >> 16) & 0xff]) *
         alphaOf(rgba);
}

}  // namespace

void FeatureAccumulator::add(FragmentNode node, float depth, glm::vec3 premultipliedColour) {
  ++n;
  nearest = std::min(nearest, node);
  farthest = std::max(farthest, depth);
  premultipliedSum += premultipliedColour;
}

void FeatureAccumulator::add(float depth, uint32_t rgba) {
  add(makeNode(depth, rgba), depth, premultiplied(rgba));
}

void FeatureAccumulator::addWithCurveInputs(float depth, uint32_t rgba) {
  const FragmentNode node = makeNode(depth, rgba);
  second = node < nearest ? nearest : std::min(second, node);
  const glm::vec3 c = premultiplied(rgba);
  add(node, depth, c);
  premultipliedSquares += glm::dot(c, c);
  alphaSum += alphaOf(rgba);
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

PixelFeatures curvePixelFeatures(const FeatureAccumulator& pixel) {
  PixelFeatures f{};
  if (pixel.n == 0) return f;
  const float n = static_cast<float>(pixel.n);
  const uint32_t nearestColour = nodeColor(pixel.nearest);
  const glm::vec3 nearest = premultiplied(nearestColour);
  const glm::vec3 mean = pixel.premultipliedSum / n;
  f[0] = std::log2(n) / 4.0f;
  f[1] = alphaOf(nearestColour);
  f[2] = pixel.alphaSum / n;
  for (int c = 0; c < 3; ++c) {
    f[3 + c] = nearest[c];
    f[6 + c] = mean[c];
  }
  // the tail-only error err(0) and err(1) of the pixel seen as its two nearest fragments and the
  // rest as one fragment of the rest's tail colour (hybrid transparency's tail: weighted mean
  // colour, opacity 1 - (1 - mean alpha)^count): exact for three fragments of equal opacity
  const auto tailColour = [](glm::vec3 sum, float alphaSum, float count) {
    if (!(alphaSum > 1e-6f) || !(count > 0.0f)) return sum;
    return sum / alphaSum * (1.0f - std::pow(std::max(0.0f, 1.0f - alphaSum / count), count));
  };
  const float a1 = f[1];
  glm::vec3 second(0.0f);
  float a2 = 0.0f;
  if (pixel.n > 1) {
    a2 = alphaOf(nodeColor(pixel.second));
    second = premultiplied(nodeColor(pixel.second));
  }
  const glm::vec3 behindFirst = pixel.premultipliedSum - nearest;
  const float behindFirstAlpha = pixel.alphaSum - a1;
  const glm::vec3 behindSecond =
      tailColour(behindFirst - second, behindFirstAlpha - a2, std::max(0.0f, n - 2.0f));
  const glm::vec3 fromSecond = second + (1.0f - a2) * behindSecond;  // the estimate behind 1
  const glm::vec3 d0 =
      nearest + (1.0f - a1) * fromSecond - tailColour(pixel.premultipliedSum, pixel.alphaSum, n);
  const glm::vec3 d1 =
      (1.0f - a1) * (fromSecond - tailColour(behindFirst, behindFirstAlpha, n - 1.0f));
  f[9] = curveLogUnit(glm::dot(d0, d0));
  f[10] = curveLogUnit(glm::dot(d1, d1));
  if (pixel.n > 1) {  // the spread of the colours behind the nearest
    const glm::vec3 behindMean = behindFirst / (n - 1.0f);
    const float squares = pixel.premultipliedSquares - glm::dot(nearest, nearest);
    f[11] = std::sqrt(std::max(0.0f, squares / (n - 1.0f) - glm::dot(behindMean, behindMean)));
  }
  return f;
}

ImageFeatureStats imageFeatureStats(const std::vector<FeatureAccumulator>& pixels) {
  ImageFeatureStats s;
  for (const FeatureAccumulator& a : pixels) s.add(a);
  return s;
}

}  // namespace mfr
