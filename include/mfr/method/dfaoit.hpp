// Deep and Fast Approximate Order Independent Transparency.
//   G. Tsopouridis, A. A. Vasilakis, I. Fudos. "Deep and Fast Approximate Order Independent
//   Transparency". Computer Graphics Forum 43(2), 2024 (e15071); arXiv:2305.10197.
//
// The paper's scheme: one rendering pass accumulates per-pixel features in constant memory (no
// fragment nodes, no sorting), and a small pre-trained fully connected network predicts the pixel's
// OIT colour from them. mfr's version, its choices stated where they are ours:
//
//   accumulate  one geometry pass, per pixel (method_math.h's dfaoitAccumulate, in dfaoit.frag on
//               GL): the premultiplied colour sum sum a c (3 floats), sum a, sum a z, sum a c z
//               (3 floats; z the window depth), the transmittance T = prod (1 - a), the count n,
//               the farthest depth and the nearest fragment as a node (depth, RGBA8; the smallest
//               node, so ties do not depend on the arrival order and it is the A-buffer's first).
//               Alpha-0 fragments are skipped (they add nothing). 52 bytes per pixel, float32.
//   split       the pixel's colour is exactly a0 c0 + ((1 - a0) - T) y' + T background, with
//               (a0, c0) the nearest fragment and y' the visibility-weighted mean colour of the
//               fragments behind it (method_math.h's dfaoitComposite). The nearest fragment, the
//               coverage and the background are taken exactly; only y' is predicted. Ours (the
//               paper predicts the colour from its features directly).
//   features    the 12 inputs of method_math.h's dfaoitFeatures, of the fragments behind the
//               nearest (the sums less the nearest's terms): their alpha-weighted mean colour,
//               where each channel's colour sits in depth against their alpha, where their alpha
//               sits between the nearest and the farthest depth, their opacity, mean alpha and
//               1 / (n - 1); and the pixel's opacity and the nearest alpha. Ours:
//               the paper accumulates its own feature set (not reproduced here: the stored copy of
//               the paper available to this work gave its abstract and introduction only, and the
//               authors' shader code was not found in the stored repositories), so this set is
//               mfr's, chosen to be scale-free (every input O(1), no image-level statistic).
//   network     12 -> 32 -> 32 -> 3, ReLU, ReLU, sigmoid (learn::Mlp, the project's trainer
//               `mfr train`); 1,571 parameters. The size is mfr's (the paper's layer sizes were
//               not available to this work either), kept small so the per-pixel resolve stays
//               cheap on both engines. The output is y' = sum_{i >= 1} a_i T_i c_i /
//               ((1 - a0) - T) (T_i the transmittance in front of fragment i), in [0, 1], so one
//               network serves any background and an empty pixel is the background exactly. With
//               at most two fragments y' is known exactly (the rest is one fragment: y' = its
//               colour, the rest's mean colour x0-2) and the network is skipped: one and two
//               layers render exactly; the datasets hold pixels of three or more fragments.
//   colour      linear RGB throughout (inputs and target), like every method of mfr (which space
//               the paper's network works in was not checked: see above).
//   training    `mfr dataset --target dfaoit` on the procedural corpus only (the A-buffer's sorted
//               composite gives y' per pixel), `mfr train` (mean squared error, SGD with momentum),
//               scripts/train-dfaoit.sh; the model ships as models/dfaoit.mfrnn, compiled into the
//               library like the deep k-buffer's, reproducible bit for bit (the tiny reference
//               models/test/dfaoit-tiny.mfrnn, tests/dfaoit_repro_test.sh).
//
// Order independence: the sums are float sums in arrival order (the CPU engine's tile-owned
// capture: primitive order; fragment-parallel and GL: any), so another draw order changes their
// last bits only; the nearest node, the farthest depth and the count do not depend on the order.
// The image is therefore draw-order independent up to float rounding of the sums (measured: 1.7e-5
// at most on shuffled hairball and smoke scenes, Dfaoit.ShuffledDrawOrderChangesRoundingOnly).
// Memory: 52 B per pixel (plus the lock word of the fragment-parallel capture, and on GL).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/core/result.hpp"
#include "mfr/method/fragment_node.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_math.h"

