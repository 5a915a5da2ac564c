// Stochastic transparency, and its stratified sampling.
//   E. Enderton, E. Sintorn, P. Shirley, D. Luebke. "Stochastic Transparency". Proceedings of the
//   ACM SIGGRAPH Symposium on Interactive 3D Graphics and Games (I3D) 2010, pp. 157-164; IEEE
//   Transactions on Visualization and Computer Graphics 17(8), 2011.
//   S. Laine, T. Karras. "Stratified Sampling for Stochastic Transparency". Computer Graphics
//   Forum 30(4) (EGSR 2011), pp. 1197-1204.
//
// Per pixel S depth samples (a stochastic z-buffer, every sample at kStochasticFarDepth) and the
// accumulators; S = 8 for both presets (stochastic, stochastic-strat). Three geometry passes, the
// first two before the capture (kExtraPasses), fragments of alpha a_i = alpha8 / 255 at window
// depth z_i with linear colour c_i:
//   1. total-alpha       T = prod (1 - a_i)                       (the paper's alpha pass)
//   2. stochastic-depth  the fragment covers the samples of its mask m_i (about a_i S of them);
//                        each covered sample keeps the nearest depth: d_j = min(d_j, z_i)
//   3. capture           vis_i = #{j : d_j >= z_i} / S  (the samples nothing nearer covered; a
//                        fragment's own samples count, their depth being z_i or nearer only by
//                        another fragment), C += vis_i a_i c_i,  A += vis_i a_i
//   composite            C / A (1 - T) + T background      (A = 0: the background; the paper's
//                        alpha correction: the colours' visibility-weighted mean scaled to the
//                        exact total opacity)
// E[vis_i] = prod over the fragments in front of (1 - a_j) when each sample is covered with
// probability a_j independently across fragments, so C and A are unbiased; the ratio C / A is
// consistent (its bias falls as 1 / S). With every alpha 0 or 1 the masks are empty or full and
// the result is the exact nearest opaque fragment; one fragment alone gets vis = 1 and is exact.
//
// Masks: a pure function of the fragment (stochasticMask), so passes 2 and 3 draw the same one:
// the key hashes the pixel index, the depth's bits and the colour word (fragment_hash.hpp), not
// the primitive id, so the image does not depend on the draw order either (a shuffled scene
// renumbers its triangles; their fragments stay the same). Two fragments equal in pixel, depth
// and colour get one mask: they composite exactly as two such coincident layers should, only the
// fragments behind them see one mask's occlusion instead of two independent ones.
//   unstratified (Enderton et al.): sample j is covered when v_j < alpha8, v_j a hash of (key, j)
//     uniform over the integers [0, 255): each sample with probability exactly a_i, the count
//     binomial(S, a_i);
//   stratified (Laine & Karras' stratification in the alpha domain): the samples' reference values
//     are x_j = (pi(j) + u) / S, pi a random permutation of the samples and u one random offset,
//     both per fragment (so distinct fragments are uncorrelated), and sample j is covered when
//     x_j < a_i. The count is then ceil(a_i S - u): floor(a_i S) or one more, with mean exactly
//     a_i S; the covered samples are a uniformly random subset of that size (partial
//     Fisher-Yates over the permutation). u is drawn over 255 levels so the mean is exact for the
//     8-bit alpha: with v uniform over [0, 255), n = #{m < S : 255 m + v < alpha8 S}.
//   The paper's other refinements concern the samples' positions in the pixel (spatial
//   stratification, surface tracking across a surface's triangles): mfr's S samples all sit at
//   the pixel centre, so the sample order carries no position and they do not apply; its
//   improvement for partially occluded layers is not implemented.
// Storage: S float depths + T + C (3 floats) + A: 4 S + 20 bytes (52 B for S = 8), float32
// throughout (the paper keeps the depth samples in an MSAA depth buffer and C, A, T in colour
// targets; mfr charges what it stores). Order: the depth minimum and the masks do not depend on
// the arrival order; the sums are float sums in arrival order (tile-owned capture: primitive
// order, the same image for any thread count).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/fragment_hash.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/peer_fragment.hpp"

