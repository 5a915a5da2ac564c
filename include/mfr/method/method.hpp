// A method is a composition: allocation policy x fragment store x culling test x compositing rule,
// run as the passes count -> allocate -> capture -> resolve. The same description drives every
// backend; presets name the combinations of the papers.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/method/importance.hpp"

namespace mfr {

namespace learn {
struct Model;
}

/// How many fragment slots each pixel gets.
enum class AllocationPolicy : uint8_t {
  Unbounded,   // count pass, exact slots for every fragment (A-buffer / S-buffer)
  FixedK,      // the same k pre-allocated for every pixel (k-buffer, k+-buffer)
  CountedK,    // count pass capped at k, prefix-sum offsets, exact memory (K+B-SB)
  DynamicK,    // largest global k whose exact memory fits the budget, from the histogram
  Importance,  // k(p) = floor(P(p) F(M)) from an importance map (variable / deep k-buffer)
  Optimal,     // offline oracle: k(p) minimising the hybrid error from an exact A-buffer pre-pass
  NoNodes,     // no fragment nodes: per-pixel accumulators only (wboit, mboit)
  Pool,        // one node pool of F(M) 12-byte nodes shared by all pixels, first come first
               // served in primitive order (per-pixel linked lists, linked_list.hpp)
};

/// The store of one pixel, as the allocation picked it from the StoreChoice.
enum class StoreKind : uint8_t { Append, MaxArray, MaxHeap };

/// Which store holds a pixel's fragments.
enum class StoreChoice : uint8_t {
  Append,  // exact-size arrays (only with Unbounded)
  MaxArray,
  MaxHeap,
  PerPixel,    // K+B-SB rule: max-heap when n(p) > k(p) and k(p) > 16, else max-array
  MultiLayer,  // MLAB's blended nodes: depth-ordered insertion, two farthest merged when full
  None,        // no nodes (NoNodes allocation)
  LinkedList,  // per-pixel linked lists: a head word per pixel, nodes from the Pool allocation
};

enum class CullingTest : uint8_t {
  None,   // insertion with replacement, no test before the critical section
  KPlus,  // reject a fragment not nearer than the current maximum of a full store, re-check inside
};

/// Where an importance allocation's map comes from.
enum class ImportanceSource : uint8_t {
  Heuristic,  // depth complexity x periphery x Fresnel + noise (variable k-buffer)
  Network,    // the deep k-buffer's MLP over 12 per-pixel features
};

enum class Compositing : uint8_t {
  KBuffer,  // sort the captured fragments, composite front to back, drop the rest
  Hybrid,   // sorted core + order-independent tail (hybrid transparency)
  // The peer methods' own rules (docs/METHODS.md); --composite does not apply to them.
  WeightedBlended,      // wboit: weighted sums and revealage (McGuire & Bavoil 2013), wboit.hpp
  MomentBased,          // mboit: power moments, reconstructed transmittance (Muenstermann 2018)
  MomentBased6,         // mboit6: the same with 6 power moments (mboit.hpp)
  MomentBased8,         // mboit8: the same with 8 power moments (mboit.hpp)
  MomentBasedTrig3,     // mboit-trig3: 3 trigonometric moments (mboit.hpp)
  MomentBasedTrig4,     // mboit-trig4: 4 trigonometric moments (mboit.hpp)
  MomentBased16,        // mboit-q16: 4 power moments stored in 16 bits (mboit.hpp)
  MomentBased6_16,      // mboit6-q16
  MomentBased8_16,      // mboit8-q16
  MomentBasedTrig3_16,  // mboit-trig3-q16
  MomentBasedTrig4_16,  // mboit-trig4-q16
  MultiLayerAlpha,      // mlab: front-to-back over of the MultiLayer store's nodes (Salvi 2014)
  Adaptive4,            // aoit4: adaptive transparency, 4 visibility nodes (Salvi 2011), aoit.hpp
  Adaptive8,            // aoit8: the same with 8 nodes
  Adaptive16,           // aoit16: the same with 16 nodes
  Peel,                 // peel: depth peeling, one nearest layer per geometry pass (Everitt 2001)
  DualPeel,             // dual-peel: nearest and farthest layer per pass (Bavoil & Myers 2008)
  DeepApproximate,      // dfaoit: per-pixel sums, a network predicts the colour (Tsopouridis
                        // 2024), dfaoit.hpp
  Stochastic8,          // stochastic: stochastic transparency, 8 samples (Enderton 2010),
                        // stochastic.hpp
  StochasticStrat8,     // stochastic-strat: the same, stratified (Laine & Karras 2011)
  HashedAlpha,          // hashed-alpha: hashed alpha testing (Wyman & McGuire 2017),
                        // hashed_alpha.hpp
};

/// True for kbuffer and hybrid, the rules `--composite` chooses between (the k-buffer family).
bool kBufferFamilyRule(Compositing c);

struct MethodDesc {
  std::string name;
  AllocationPolicy allocation = AllocationPolicy::Unbounded;
  StoreChoice store = StoreChoice::Append;
  CullingTest culling = CullingTest::None;
  bool perPixelLock = false;  // spin-lock word per pixel (k+-buffer family)
  int occupancyWords = 0;     // 0: no occupancy culling; d > 0: 32*d buckets
  Compositing compositing = Compositing::KBuffer;
  std::optional<uint32_t> k;  // explicit k (otherwise derived from the budget)
  ImportanceSource importanceSource = ImportanceSource::Heuristic;  // Importance allocation only
  ImportanceParams importance;                                      // heuristic importance only
  /// Network importance: the model (null: the built-in model, builtinDkbModel()).
  std::shared_ptr<const learn::Model> model;
  /// Importance allocation: one slot for every covered pixel, the rest by importance capped at
  /// n(p), and the freed and floor() remainder slots to the pixels with the largest unmet
  /// importance (vkb-fill), instead of the paper's exact rule. Under hybrid compositing the cap is
  /// n(p) - 1 (a tail of one fragment is exact) and a pixel of one fragment gets no slot.
  bool fillUnusedSlots = false;
  /// Optimal allocation: DHOIT's Algorithm 1 as published instead of the convex-hull allocator.
  bool publishedGreedy = false;
  /// Optimal allocation over error curves a network predicts from the deep k-buffer's features
  /// (dkb-curve, mfr/method/dkb_curve.hpp) instead of the exact A-buffer pre-pass's; `model`
  /// then holds a curve model (null: the built-in one).
  bool predictedCurves = false;
  /// Depth peeling (peel, dual-peel; peel.hpp): at most this many geometry passes (--max-peels;
  /// none: until no fragment remains). The fragments left after them are dropped, or blended
  /// into the hybrid tail when `peelTail`.
  std::optional<uint32_t> maxPeels;
  /// Depth peeling under --composite hybrid: the fragments left after maxPeels passes go to the
  /// order-independent tail (compositing.hpp's rule) behind the peeled front layers.
  bool peelTail = false;
};

/// One row of the preset table (src/method/method.cpp): the name, the paper it follows and a
/// one-line summary. The CLI help, `mfr presets`, the README's table and the compare
/// report's legend are generated from it, so they cannot disagree.
struct PresetInfo {
  std::string name;
  std::string paper;
  std::string summary;
};
const std::vector<PresetInfo>& presetTable();

/// The preset table as Markdown (the README's, between its `presets` markers).
std::string presetTableMarkdown();

/// Preset names: zbuffer, abuffer, fkb, kplus-array, kplus-heap, kplus-sb, kplus-dynamic, vkb,
/// vkb-fill, dkb, dkb-fill, dkb-curve, optimal, optimal-greedy, each bounded one optionally
/// followed by
/// "+occupancy"; and the peer methods wboit, mboit, mlab (no +occupancy).
std::vector<std::string> presetNames();

/// Looks up a preset ("kplus-heap", "fkb+occupancy", ...). Errors list the known names.
/// The description is a plain value: adjust it (k, compositing, occupancyWords, importance, model)
/// before render(); which adjustments a preset accepts is method_options.hpp's table. `model` is
/// shared (std::shared_ptr), not copied, so one network can serve many descriptions.
Result<MethodDesc> methodPreset(const std::string& name);

const char* toString(AllocationPolicy a);
const char* toString(StoreChoice s);
const char* toString(CullingTest c);
const char* toString(Compositing c);
Result<Compositing> parseCompositing(const std::string& text);

}  // namespace mfr
