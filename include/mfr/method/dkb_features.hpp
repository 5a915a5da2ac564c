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
// dkb-curve's hybrid model has its own 12 inputs (curvePixelFeatures, kDkbCurveFeatureSet; issue
// 28): what the hybrid tail's error depends on, the fragments' colours and opacities, rather than
// the image's depth range and the budget (a curve does not depend on the budget):
//
//   #      feature                                value fed to the network
//   0      the pixel's fragment count             log2(n(p)) / 4 (the curve's length is absolute)
//   1      opacity of the nearest fragment        alpha
//   2      mean opacity                           mean alpha
//   3-5    colour of the nearest fragment         linear RGB x alpha (as above)
//   6-8    average colour of the fragments        mean of linear RGB x alpha (as above)
//   9      estimate of err(0), the tail alone     curveLogUnit(|C3 - tail(all)|^2), below
//   10     estimate of err(1)                     curveLogUnit((1 - a1)^2 |C3' - tail(behind 1)|^2)
//   11     colour spread behind the nearest       sqrt(mean |a c|^2 - |mean a c|^2) over the
//                                                 fragments but the nearest
//
// Features 9 and 10 see the pixel as three fragments: its two nearest (a1 c1, a2 c2; the feature
// pass keeps both) and the rest as one fragment of the rest's own tail colour, with hybrid
// transparency's tail (Maule et al. 2013, as method_math.h's hybridBehind): tail(S, A, m) =
// S / A * (1 - (1 - A / m)^m) for m fragments of premultiplied sum S and alpha sum A. Behind the
// nearest that is C3' = a2 c2 + (1 - a2) tail(behind 2), and in all C3 = a1 c1 + (1 - a1) C3';
// err(0) compares C3 with the tail of every fragment, err(1) C3' with the tail of the fragments
// behind the nearest, seen through the nearest. The background's share is left out (it cancels
// when the opacities are equal). Both are exact for up to three fragments of one opacity (most
// pixels of a closed mesh at one alpha) and are on the targets' log scale, so for such pixels the
// first two drops follow from them; 11 tells how far the rest is from one colour.
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
/// The same for curvePixelFeatures (dkb-curve's hybrid model).
inline constexpr const char* kDkbCurveFeatureSet = "mfr-dkb-curve-features-v1";
using PixelFeatures = std::array<float, kDkbFeatureCount>;

/// What the feature pass accumulates for one pixel (order-independent: min, max, sums; ties of the
/// nearest fragment broken by the node order, so the result does not depend on arrival order).
struct FeatureAccumulator {
  uint32_t n = 0;
  FragmentNode nearest = kFarNode;
  float farthest = 0.0f;
  glm::vec3 premultipliedSum{0.0f};
  // dkb-curve's hybrid inputs (curvePixelFeatures), kept by addWithCurveInputs only
  FragmentNode second = kFarNode;     // the second nearest
  float premultipliedSquares = 0.0f;  // sum of |linear RGB x alpha|^2
  float alphaSum = 0.0f;
  /// The deep k-buffer's inputs (pixelFeatures).
  void add(float depth, uint32_t rgba);
  /// The same and dkb-curve's hybrid inputs (accumulateFeatures; the paper's feature pass,
  /// predictImportance, needs add alone).
  void addWithCurveInputs(float depth, uint32_t rgba);

 private:
  void add(FragmentNode node, float depth, glm::vec3 premultipliedColour);
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

/// dkb-curve's 12 hybrid inputs of a covered pixel (the second table above); zeros when
/// uncovered.
PixelFeatures curvePixelFeatures(const FeatureAccumulator& pixel);

/// Image statistics of a feature pass.
ImageFeatureStats imageFeatureStats(const std::vector<FeatureAccumulator>& pixels);

}  // namespace mfr
