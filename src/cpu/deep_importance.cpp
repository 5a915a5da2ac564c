// Deep k-buffer importance (DHOIT sec. 3.2): count pass with the image's depth range, then per
// tile the feature accumulation and one network batch. See deep_importance.hpp.
#include "mfr/cpu/deep_importance.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

#include "mfr/core/quote.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/model_file.hpp"
#include "shaded_fragments.hpp"

namespace mfr {
namespace {

using Clock = std::chrono::steady_clock;

// Adds a duration in nanoseconds to a shared counter.
void addNs(std::atomic<uint64_t>& total, Clock::time_point start) {
  total += static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start).count());
}

}  // namespace

std::vector<uint32_t> countWithDepthRange(const RasterFrame& frame, ImageFeatureStats& image) {
  std::vector<uint32_t> counts(frame.pixelCount(), 0);
  std::vector<ImageFeatureStats> perTile(frame.tileCount());
  frame.forEachTile([&](int tile) {
    ImageFeatureStats& s = perTile[tile];
    frame.rasterizeTile<ShadeMode::Coverage>(tile, CoverageAll{[&](uint32_t p, float z) {
                                               s.coveredPixels += counts[p] == 0;
                                               ++counts[p];
                                               ++s.fragments;
                                               s.nearest = std::min(s.nearest, z);
                                               s.farthest = std::max(s.farthest, z);
                                             }});
  });
  image = ImageFeatureStats{};
  for (const ImageFeatureStats& s : perTile) image.merge(s);  // tile order: deterministic
  return counts;
}

std::vector<float> predictImportance(const RasterFrame& frame, const learn::Model& model,
                                     const ImageFeatureStats& image, uint64_t slots,
                                     double* featureMs, double* inferenceMs) {
  std::vector<float> importance(frame.pixelCount(), 0.0f);
  std::atomic<uint64_t> featureNs{0}, inferenceNs{0};
  const double inverseWidth = 1.0 / frame.width();
  frame.forEachTile([&](int tile) {
    auto start = Clock::now();
    const TileRect r = frame.tileRect(tile);
    const int w = r.x1 - r.x0 + 1, h = r.y1 - r.y0 + 1;
    const uint32_t origin = static_cast<uint32_t>(r.y0) * frame.width() + r.x0;
    // the tile's scratch, reused by the worker from tile to tile
    thread_local std::vector<FeatureAccumulator> local;
    thread_local std::vector<int> covered;
    thread_local Eigen::MatrixXf inputs;
    local.assign(static_cast<size_t>(w) * h, FeatureAccumulator{});
    detail::forEachShadedFragment(frame, tile, [&](const Fragment& f) {
      // row and column in the tile without an integer division: (d + 0.5) / width is exact
      // enough
      const uint32_t d = f.pixel - origin;
      const uint32_t y = static_cast<uint32_t>((d + 0.5) * inverseWidth);
      const uint32_t x = d - y * frame.width();
      local[y * w + x].add(f.depth, f.rgba);
    });
    // the tile's covered pixels, in row order, are one batch (the same for any thread count)
    covered.clear();
    for (int i = 0; i < w * h; ++i)
      if (local[i].n > 0) covered.push_back(i);
    if (covered.empty()) {
      addNs(featureNs, start);
      return;
    }
    inputs.resize(kDkbFeatureCount, static_cast<Eigen::Index>(covered.size()));
    for (size_t j = 0; j < covered.size(); ++j) {
      const PixelFeatures f = pixelFeatures(local[covered[j]], image, slots);
      std::copy(f.begin(), f.end(), inputs.col(static_cast<Eigen::Index>(j)).data());
    }
    addNs(featureNs, start);
    start = Clock::now();
    const Eigen::MatrixXf out = learn::predict(model.net, inputs);
    for (size_t j = 0; j < covered.size(); ++j) {
      const int x = r.x0 + covered[j] % w, y = r.y0 + covered[j] / w;
      // a model whose activations overflow float predicts NaN: that pixel gets importance 0
      const float v = out(0, static_cast<Eigen::Index>(j));
      importance[static_cast<size_t>(y) * frame.width() + x] = std::isnan(v) ? 0.0f : v;
    }
    addNs(inferenceNs, start);
  });
  if (featureMs) *featureMs = static_cast<double>(featureNs.load()) * 1e-6;
  if (inferenceMs) *inferenceMs = static_cast<double>(inferenceNs.load()) * 1e-6;
  return importance;
}

std::vector<FeatureAccumulator> accumulateFeatures(const RasterFrame& frame) {
  std::vector<FeatureAccumulator> pixels(frame.pixelCount());
  frame.forEachTile([&](int tile) {
    detail::forEachShadedFragment(frame, tile, [&](const Fragment& f) {
      pixels[f.pixel].addWithCurveInputs(f.depth, f.rgba);
    });
  });
  return pixels;
}

}  // namespace mfr
