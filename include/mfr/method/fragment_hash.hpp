// The integer hash the stochastic peer methods draw their random numbers from (stochastic.hpp,
// hashed_alpha.hpp): a fragment's "random" choices are a pure function of what identifies it, so
// every geometry pass of a frame, every thread count and every capture order sees the same ones.
//
// The hash is PCG's output permutation over one LCG step (Jarzynski & Olano, "Hash Functions for
// GPU Rendering", JCGT 9(3), 2020, the "pcg" hash they recommend): 32-bit integer multiplies,
// shifts and xors only, so a GLSL port (uint arithmetic) gives the same bits. Several words are
// folded in by hashing each into the running value (hashCombine). Written in the C++ subset that
// GLSL shares (uint32, no library calls).
#pragma once

#include <cstdint>

namespace mfr {

/// PCG hash of one 32-bit word.
constexpr uint32_t pcgHash(uint32_t v) {
  const uint32_t state = v * 747796405u + 2891336453u;
  const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

/// Folds `word` into the running hash `h`.
constexpr uint32_t hashCombine(uint32_t h, uint32_t word) {
  return pcgHash(h ^ pcgHash(word));
}

/// A hash as a float in [0, 1): its top 24 bits over 2^24 (exact in float).
constexpr float hashToUnit(uint32_t h) {
  return static_cast<float>(h >> 8u) * (1.0f / 16777216.0f);
}

/// A hash as an integer uniform in [0, n): the top of the 64-bit product h * n (Lemire's
/// multiply-shift; the bias is below n / 2^32).
constexpr uint32_t hashBelow(uint32_t h, uint32_t n) {
  return static_cast<uint32_t>((static_cast<uint64_t>(h) * n) >> 32u);
}

}  // namespace mfr
