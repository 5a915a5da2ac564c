// Submission order of a scene's triangles: `mfr render/compare --shuffle-draw-order SEED` submits
// them in a seeded random order, to check which methods depend on the order fragments arrive in.
#pragma once

#include <cstdint>

#include "mfr/scene/scene.hpp"

namespace mfr {

/// Permutes the triangles (indices and per-triangle materials together) with a Fisher-Yates
/// shuffle driven by SplitMix64(seed): the same permutation on every platform and compiler.
void shuffleDrawOrder(Scene& scene, uint64_t seed);

}  // namespace mfr
