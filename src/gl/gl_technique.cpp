// The GL engine's technique table and classifyGl (mfr/gl/gl_technique.hpp).
#include "mfr/gl/gl_technique.hpp"

#include <iterator>
#include <optional>
#include <string>

namespace mfr::gl {
namespace {

constexpr GlTechniqueInfo kTechniques[] = {
    {GlTechnique::ABuffer, "abuffer",
     "count -> prefix sum -> capture (append) -> resolve (sort, front-to-back over)",
     "capture_abuffer.frag", "resolve.comp",
     "n(p) 4 B + offset 4 B + fill counter 4 B + n(p) nodes of 8 B", "abuffer"},
    {GlTechnique::KBuffer, "kbuffer",
     "[count + allocation (variable k)] -> [depth range -> occupancy fill -> occupancy count] -> "
     "capture (k+ test, lock / interlock / 64-bit atomicMin) -> resolve (sort, kbuffer or hybrid)",
     "capture_kbuffer.frag, capture_kbuffer_atomic64.frag (+ swap_node_words.comp)", "resolve.comp",
     "k or k(p) nodes of 8 B + lock 4 B [+ allocation 8 B] [+ tail 20 B] [+ occupancy 12 + 4d B]",
     "zbuffer, fkb, kplus-array, kplus-heap, kplus-sb, kplus-dynamic, vkb, vkb-fill, dkb, "
     "dkb-fill, dkb-curve, optimal, optimal-greedy (and their +occupancy forms)"},
    {GlTechnique::Wboit, "wboit", "capture (accumulate under the lock) -> resolve", "wboit.frag",
     "wboit_resolve.comp", "accumulators 20 B + lock 4 B", "wboit"},
    {GlTechnique::Mboit, "mboit",
     "moments (accumulate) -> capture (colour, reconstructed transmittance) -> resolve",
     "mboit_moments.frag, mboit_color.frag", "mboit_resolve.comp",
     "accumulators 36 B (4 moments), 44 B (6 power or 3 trigonometric), 52 B (8 or 4); 16-bit "
     "moments: 28, 32, 36 B + lock 4 B",
     "mboit, mboit6, mboit8, mboit-trig3, mboit-trig4 and their -q16 forms"},
    {GlTechnique::Mlab, "mlab", "capture (insert, merge the two farthest when full) -> resolve",
     "mlab.frag", "mlab_resolve.comp", "k nodes of 20 B + node count 4 B + lock 4 B", "mlab"},
    {GlTechnique::Aoit, "aoit",
     "visibility (insert, remove the least-area node) -> capture (colour, visibility) -> resolve",
     "aoit_visibility.frag, aoit_color.frag", "aoit_resolve.comp",
     "nodes and colour sum 44 B (4 nodes), 76 B (8), 140 B (16) + lock 4 B",
     "aoit4, aoit8, aoit16"},
    {GlTechnique::LinkedList, "linked-list",
     "[count (no budget)] -> capture (pool counter atomicAdd, head atomicExchange; full pool: "
     "lost or hybrid tail) -> resolve (walk, selection sort in place, kbuffer or hybrid)",
     "capture_list.frag", "resolve_list.comp",
     "head 4 B [+ tail 20 B]; per image: pool counter 4 B + F(M) nodes of 12 B", "linked-list"},
    {GlTechnique::Peel, "peel",
     "peel passes (the nearest [and farthest] key under the lock, then peel_step.comp blends it "
     "and advances the bounds) until a pass peels every fragment in range or --max-peels -> "
     "[tail pass] -> resolve",
     "peel.frag (+ peel_step.comp)", "peel_resolve.comp",
     "state 36 B (peel) or 72 B (dual-peel) + lock 4 B [+ tail 20 B]", "peel, dual-peel"},
    {GlTechnique::Dfaoit, "dfaoit",
     "capture (accumulate the sums under the lock) -> resolve (features, 12-32-32-3 network, "
     "composite)",
     "dfaoit.frag", "dfaoit_resolve.comp",
     "accumulators 52 B + lock 4 B; per image: the network's 1,571 weights", "dfaoit"},
    {GlTechnique::Stochastic, "stochastic",
     "total alpha (T under the lock) -> stochastic depth (8 sample depths, atomicMin) -> capture "
     "(visibility-weighted sums under the lock) -> resolve (alpha-corrected composite)",
     "stochastic.frag", "stochastic_resolve.comp", "8 depths, T and sums 52 B + lock 4 B",
     "stochastic, stochastic-strat"},
    {GlTechnique::HashedAlpha, "hashed-alpha",
     "capture (alpha against the surface point's hash; the nearest kept under the lock) -> "
     "resolve",
     "hashed_alpha.frag", "hashed_alpha_resolve.comp", "depth and colour 8 B + lock 4 B",
     "hashed-alpha"},
};

constexpr bool rowsInEnumOrder() {
  for (size_t i = 0; i < std::size(kTechniques); ++i)
    if (static_cast<size_t>(kTechniques[i].technique) != i) return false;
  return true;
}
static_assert(rowsInEnumOrder(), "kTechniques lists the techniques in GlTechnique's order");

// the k-buffer family's stores and rules on the GL engine
bool kBufferStore(const MethodDesc& m) {
  switch (m.store) {
    case StoreChoice::MaxArray:
    case StoreChoice::MaxHeap:
      return true;
    case StoreChoice::PerPixel:  // K+B-SB: chosen per pixel from the allocation
      return m.allocation != AllocationPolicy::FixedK;
    case StoreChoice::Append:
    case StoreChoice::MultiLayer:
    case StoreChoice::None:
    case StoreChoice::LinkedList:
      return false;
  }
  return false;
}

bool kBufferAllocation(AllocationPolicy a) {
  switch (a) {
    case AllocationPolicy::FixedK:
    case AllocationPolicy::CountedK:
    case AllocationPolicy::DynamicK:
    case AllocationPolicy::Importance:
    case AllocationPolicy::Optimal:
      return true;
    case AllocationPolicy::Unbounded:
    case AllocationPolicy::NoNodes:
    case AllocationPolicy::Pool:
      return false;
  }
  return false;
}

// the technique a method's fields name, before the checks of its options
std::optional<GlTechnique> techniqueOf(const MethodDesc& m) {
  switch (m.compositing) {
    case Compositing::KBuffer:
    case Compositing::Hybrid:
      if (m.allocation == AllocationPolicy::Unbounded && m.store == StoreChoice::Append &&
          m.compositing == Compositing::KBuffer && m.occupancyWords == 0)
        return GlTechnique::ABuffer;
      if (m.allocation == AllocationPolicy::Pool && m.store == StoreChoice::LinkedList &&
          m.occupancyWords == 0)
        return GlTechnique::LinkedList;
      if (kBufferAllocation(m.allocation) && kBufferStore(m)) return GlTechnique::KBuffer;
      return std::nullopt;
    case Compositing::WeightedBlended:
    case Compositing::MomentBased:
    case Compositing::MomentBased6:
    case Compositing::MomentBased8:
    case Compositing::MomentBasedTrig3:
    case Compositing::MomentBasedTrig4:
    case Compositing::MomentBased16:
    case Compositing::MomentBased6_16:
    case Compositing::MomentBased8_16:
    case Compositing::MomentBasedTrig3_16:
    case Compositing::MomentBasedTrig4_16:
      if (m.allocation != AllocationPolicy::NoNodes || m.store != StoreChoice::None ||
          m.occupancyWords != 0)
        return std::nullopt;
      return m.compositing == Compositing::WeightedBlended ? GlTechnique::Wboit
                                                           : GlTechnique::Mboit;
    case Compositing::MultiLayerAlpha:
      if (m.allocation != AllocationPolicy::FixedK || m.store != StoreChoice::MultiLayer ||
          m.occupancyWords != 0)
        return std::nullopt;
      return GlTechnique::Mlab;
    case Compositing::Adaptive4:
    case Compositing::Adaptive8:
    case Compositing::Adaptive16:
      if (m.allocation != AllocationPolicy::NoNodes || m.store != StoreChoice::None ||
          m.occupancyWords != 0)
        return std::nullopt;
      return GlTechnique::Aoit;
    case Compositing::DeepApproximate:
      if (m.allocation != AllocationPolicy::NoNodes || m.store != StoreChoice::None ||
          m.occupancyWords != 0)
        return std::nullopt;
      return GlTechnique::Dfaoit;
    case Compositing::Peel:
    case Compositing::DualPeel:
      if (m.allocation != AllocationPolicy::NoNodes || m.store != StoreChoice::None ||
          m.occupancyWords != 0)
        return std::nullopt;
      return GlTechnique::Peel;
    case Compositing::Stochastic8:
    case Compositing::StochasticStrat8:
    case Compositing::HashedAlpha:
      if (m.allocation != AllocationPolicy::NoNodes || m.store != StoreChoice::None ||
          m.occupancyWords != 0)
        return std::nullopt;
      return m.compositing == Compositing::HashedAlpha ? GlTechnique::HashedAlpha
                                                       : GlTechnique::Stochastic;
  }
  return std::nullopt;
}

}  // namespace

std::span<const GlTechniqueInfo> glTechniques() {
  return kTechniques;
}

const GlTechniqueInfo& techniqueInfo(GlTechnique technique) {
  return kTechniques[static_cast<size_t>(technique)];
}

const char* toString(GlTechnique technique) {
  return techniqueInfo(technique).name;
}

Result<GlTechnique> classifyGl(const MethodDesc& method) {
  const std::optional<GlTechnique> t = techniqueOf(method);
  if (!t || method.occupancyWords < 0 || method.occupancyWords > 64)
    return makeError(
        "--engine gl: method " + method.name +
        " is not in the GL engine (it runs the A-buffer; the k-buffer family with a "
        "fixed k or a per-pixel k(p), max-array or max-heap stores, occupancy culling "
        "and kbuffer or hybrid compositing; wboit; mboit; mlab; aoit; linked-list; peel, "
        "dual-peel; dfaoit; stochastic, stochastic-strat; hashed-alpha)");
  return *t;
}

}  // namespace mfr::gl
