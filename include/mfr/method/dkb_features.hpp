// The deep k-buffer's network inputs (Tsopouridis, Vasilakis, Fudos, "Deep hybrid
// order-independent transparency", sec. 3.1.1): 12 floats per pixel from one geometry pass. The
// paper lists the quantities; the normalisations are ours, chosen so every input is O(1) and
// independent of the image size, the scene scale and the depth-buffer precision:
//
//   #      feature (paper)                        value fed to the network
//   0      n(p) / sum n                           log2(1 + n(p) / nbar), nbar = sum n / covered
//   1      nearest depth d_n(p)                   (d_n(p) - D_n) / (D_f - D_n)   (0 if D_f = D_n)
//   2      farthest depth d_f(p)                  (d_f(p) - D_n) / (D_f - D_n)
//   3-5    colour of the nearest fragment         linear RGB x alpha (premultiplied)
//   6-8    average colour of the fragments        mean of linear RGB x alpha
//   9      F(M) / sum n                           min(1, F(M) / sum n)
//   10     image nearest depth D_n = min d_n(p)   window depth in [0, 1]
//   11     image farthest depth D_f = max d_f(p)  window depth in [0, 1]
//
// Depths are window depths (gl_FragCoord.z). Colours are premultiplied by the fragment's opacity
// because a fragment's share of the final colour (and so of the error of dropping it) scales with
// it; the paper's fully transparent scenes had one opacity, ours do not. Uncovered pixels have no
// features (they get importance 0 and no storage).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/method/fragment_node.hpp"

namespace mfr {

inline constexpr int kDkbFeatureCount = 12;

/// Identifier of the feature set above (order, normalisation): the one constant `mfr dataset`
/// records in datasets, `mfr train` in models, and checkDkbModel requires of a model ("features").
/// Change it whenever pixelFeatures changes, and retrain (scripts/train-model.sh).
inline constexpr const char* kDkbFeatureSet = "mfr-dkb-features-v1";
using PixelFeatures = std::array<float, kDkbFeatureCount>;

/// What the feature pass accumulates for one pixel (order-independent: min, max, sums; ties of the
/// nearest fragment broken by the node order, so the result does not depend on arrival order).
struct FeatureAccumulator {
  uint32_t n = 0;
  FragmentNode nearest = kFarNode;
  float farthest = 0.0f;
  glm::vec3 premultipliedSum{0.0f};
  void add(float depth, uint32_t rgba);
};

/// Image-level quantities of the frame (over covered pixels).
struct ImageFeatureStats {
  uint64_t fragments = 0;      // sum n(p)
  uint64_t coveredPixels = 0;  // pixels with n(p) > 0
  float nearest = 1.0f;        // D_n
  float farthest = 0.0f;       // D_f
  void add(const FeatureAccumulator& a);
  void merge(const ImageFeatureStats& o);
};

/// The 12 inputs of a covered pixel; `slots` = F(M).
PixelFeatures pixelFeatures(const FeatureAccumulator& pixel, const ImageFeatureStats& image,
                            uint64_t slots);

/// Image statistics of a feature pass.
ImageFeatureStats imageFeatureStats(const std::vector<FeatureAccumulator>& pixels);

}  // namespace mfr
