// Importance maps of the variable k-buffer (paper sec. 3.2, Eqs. 3-6); see importance.hpp.
#include "mfr/method/importance.hpp"

#include <algorithm>

#include "mfr/method/method_math.h"

namespace mfr {

namespace mm = method_math;  // the terms, shared with shaders/importance.comp

float importanceNoise(uint64_t seed, uint64_t pixel) {
  // SplitMix64 finaliser of (seed, pixel): deterministic, no state shared between threads
  uint64_t z = seed * mm::words64(mm::kSplitMixGammaLo, mm::kSplitMixGammaHi) + pixel +
               mm::words64(mm::kSplitMixOffsetLo, mm::kSplitMixOffsetHi);
  z = (z ^ (z >> mm::kSplitMixShift1)) * mm::words64(mm::kSplitMixMul1Lo, mm::kSplitMixMul1Hi);
  z = (z ^ (z >> mm::kSplitMixShift2)) * mm::words64(mm::kSplitMixMul2Lo, mm::kSplitMixMul2Hi);
  z ^= z >> mm::kSplitMixShift3;
  return static_cast<float>(z >> mm::kSplitMixKeepShift) * mm::kImportanceNoiseUnit;
}

ImportanceMaps computeImportance(int width, int height, const std::vector<uint32_t>& n,
                                 const std::vector<float>& previousCosine,
                                 const ImportanceParams& p) {
  const size_t pixels = static_cast<size_t>(width) * height;
  ImportanceMaps m;
  m.importance.assign(pixels, 0.0f);
  m.depth.assign(pixels, 0.0f);
  m.periphery.assign(pixels, 0.0f);
  m.fresnel.assign(pixels, 0.0f);
  m.noise.assign(pixels, 0.0f);
  const glm::vec2 fovea = p.fovea.value_or(glm::vec2(width * 0.5f, height * 0.5f));
  const float diagonal =
      mm::importanceDiagonal(static_cast<float>(width), static_cast<float>(height));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      if (n[i] == 0) continue;
      const float id =
          p.useDepth ? mm::importanceDepth(p.alpha, 1.0f - p.alpha, n[i], p.nLimit) : 1.0f;
      // (the exponent's integer form only matters to the GLSL side's powf, mm::hostPow)
      const float iper = p.usePeriphery ? mm::importancePeriphery(static_cast<uint32_t>(x),
                                                                  static_cast<uint32_t>(y), fovea,
                                                                  diagonal, p.peripheryExponent, -1)
                                        : 1.0f;
      const float cosine =
          previousCosine.empty() ? 1.0f : std::clamp(previousCosine[i], 0.0f, 1.0f);
      const float ifr = p.useFresnel ? mm::importanceFresnel(cosine) : 1.0f;
      const float noise =
          p.useNoise ? mm::importanceNoiseTerm(p.noise, importanceNoise(p.seed, i)) : 0.0f;
      m.depth[i] = id;
      m.periphery[i] = iper;
      m.fresnel[i] = ifr;
      m.noise[i] = noise;
      m.importance[i] = mm::importanceCombine(iper, id, ifr, noise);
    }
  return m;
}

}  // namespace mfr
