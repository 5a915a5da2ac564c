// dkb-curve's feature, inference and allocation passes (issue 14 sec. 4; features and network of
// DHOIT sec. 3.1.3 / 3.2, allocation of DHOIT sec. 3.1.2's hull variant): see
// mfr/cpu/dkb_curve_pass.hpp.
#include "mfr/cpu/dkb_curve_pass.hpp"

#include <tbb/task_arena.h>

#include "mfr/cpu/deep_importance.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/dkb_curve.hpp"
#include "mfr/method/dkb_model.hpp"

namespace mfr {

Result<CurveChoice> predictedCurveK(const RasterFrame& frame, const MethodDesc& method,
                                    uint64_t slots) {
  auto model = dkbModelFor(method);
  if (!model) return model.error();
  // features of every pixel
  const std::vector<FeatureAccumulator> pixels = accumulateFeatures(frame);
  const ImageFeatureStats image = imageFeatureStats(pixels);
  CurveChoice out;
  out.n.resize(pixels.size());
  std::vector<uint32_t> covered;
  for (uint32_t p = 0; p < pixels.size(); ++p) {
    out.n[p] = pixels[p].n;
    if (pixels[p].n > 0) covered.push_back(p);
  }
  // under hybrid compositing a pixel may keep no slot (its tail alone) and the model's curves
  // start at k = 0; else allocate() reports a budget below one slot per covered pixel
  const uint32_t firstK = curveFirstK(method.compositing);
  MFR_CHECK_EQ(firstK, allowsTailOnlyPixels(method) ? 0u : 1u);
  if (firstK == 1 && slots < covered.size()) return out;
  // the network over the covered pixels (rows of 12 features: the hybrid model's own)
  std::vector<float> rows(covered.size() * kDkbFeatureCount);
  for (size_t i = 0; i < covered.size(); ++i) {
    const PixelFeatures f = firstK == 0 ? curvePixelFeatures(pixels[covered[i]])
                                        : pixelFeatures(pixels[covered[i]], image, slots);
    std::copy(f.begin(), f.end(), rows.begin() + static_cast<ptrdiff_t>(i * kDkbFeatureCount));
  }
  std::vector<float> predicted(covered.size() * kCurveOutputs);
  learn::predictRows((*model)->net, rows.data(), covered.size(), predicted.data());
  std::vector<float> predictions(pixels.size() * kCurveOutputs, 0.0f);
  for (size_t i = 0; i < covered.size(); ++i)
    std::copy_n(predicted.begin() + static_cast<ptrdiff_t>(i * kCurveOutputs), kCurveOutputs,
                predictions.begin() + static_cast<ptrdiff_t>(covered[i]) * kCurveOutputs);
  // the hull allocation over the rebuilt curves
  // (on the frame's workers, like its tile passes; the same k on any number)
  tbb::task_arena(frame.arenaThreads()).execute([&] {
    out.k = allocateByPredictedCurves(predictions, out.n, slots, firstK);
  });
  out.bytesAllocated = pixels.size() * (sizeof(FeatureAccumulator) + 4 * kCurveOutputs) +
                       (rows.size() + predicted.size()) * 4 +
                       (image.fragments + (firstK == 0 ? covered.size() : 0)) * sizeof(double) +
                       pixels.size() * sizeof(std::vector<double>);
  return out;
}

}  // namespace mfr
