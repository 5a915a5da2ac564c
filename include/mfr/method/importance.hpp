// Importance maps of the variable k-buffer (Vasilakis, Vardis, Papaioannou, Moustakas, "Variable
// k-buffer using Importance Maps", sec. 3.2, Eqs. 3-6):
//   (3) depth complexity  I_d   = alpha + (1 - alpha) * min(1, n(p) / N_limit)
//   (4) periphery         I_per = 1 - (2 |p - o| / (1.1 sqrt(w^2 + h^2)))^d
//   (5) Fresnel           I_f   = 1 - (1 - n_prev . e)^5 / 2   (nearest fragment, previous frame)
//   (6) with noise        I     = max(0, I_per * I_d * I_f + lambda * (xi - 0.5))
// Pixels without fragments get I = 0 (they need no storage). Each factor can be switched off
// (it then contributes 1, or 0 for the noise).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

namespace mfr {

struct ImportanceParams {
  float alpha = 0.375f;            // Eq. 3 range bias (paper: 0.25-0.5)
  float nLimit = 20.0f;            // Eq. 3 anticipated maximum layer count (paper: 20-30)
  float peripheryExponent = 3;     // Eq. 4 d
  std::optional<glm::vec2> fovea;  // Eq. 4 o in pixels (default: image centre)
  float noise = 0.1f;              // Eq. 6 lambda
  uint64_t seed = 1;               // Eq. 6 xi
  bool useDepth = true, usePeriphery = true, useFresnel = true, useNoise = true;
};

/// The map and its factors, one value per pixel (row 0 at the top).
struct ImportanceMaps {
  std::vector<float> importance, depth, periphery, fresnel, noise;
};

/// n(p) per pixel and |n . e| of each pixel's nearest fragment in the previous frame (0..1).
ImportanceMaps computeImportance(int width, int height, const std::vector<uint32_t>& fragmentCounts,
                                 const std::vector<float>& previousNearestCosine,
                                 const ImportanceParams& params);

/// xi of Eq. 6 for a pixel: uniform in [0, 1), a hash of (seed, pixel), independent of threads.
float importanceNoise(uint64_t seed, uint64_t pixel);

}  // namespace mfr
