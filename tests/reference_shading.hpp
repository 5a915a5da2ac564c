// An independent reference for expected pixel values: sRGB by its formula (not the library's
// tables), the headlight term of a +z-facing surface seen by a camera looking down -z, the 8-bit
// quantisation of fragment colours, and front-to-back compositing in double.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

namespace mfr::test {

inline double refSrgbDecode(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
inline double refSrgbEncode(double l) {
  l = std::clamp(l, 0.0, 1.0);
  return l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
}
/// The 8-bit sRGB code of a linear value, as written to a PNG.
inline int refSrgbCode(double linear) {
  return static_cast<int>(std::lround(refSrgbEncode(linear) * 255.0));
}

/// |n.v| at the centre of pixel (x, y) (y down) of a width x height image, for a surface with
/// normal +z and a camera looking down -z with vertical field of view fovYDegrees.
inline double refHeadlightCosine(int x, int y, int width, int height, double fovYDegrees) {
  const double tanHalf = std::tan(fovYDegrees * M_PI / 360.0);
  const double aspect = static_cast<double>(width) / height;
  const double dx = ((x + 0.5) / width * 2.0 - 1.0) * tanHalf * aspect;
  const double dy = (1.0 - (y + 0.5) / height * 2.0) * tanHalf;
  return 1.0 / std::sqrt(dx * dx + dy * dy + 1.0);
}

struct RefLayer {
  glm::dvec3 color;  // linear base colour
  double alpha;      // alpha after the alpha mode (1 for opaque or passed mask)
};

/// Front-to-back "over" of `layers` (nearest first) over `background`, each fragment shaded
/// base x (0.2 + 0.8 |n.v|) and carried as sRGB8 colour + 8-bit linear alpha.
inline glm::dvec3 refComposite(const std::vector<RefLayer>& layers, double cosine,
                               glm::dvec3 background) {
  const double light = 0.2 + 0.8 * cosine;
  glm::dvec3 color(0.0);
  double T = 1.0;
  for (const RefLayer& l : layers) {
    glm::dvec3 shaded;
    for (int ch = 0; ch < 3; ++ch)
      shaded[ch] = refSrgbDecode(std::round(refSrgbEncode(l.color[ch] * light) * 255.0) / 255.0);
    const double a = std::round(std::clamp(l.alpha, 0.0, 1.0) * 255.0) / 255.0;
    color += T * a * shaded;
    T *= 1.0 - a;
  }
  return color + T * background;
}

}  // namespace mfr::test
