// Triangulating the polygons of OBJ faces, in time linear in the corners for convex ones.
//
// Triangles and convex quads are split as tinyobjloader splits them (a quad along its shorter
// diagonal), so that scenes made of them load as before; a concave quad is split from its reflex
// corner, and one that crosses itself (a bow-tie) is refused. Larger polygons are projected onto
// the plane of their Newell normal (Newell 1972; Sutherland, Sproull, Schumacker 1974); a convex
// one (every turn the same way, and each axis direction changing sign at most twice, so a star
// polygon whose turns all agree is not mistaken for one) becomes a fan, a non-convex one is
// ear-clipped (Meisters 1975) up to kMaxNonConvexCorners corners, quadratic in the corners.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "mfr/core/result.hpp"

namespace mfr {

/// Non-convex polygons with more corners are refused (ear clipping is quadratic).
inline constexpr size_t kMaxNonConvexCorners = 1024;

/// Appends to `triangles` index triples into `corners` (counter-clockwise about the polygon's
/// normal, as the corners wind) covering the polygon once. A polygon that folds onto itself so
/// that no ear can be cut (self-intersecting), and a non-convex one of more than
/// kMaxNonConvexCorners corners, are errors saying so.
Result<void> triangulatePolygon(const std::vector<glm::vec3>& corners,
                                std::vector<uint32_t>& triangles);

}  // namespace mfr
