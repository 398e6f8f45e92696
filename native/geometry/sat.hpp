#pragma once
// Separating-axis test for convex polygons. In the plane the face normals of the two polygons
// are the only candidate separating axes (Gottschalk et al. 1996; Ericson, "Real-Time
// Collision Detection", 2005, sec. 5.2.1), so the largest face separation is the exact
// signed distance when the polygons overlap, and a lower bound on the gap when they do not.
#include <cstdint>
#include <limits>

#include "geometry/vec2.hpp"

namespace floedem {

/// A convex counter-clockwise polygon as the narrow phase sees it: world vertices and the
/// outward unit normal of each edge (edge i runs from vertex i to i + 1).
struct ConvexView {
  const Vec2* vertices = nullptr;
  const Vec2* normals = nullptr;
  int count = 0;
};

struct FaceSeparation {
  int edge = -1;
  double separation = -std::numeric_limits<double>::infinity();
};

/// Edge i's separation alone: the smallest signed distance of `b`'s vertices to edge i of `a`
/// (the same value as max_face_separation gives it: a minimum is exact in any order).
inline double edge_separation(const ConvexView& a, const ConvexView& b, int i) {
  const Vec2 n = a.normals[i];
  const Vec2 v = a.vertices[i];
  double s = std::numeric_limits<double>::infinity();
  for (int j = 0; j < b.count; ++j) {
    const double d = dot(n, b.vertices[j] - v);
    if (d < s) s = d;
  }
  return s;
}

/// Largest over the edges of `a` of the smallest signed distance of `b`'s vertices to that edge:
/// the first edge in order that reaches it, and its separation. Three exact shortcuts (the same
/// edge and separation as the full double loop, to the bit):
///  - an edge is left at its first vertex no further than the best edge so far (its minimum
///    cannot beat it);
///  - the search ends at the first edge separating by more than `enough` (the caller needs to
///    know no more: a pair beyond its contact margin);
///  - given an edge `hint` and its separation `floor` (edge_separation; a pair's best edge at its
///    last step), the winner separates by at least `floor`, so an edge is left as soon as it
///    falls below it, and the hint is not searched again; before the hint, an edge that ties it
///    still wins (the first in order), so only one below it is left there. hint < 0: none.
inline FaceSeparation max_face_separation(const ConvexView& a, const ConvexView& b,
                                          double enough = std::numeric_limits<double>::infinity(), int hint = -1,
                                          double floor = 0.0) {
  FaceSeparation best;
  for (int i = 0; i < a.count; ++i) {
    double s = floor;
    if (i != hint) {
      const double need = i < hint ? floor : -std::numeric_limits<double>::infinity();
      const Vec2 n = a.normals[i];
      const Vec2 v = a.vertices[i];
      s = std::numeric_limits<double>::infinity();
      for (int j = 0; j < b.count && s > best.separation && s >= need; ++j) {
        const double d = dot(n, b.vertices[j] - v);
        if (d < s) s = d;
      }
      if (s < need) continue;
    }
    if (s > best.separation) {
      best.separation = s;
      best.edge = i;
      if (s > enough) break;
    }
  }
  return best;
}

/// The edge of each polygon that separated most at a pair's last test (-1: none yet), where the
/// next test of the pair starts (collide()).
struct SeparationHint {
  std::int16_t a = -1, b = -1;
};

}  // namespace floedem
