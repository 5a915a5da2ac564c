// RenderStats helpers and the per-sample reduction (mfr/method/render_output.hpp).
#include "mfr/method/render_output.hpp"

#include <algorithm>

namespace mfr {
namespace {

// Each run of `samples` consecutive values (one pixel's samples) summed, or averaged with `mean`
// (the box filter), in place.
template <class T>
void reduceSamples(std::vector<T>& v, int samples, bool mean) {
  for (size_t p = 0; p < v.size() / samples; ++p) {
    T sum = T(0);
    for (int s = 0; s < samples; ++s) sum += v[p * samples + s];
    if (mean)
      v[p] = sum / static_cast<float>(samples);
    else
      v[p] = sum;
  }
  v.resize(v.size() / samples);
}

}  // namespace

void toImagePixels(RenderOutput& out, int samples) {
  reduceSamples(out.image.pixels, samples, true);
  out.image.width /= samples;
  reduceSamples(out.kMap, samples, false);
  reduceSamples(out.depthComplexity, samples, false);
  reduceSamples(out.importance.importance, samples, true);
  reduceSamples(out.nearestCosine, samples, true);
}

double RenderStats::totalMs() const {
  double total = 0.0;
  for (const PassTime& p : passes) total += p.ms;
  return total;
}

void edgeStatistics(const std::vector<uint32_t>& n, const std::vector<uint32_t>& captured,
                    const std::vector<uint8_t>& edges, int perPixel, RenderOutput& out) {
  RenderStats& st = out.stats;
  out.lostPerPixel.assign(edges.size(), 0);
  for (size_t q = 0; q < n.size(); ++q) {
    const uint32_t held = q < captured.size() ? std::min(captured[q], n[q]) : n[q];
    const size_t pixel = q / static_cast<size_t>(perPixel);
    out.lostPerPixel[pixel] += n[q] - held;
    (edges[pixel] ? st.lostAtEdges : st.lostInside) += n[q] - held;
    (edges[pixel] ? st.fragmentsAtEdges : st.fragmentsInside) += n[q];
  }
  st.edgePixels = static_cast<uint64_t>(std::count(edges.begin(), edges.end(), uint8_t{1}));
}

}  // namespace mfr
