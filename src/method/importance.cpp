// Importance maps of the variable k-buffer (paper sec. 3.2, Eqs. 3-6); see importance.hpp.
#include "mfr/method/importance.hpp"

#include <algorithm>
#include <cmath>

namespace mfr {

float importanceNoise(uint64_t seed, uint64_t pixel) {
  // SplitMix64 finaliser of (seed, pixel): deterministic, no state shared between threads
  uint64_t z = seed * 0x9E3779B97F4A7C15ull + pixel + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<float>(z >> 40) * (1.0f / 16777216.0f);
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
      1.1f * std::sqrt(static_cast<float>(width) * width + static_cast<float>(height) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      if (n[i] == 0) continue;
      const float id =
          p.useDepth
              ? p.alpha + (1.0f - p.alpha) * std::min(1.0f, static_cast<float>(n[i]) / p.nLimit)
              : 1.0f;
      const glm::vec2 centre(x + 0.5f, y + 0.5f);
      const float iper =
          p.usePeriphery
              ? 1.0f - std::pow(2.0f * glm::length(centre - fovea) / diagonal, p.peripheryExponent)
              : 1.0f;
      const float cosine =
          previousCosine.empty() ? 1.0f : std::clamp(previousCosine[i], 0.0f, 1.0f);
      const float ifr = p.useFresnel ? 1.0f - std::pow(1.0f - cosine, 5.0f) * 0.5f : 1.0f;
      const float noise = p.useNoise ? p.noise * (importanceNoise(p.seed, i) - 0.5f) : 0.0f;
      m.depth[i] = id;
      m.periphery[i] = iper;
      m.fresnel[i] = ifr;
      m.noise[i] = noise;
      m.importance[i] = std::max(0.0f, iper * id * ifr + noise);
    }
  return m;
}

}  // namespace mfr
