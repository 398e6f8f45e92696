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

/// Largest over the edges of `a` of the smallest signed distance of `b`'s vertices to that edge.
/// Two exact shortcuts (the same edge and separation as the full double loop, to the bit): an
/// edge is left at its first vertex no further than the best edge so far (its minimum cannot
/// beat it), and the search ends at the first edge separating by more than `enough` (the caller
/// needs to know no more: a pair beyond its contact margin).
inline FaceSeparation max_face_separation(const ConvexView& a, const ConvexView& b,
                                          double enough = std::numeric_limits<double>::infinity()) {
  FaceSeparation best;
  for (int i = 0; i < a.count; ++i) {
    const Vec2 n = a.normals[i];
    const Vec2 v = a.vertices[i];
    double s = std::numeric_limits<double>::infinity();
    for (int j = 0; j < b.count && s > best.separation; ++j) {
      const double d = dot(n, b.vertices[j] - v);
      if (d < s) s = d;
    }
    if (s > best.separation) {
      best.separation = s;
      best.edge = i;
      if (s > enough) break;
    }
  }
  return best;
}

/// Edge i's separation alone: the smallest signed distance of `b`'s vertices to edge i of `a`
/// (the same value as the loops above give it: a minimum is exact in any order).
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

/// max_face_separation, given edge `hint`'s separation `floor` (edge_separation): the same edge
/// and separation to the bit, sooner when the hint is the winner or near it (a pair's best edge
/// at its last step). The winner separates by at least `floor`, so an edge is left as soon as
/// it falls below it; before the hint, an edge that ties it still wins (the first in order, as
/// in the plain search), so only an edge below it is left there.
inline FaceSeparation max_face_separation(const ConvexView& a, const ConvexView& b, double enough, int hint,
                                          double floor) {
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
