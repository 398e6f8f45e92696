#pragma once
// Separating-axis test for convex polygons. In the plane the face normals of the two polygons
// are the only candidate separating axes (Gottschalk et al. 1996; Ericson, "Real-Time
// Collision Detection", 2005, sec. 5.2.1), so the largest face separation is the exact
// signed distance when the polygons overlap, and a lower bound on the gap when they do not.
#include <cstdint>
#include <cstring>
#include <limits>

#include "geometry/lanes4.hpp"
#include "floedem/geometry/vec2.hpp"

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

// max_face_separation_lanes' helpers.
namespace sat_lanes {
using lanes4::v4d;
struct Lanes {
  v4d x, y;
};
/// x and y of points i .. i + 3 of `at` (point 0 past `count`), as two (x, y) pairs joined twice.
FLOEDEM_LANES Lanes four(const Vec2* at, int count, int i) {
  using v2d = double __attribute__((vector_size(16)));
  v2d p[4];
  for (int l = 0; l < 4; ++l) std::memcpy(&p[l], &at[i + l < count ? i + l : 0], sizeof p[l]);
  const v4d even = __builtin_shufflevector(p[0], p[2], 0, 1, 2, 3);  // x0 y0 x2 y2
  const v4d odd = __builtin_shufflevector(p[1], p[3], 0, 1, 2, 3);   // x1 y1 x3 y3
  return {__builtin_shufflevector(even, odd, 0, 4, 2, 6), __builtin_shufflevector(even, odd, 1, 5, 3, 7)};
}
/// The separations of edges g .. g + 3 taken in order: the first edge to reach the largest wins.
FLOEDEM_LANES void take(const v4d& s, int g, int count, FaceSeparation& best) {
  alignas(32) double lane[4];
  std::memcpy(lane, &s, sizeof lane);
  for (int l = 0; l < 4 && g + l < count; ++l)
    if (lane[l] > best.separation) {
      best.separation = lane[l];
      best.edge = g + l;
    }
}
}  // namespace sat_lanes

/// max_face_separation with no shortcut: every edge of `a` against every vertex of `b`, four
/// edges to a vector (geometry/lanes4.hpp: one AVX register in the AVX2 and AVX-512 builds of
/// the narrow phase, two SSE2 registers on the baseline) and up to two vectors, eight edges, to
/// one pass over `b`'s vertices, without a branch on the data. Each lane computes its edge's
/// separation as the plain double loop does (the same products and sums in the same order,
/// vertex by vertex, no contraction into fused multiply-adds: -ffp-contract=off;
/// `d < s ? d : s` is that loop's `if (d < s) s = d`, minpd), and the edges are then taken in
/// order, the first to reach the largest winning: the full search's edge and separation to the
/// bit, -0 and +0 included. Lanes past the last edge repeat edge 0 and are not read. The narrow
/// phase's search: at a packed field's pairs the shortcuts' branches, taken or not by the data,
/// cost more than the products they save (BM_NarrowPhase). Elsewhere, the plain loop.
[[gnu::always_inline]] inline FaceSeparation max_face_separation_lanes(const ConvexView& a, const ConvexView& b) {
  using lanes4::splat;
  using sat_lanes::v4d;
  FaceSeparation best;
  const Vec2 *v = a.vertices, *n = a.normals;
  const v4d inf = splat(std::numeric_limits<double>::infinity());
  for (int g = 0; g < a.count; g += 8) {
    const auto [vx0, vy0] = sat_lanes::four(v, a.count, g);
    const auto [nx0, ny0] = sat_lanes::four(n, a.count, g);
    v4d s0 = inf;
    if (g + 4 < a.count) {
      const auto [vx1, vy1] = sat_lanes::four(v, a.count, g + 4);
      const auto [nx1, ny1] = sat_lanes::four(n, a.count, g + 4);
      v4d s1 = inf;
      for (int j = 0; j < b.count; ++j) {
        const v4d px = splat(b.vertices[j].x), py = splat(b.vertices[j].y);
        // dot(n, p - v) = n.x (p.x - v.x) + n.y (p.y - v.y), per lane.
        const v4d d0 = nx0 * (px - vx0) + ny0 * (py - vy0);
        const v4d d1 = nx1 * (px - vx1) + ny1 * (py - vy1);
        s0 = d0 < s0 ? d0 : s0;
        s1 = d1 < s1 ? d1 : s1;
      }
      sat_lanes::take(s0, g, a.count, best);
      sat_lanes::take(s1, g + 4, a.count, best);
    } else {
      for (int j = 0; j < b.count; ++j) {
        const v4d px = splat(b.vertices[j].x), py = splat(b.vertices[j].y);
        const v4d d0 = nx0 * (px - vx0) + ny0 * (py - vy0);
        s0 = d0 < s0 ? d0 : s0;
      }
      sat_lanes::take(s0, g, a.count, best);
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
