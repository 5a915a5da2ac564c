#include "mfr/scene/draw_order.hpp"

#include <utility>

namespace mfr {
namespace {

uint64_t splitMix64(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// uniform in [0, bound) by rejection (no modulo bias)
uint64_t below(uint64_t& state, uint64_t bound) {
  const uint64_t limit = UINT64_MAX - UINT64_MAX % bound;
  uint64_t x;
  do x = splitMix64(state);
  while (x >= limit);
  return x % bound;
}

}  // namespace

void shuffleDrawOrder(Scene& scene, uint64_t seed) {
  const size_t n = scene.triangleMaterial.size();
  uint64_t state = seed;
  for (size_t i = n; i > 1; --i) {
    const size_t j = below(state, i);
    if (j == i - 1) continue;
    std::swap(scene.triangleMaterial[i - 1], scene.triangleMaterial[j]);
    for (int c = 0; c < 3; ++c) std::swap(scene.indices[(i - 1) * 3 + c], scene.indices[j * 3 + c]);
  }
}

}  // namespace mfr
