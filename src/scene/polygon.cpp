// Polygon triangulation for the OBJ loader (see polygon.hpp).
#include "polygon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

namespace mfr {
namespace {

using Point = glm::dvec2;

double cross(const Point& o, const Point& a, const Point& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/// Counts how often the sign of a sequence of values changes around the cycle (values within
/// `tolerance` of zero skipped).
int signChanges(const std::vector<double>& values, double tolerance) {
  int changes = 0, first = 0, last = 0;
  for (const double v : values) {
    const int sign = v > tolerance ? 1 : (v < -tolerance ? -1 : 0);
    if (sign == 0) continue;
    if (first == 0) first = sign;
    if (last != 0 && sign != last) ++changes;
    last = sign;
  }
  if (first != 0 && last != first) ++changes;
  return changes;
}

/// Is the (counter-clockwise) polygon convex: no right turn, and the edges' x and y directions
/// each change sign at most twice around it (a star polygon turns left everywhere too). The
/// corners came as floats: a turn or a direction within their rounding (`rounding`, the size of
/// an ulp of the largest coordinate, a few times over) counts as straight, so that a finely
/// sampled disc is convex; a fan over such a polygon overlaps itself by no more than the rounding.
bool isConvex(const std::vector<Point>& p, double rounding) {
  const size_t n = p.size();
  std::vector<double> dx(n), dy(n);
  for (size_t i = 0; i < n; ++i) {
    const Point& a = p[i];
    const Point& b = p[(i + 1) % n];
    const Point& c = p[(i + 2) % n];
    const double tolerance = 2.0 * rounding * (glm::length(b - a) + glm::length(c - b));
    if (cross(a, b, c) < -tolerance) return false;
    dx[i] = b.x - a.x;
    dy[i] = b.y - a.y;
  }
  return signChanges(dx, rounding) <= 2 && signChanges(dy, rounding) <= 2;
}

/// `q` inside or on the triangle (a, b, c), counter-clockwise.
bool inTriangle(const Point& a, const Point& b, const Point& c, const Point& q) {
  return cross(a, b, q) >= 0.0 && cross(b, c, q) >= 0.0 && cross(c, a, q) >= 0.0;
}

/// Ear clipping on a doubly linked ring: an ear is a convex corner whose triangle holds no other
/// remaining reflex corner. The search resumes after the last ear, so a simple polygon costs
/// O(n^2); a full round without an ear means the polygon crosses itself.
Result<void> clipEars(const std::vector<Point>& p, std::vector<uint32_t>& out) {
  const size_t n = p.size();
  std::vector<size_t> prev(n), next(n);
  for (size_t i = 0; i < n; ++i) {
    prev[i] = (i + n - 1) % n;
    next[i] = (i + 1) % n;
  }
  size_t left = n, current = 0, failures = 0;
  while (left > 3) {
    const size_t a = prev[current], b = current, c = next[current];
    bool ear = cross(p[a], p[b], p[c]) > 0.0;
    for (size_t v = next[c]; ear && v != a; v = next[v]) {
      if (cross(p[prev[v]], p[v], p[next[v]]) > 0.0) continue;  // only reflex corners can poke in
      if (p[v] == p[a] || p[v] == p[b] || p[v] == p[c]) continue;
      ear = !inTriangle(p[a], p[b], p[c], p[v]);
    }
    if (!ear) {
      current = next[current];
      if (++failures > left)
        return makeError("a face of " + std::to_string(n) +
                         " vertices crosses itself and cannot be triangulated");
      continue;
    }
    out.insert(out.end(),
               {static_cast<uint32_t>(a), static_cast<uint32_t>(b), static_cast<uint32_t>(c)});
    next[a] = c;
    prev[c] = a;
    --left;
    current = c;
    failures = 0;
  }
  out.insert(out.end(), {static_cast<uint32_t>(prev[current]), static_cast<uint32_t>(current),
                         static_cast<uint32_t>(next[current])});
  return {};
}

/// Whether segments (a, b) and (c, d) cross at a point inside both (each pair of ends strictly on
/// either side of the other segment's line, beyond `tolerance`).
bool segmentsCross(const Point& a, const Point& b, const Point& c, const Point& d,
                   double tolerance) {
  const auto side = [tolerance](double v) { return v > tolerance ? 1 : (v < -tolerance ? -1 : 0); };
  const int abC = side(cross(a, b, c)), abD = side(cross(a, b, d));
  const int cdA = side(cross(c, d, a)), cdB = side(cross(c, d, b));
  return abC * abD < 0 && cdA * cdB < 0;
}

/// A quad: refused when it crosses itself (a bow-tie: two opposite edges cross, and any split
/// gives two triangles overlapping at the crossing), split from its reflex corner when it is
/// concave (the other diagonal lies outside it: the triangles would cover the notch and overlap),
/// and otherwise as tinyobjloader splits it, along the shorter diagonal, so that scenes of convex
/// quads load as they did. The test runs in the plane of the largest corner normal (a bow-tie's
/// Newell normal can vanish: its two lobes' areas cancel).
Result<void> splitQuad(const std::vector<glm::vec3>& corners, std::vector<uint32_t>& triangles) {
  glm::dvec3 normal(0.0);
  for (size_t i = 0; i < 4; ++i) {
    const glm::dvec3 o(corners[i]), a(corners[(i + 1) % 4]), b(corners[(i + 3) % 4]);
    const glm::dvec3 n = glm::cross(a - o, b - o);
    if (glm::dot(n, n) > glm::dot(normal, normal)) normal = n;
  }
  const glm::dvec3 magnitude = glm::abs(normal);
  const int drop = magnitude.x >= magnitude.y && magnitude.x >= magnitude.z ? 0
                   : magnitude.y >= magnitude.z                             ? 1
                                                                            : 2;
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  Point p[4];
  double largest = 0.0;
  for (size_t i = 0; i < 4; ++i) {
    const glm::dvec3 c(corners[i]);
    p[i] = Point(c[u], c[v]);
    largest = std::max({largest, std::abs(c[u]), std::abs(c[v])});
  }
  // a turn or a side within the corners' float rounding counts as straight (as isConvex)
  const double rounding = 4.0 * std::numeric_limits<float>::epsilon() * largest;
  const auto tolerance = [&](const Point& a, const Point& b, const Point& c) {
    return 2.0 * rounding * (glm::length(b - a) + glm::length(c - a));
  };
  if (std::isfinite(largest) &&
      (segmentsCross(p[0], p[1], p[2], p[3], tolerance(p[0], p[1], p[2])) ||
       segmentsCross(p[1], p[2], p[3], p[0], tolerance(p[1], p[2], p[3]))))
    return makeError("a face of 4 vertices crosses itself and cannot be triangulated");
  // the signed area's sign is the winding; a corner turning the other way is reflex
  double area = 0.0;
  for (size_t i = 0; i < 4; ++i) area += p[i].x * p[(i + 1) % 4].y - p[(i + 1) % 4].x * p[i].y;
  for (uint32_t r = 0; r < 4 && std::isfinite(area); ++r) {
    const Point& a = p[(r + 3) % 4];
    const Point& b = p[r];
    const Point& c = p[(r + 1) % 4];
    const double turn = cross(a, b, c) * (area < 0.0 ? -1.0 : 1.0);
    if (turn < -tolerance(b, a, c)) {
      const uint32_t r1 = (r + 1) % 4, r2 = (r + 2) % 4, r3 = (r + 3) % 4;
      triangles.insert(triangles.end(), {r, r1, r2, r, r2, r3});
      return {};
    }
  }
  const glm::vec3 e02 = corners[2] - corners[0], e13 = corners[3] - corners[1];
  if (glm::dot(e02, e02) < glm::dot(e13, e13))
    triangles.insert(triangles.end(), {0u, 1u, 2u, 0u, 2u, 3u});
  else
    triangles.insert(triangles.end(), {0u, 1u, 3u, 1u, 2u, 3u});
  return {};
}

}  // namespace

Result<void> triangulatePolygon(const std::vector<glm::vec3>& corners,
                                std::vector<uint32_t>& triangles) {
  const size_t n = corners.size();
  if (n < 3) return {};
  if (n == 3) {
    triangles.insert(triangles.end(), {0u, 1u, 2u});
    return {};
  }
  if (n == 4) return splitQuad(corners, triangles);
  // Newell's normal, then the plane of its largest component, oriented so that the polygon
  // winds counter-clockwise in it.
  glm::dvec3 normal(0.0);
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 a(corners[i]), b(corners[(i + 1) % n]);
    normal +=
        glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
  }
  const glm::dvec3 magnitude = glm::abs(normal);
  const int drop = magnitude.x >= magnitude.y && magnitude.x >= magnitude.z ? 0
                   : magnitude.y >= magnitude.z                             ? 1
                                                                            : 2;
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  const bool flip = normal[drop] < 0.0;
  std::vector<Point> p(n);
  double largest = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 c(corners[i]);
    p[i] = flip ? Point(c[v], c[u]) : Point(c[u], c[v]);
    largest = std::max({largest, std::abs(c[u]), std::abs(c[v])});
  }
  const double rounding = 4.0 * std::numeric_limits<float>::epsilon() * largest;
  if (!(glm::length(normal) > 0.0) || !std::isfinite(glm::length(normal)) ||
      isConvex(p, rounding)) {
    // a fan (a degenerate polygon of no area gives triangles of no area: nothing is drawn)
    for (size_t i = 1; i + 1 < n; ++i)
      triangles.insert(triangles.end(),
                       {0u, static_cast<uint32_t>(i), static_cast<uint32_t>(i + 1)});
    return {};
  }
  if (n > kMaxNonConvexCorners)
    return makeError("a non-convex face of " + std::to_string(n) +
                     " vertices (non-convex faces are triangulated up to " +
                     std::to_string(kMaxNonConvexCorners) + " vertices; convex ones of any size)");
  const size_t first = triangles.size();
  MFR_TRY(clipEars(p, triangles));
  // A simple polygon's ears add up to its area; ears of one that crosses itself (a pentagram
  // turns the same way at every corner, so every corner looks like an ear) add up to more.
  double area = 0.0, ears = 0.0;
  for (size_t i = 0; i < n; ++i) area += p[i].x * p[(i + 1) % n].y - p[(i + 1) % n].x * p[i].y;
  for (size_t t = first; t < triangles.size(); t += 3)
    ears += std::abs(cross(p[triangles[t]], p[triangles[t + 1]], p[triangles[t + 2]]));
  if (ears > std::abs(area) * (1.0 + 1e-6) + rounding * rounding) {
    triangles.resize(first);
    return makeError("a face of " + std::to_string(n) +
                     " vertices crosses itself and cannot be triangulated");
  }
  return {};
}

}  // namespace mfr
