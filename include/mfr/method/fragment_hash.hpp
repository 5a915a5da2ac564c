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

#include "mfr/method/method_math.h"

namespace mfr {

// (written once in method_math.h, which the GL engine's shaders share)
using method_math::hashBelow;
using method_math::hashCombine;
using method_math::hashToUnit;
using method_math::pcgHash;

}  // namespace mfr