namespace mfr {

namespace learn {
struct Model;
struct Mlp;
}  // namespace learn

using method_math::kDfaoitHidden;
using method_math::kDfaoitInputs;
using method_math::kDfaoitOutputs;

/// Identifier of the feature set (method_math.h's dfaoitFeatures): datasets and models record it,
/// checkDfaoitModel requires it. Change it whenever the features change, and retrain.
inline constexpr const char* kDfaoitFeatureSet = "mfr-dfaoit-features-v2";
/// The target definition: datasets and models record it.
inline constexpr const char* kDfaoitTarget =
    "visibility-weighted mean linear colour behind the nearest fragment sum_{i >= 1} a_i T_i c_i / "
    "((1 - a0) - T) (include/mfr/method/dfaoit.hpp)";
/// The network's layer sizes.
inline const std::vector<int> kDfaoitLayers = {kDfaoitInputs, kDfaoitHidden, kDfaoitHidden,
                                               kDfaoitOutputs};
/// The flat weights' length (dfaoitWeights' layout).
inline constexpr size_t kDfaoitWeightCount =
    size_t{kDfaoitHidden} * kDfaoitInputs + kDfaoitHidden + size_t{kDfaoitHidden} * kDfaoitHidden +
    kDfaoitHidden + size_t{kDfaoitOutputs} * kDfaoitHidden + kDfaoitOutputs;

using DfaoitInputs = std::array<float, kDfaoitInputs>;

/// One pixel's accumulators: 52 bytes.
struct DfaoitPixel {
  float r = 0.0f, g = 0.0f, b = 0.0f;     // sum a c
  float alphaSum = 0.0f;                  // sum a
  float alphaDepth = 0.0f;                // sum a z
  float rz = 0.0f, gz = 0.0f, bz = 0.0f;  // sum a c z
  float transmittance = 1.0f;             // prod (1 - a)
  uint32_t n = 0;                         // fragments with a > 0
  float farthest = 0.0f;                  // largest depth
  // the smallest (depth, colour) node, as two words (4-byte alignment: no padding)
  uint32_t nearDepthBits = static_cast<uint32_t>(kFarNode >> 32), nearColour = 0;

  FragmentNode nearest() const { return (uint64_t{nearDepthBits} << 32) | nearColour; }

  void add(float depth, uint32_t rgba) {
    const glm::vec4 c = unpackFragmentColor(rgba);
    if (c.a <= 0.0f) return;
    method_math::dfaoitAccumulate(r, g, b, alphaSum, alphaDepth, rz, gz, bz, transmittance,
                                  glm::vec3(c), c.a, depth);
    ++n;
    farthest = std::max(farthest, depth);
    if (const FragmentNode node = makeNode(depth, rgba); node < nearest()) {
      nearDepthBits = static_cast<uint32_t>(node >> 32);
      nearColour = rgba;
    }
  }

  /// The network's inputs (n >= 1).
  DfaoitInputs features() const;
};
static_assert(sizeof(DfaoitPixel) == 52);

/// The network's weights as one array, the layout dfaoit_resolve.comp reads: per layer its matrix
/// column-major (element (row, column) at column * rows + row, as Eigen stores it), then its bias.
std::vector<float> dfaoitWeights(const learn::Mlp& net);

/// The forward pass over flat weights (dfaoitWeights), the sums in index order (the shader's): the
/// predicted colour y.
glm::vec3 dfaoitForward(const float* weights, const DfaoitInputs& x);

/// Error unless the model fits DFAOIT: 12 inputs, 3 outputs, the layer sizes kDfaoitLayers and
/// metadata declaring kDfaoitFeatureSet and kDfaoitTarget.
Result<void> checkDfaoitModel(const learn::Model& model, const std::string& name);

/// The shipped model, models/dfaoit.mfrnn (compiled into the library), decoded and checked once.
Result<std::shared_ptr<const learn::Model>> builtinDfaoitModel();

/// The shipped model's flat weights (dfaoitWeights), computed once; empty when the build has no
/// model (the GL engine then refuses dfaoit with builtinDfaoitModel's error; the CPU engine
/// renders pixels of two or more fragments as the background).
const std::vector<float>& builtinDfaoitWeights();

/// A pixel's colour: the background when it holds no fragment; with one or two fragments y' is
/// the rest's mean colour (exact, no network); else the network's prediction; composited by
/// dfaoitComposite.
glm::vec3 dfaoitResolve(const DfaoitPixel& pixel, const float* weights, glm::vec3 background);

/// dfaoit as a peer method (peer_method.hpp): one accumulation pass into 52 bytes per pixel, the
/// network in the resolve.
struct DfaoitMethod {
  static constexpr Compositing kRule = Compositing::DeepApproximate;
  static constexpr const char* kRuleName = "deep-approximate";
  static PresetInfo preset() {
    return {"dfaoit", "deep and fast approximate OIT (Tsopouridis et al. 2024)",
            "one pass of per-pixel sums, a 12-32-32-3 network predicts the colour"};
  }
  using Slot = DfaoitPixel;
  static constexpr bool kNodes = false;
  static constexpr std::array<const char*, 0> kExtraPasses{};
  template <class Pixel>
  static void add(Pixel px, int /*pass*/, float depth, uint32_t rgba) {
    px.slots->add(depth, rgba);
    ++px.count;
  }
  static glm::vec3 composite(const DfaoitPixel* slots, uint32_t, glm::vec3 background) {
    const std::vector<float>& w = builtinDfaoitWeights();
    if (w.empty()) return background;
    return dfaoitResolve(*slots, w.data(), background);
  }
};

}  // namespace mfr