namespace mfr {

// The maths (the key, the masks, the visibility, the composite) are method_math.h's, which the
// GL engine's shaders share.
using method_math::kStochasticFarDepth;
using method_math::kStochasticMaxSamples;
using method_math::stochasticMask;

/// What identifies a fragment, hashed: its pixel, the depth's bits and the colour word.
inline uint32_t stochasticKey(uint32_t pixel, float depth, uint32_t rgba) {
  return method_math::stochasticKey(pixel, std::bit_cast<uint32_t>(depth), rgba);
}

/// One pixel's buffers with S samples: 4 S + 20 bytes.
template <int S>
struct StochasticPixel {
  static_assert(S >= 1 && S <= kStochasticMaxSamples);
  std::array<float, S> depth = filledFar();  // the stochastic z-buffer
  float trans = 1.0f;                        // pass 1: prod (1 - a)
  float r = 0.0f, g = 0.0f, b = 0.0f;        // pass 3: sum vis a c
  float a = 0.0f;                            // pass 3: sum vis a

  static constexpr std::array<float, S> filledFar() {
    std::array<float, S> d{};
    for (float& x : d) x = kStochasticFarDepth;
    return d;
  }
  void addDepth(uint32_t mask, float z) {
    for (int j = 0; j < S; ++j)
      if ((mask >> j) & 1u) depth[j] = std::min(depth[j], z);
  }
  /// The fraction of samples nothing nearer than z covered.
  float visibility(float z) const {
    int seen = 0;
    for (int j = 0; j < S; ++j) seen += depth[j] >= z ? 1 : 0;
    return method_math::stochasticVisibility(seen, S);
  }
  glm::vec3 composite(glm::vec3 background) const {
    return method_math::stochasticComposite(glm::vec3(r, g, b), a, trans, background);
  }
};
static_assert(sizeof(StochasticPixel<8>) == 52 && sizeof(StochasticPixel<16>) == 84 &&
              sizeof(StochasticPixel<32>) == 148);

/// The total-alpha and stochastic-depth passes, then the capture weighting each fragment by its
/// stochastic visibility: both stochastic presets.
template <int S, bool Stratified>
struct StochasticPasses {
  using Slot = StochasticPixel<S>;
  static constexpr int kSamples = S;
  static constexpr bool kStratified = Stratified;
  static constexpr bool kNodes = false;
  static constexpr std::array<const char*, 2> kExtraPasses{"total-alpha", "stochastic-depth"};

  static uint32_t maskOf(const PeerFragment& f) {
    return stochasticMask(S, Stratified, stochasticKey(f.pixel, f.depth, f.rgba), f.rgba >> 24);
  }
  template <class PeerPixel>
  static void add(PeerPixel px, int pass, const PeerFragment& f) {
    Slot& p = *px.slots;
    const uint32_t alpha8 = f.rgba >> 24;
    if (pass == 0) {
      // the same alpha as the capture's (unpackFragmentColor): x * (1 / 255)
      p.trans *= 1.0f - static_cast<float>(alpha8) * (1.0f / 255.0f);
      return;
    }
    if (pass == 1) {
      if (alpha8 != 0u) p.addDepth(maskOf(f), f.depth);
      return;
    }
    ++px.count;
    const glm::vec4 c = unpackFragmentColor(f.rgba);
    if (c.a <= 0.0f) return;
    const float w = p.visibility(f.depth) * c.a;
    p.r += w * c.r;
    p.g += w * c.g;
    p.b += w * c.b;
    p.a += w;
  }
  static glm::vec3 composite(const Slot* slots, uint32_t, glm::vec3 background) {
    return slots->composite(background);
  }
};

/// stochastic: 8 samples, each covered independently with probability alpha; 52 bytes per pixel.
struct Stochastic8Method : StochasticPasses<8, false> {
  static constexpr Compositing kRule = Compositing::Stochastic8;
  static constexpr const char* kRuleName = "stochastic-8";
  static PresetInfo preset() {
    return {"stochastic", "stochastic transparency, 8 samples (Enderton et al. 2010)",
            "8 stochastic depth samples + alpha-corrected sums per pixel, noisy, no sorting"};
  }
};

/// stochastic-strat: 8 samples, the covered count stratified (Laine & Karras); 52 bytes per pixel.
struct StochasticStrat8Method : StochasticPasses<8, true> {
  static constexpr Compositing kRule = Compositing::StochasticStrat8;
  static constexpr const char* kRuleName = "stochastic-stratified-8";
  static PresetInfo preset() {
    return {"stochastic-strat",
            "stratified stochastic transparency, 8 samples (Laine & Karras 2011)",
            "as stochastic, each fragment covering floor(a S) or +1 samples (stratified alpha)"};
  }
};

}  // namespace mfr
