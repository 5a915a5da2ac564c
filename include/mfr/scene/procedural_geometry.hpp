// Analytic ground truth for the built-in procedural scenes (see mfr/scene/procedural.hpp), for
// tests that compare rendered per-pixel fragment counts with the exact geometry.
#pragma once

#include "mfr/scene/camera.hpp"

namespace mfr {

/// Defaults of "procedural:spheres": `count` concentric spheres centred at the origin with radii
/// scale * i / count (i = 1..count), each a UV sphere of `detail` latitude bands and 2 * detail
/// longitude steps (poles on the y axis, vertices exactly on the sphere).
inline constexpr int kSpheresDefaultCount = 8;
inline constexpr float kSpheresDefaultScale = 1.0f;
inline constexpr int kSpheresDefaultDetail = 64;

/// Exact number of surface crossings of the analytic spheres of "procedural:spheres" (count,
/// scale) along the centre ray of pixel (x, y) (row 0 at the top) of a width x height image, i.e.
/// the fragment count a rasterizer must produce there: for a camera outside all spheres, 2 for
/// every sphere whose radius exceeds the ray's distance to the origin; in general every
/// intersection in front of the eye. When the camera has explicit clip planes (zNear / zFar > 0),
/// crossings whose view depth lies outside [zNear, zFar] are not counted.
///
/// If marginOut is not null it receives the distance in world units to the nearest change of the
/// count: the smallest |d - r_i| over the spheres (d = distance from the origin to the ray line)
/// and, with clip planes, the smallest distance of a crossing's view depth to a plane. The
/// tessellated spheres differ from the analytic ones by at most sphereTessellationError, so pixels
/// with a margin above that are guaranteed to have the analytic count on the mesh too.
int sphereLayersAnalytic(const Camera& camera, int width, int height, int x, int y, int count,
                         float scale, float* marginOut = nullptr);

/// Upper bound of the distance between the analytic sphere of the given radius and its UV-sphere
/// tessellation with `detail` latitude bands (and 2 * detail longitude steps).
float sphereTessellationError(float radius, int detail);

}  // namespace mfr
