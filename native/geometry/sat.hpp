#pragma once
// Separating-axis test for convex polygons. In the plane the face normals of the two polygons
// are the only candidate separating axes (Gottschalk et al. 1996; Ericson, "Real-Time
// Collision Detection", 2005, sec. 5.2.1), so the largest face separation is the exact
// signed distance when the polygons overlap, and a lower bound on the gap when they do not.
#include <cstdint>
#include <limits>
#include <utility>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

/// max_face_separation with no shortcut: every edge of `a` against every vertex of `b`, four
/// edges at a time in SSE2 lanes (two per register; x86-64 always has them), without a branch
/// on the data. Each lane computes its edge's separation as the plain double loop does (the
/// same products and sums in the same order, vertex by vertex, no contraction into fused
/// multiply-adds: -ffp-contract=off; minpd(d, s) is `d < s ? d : s`, that loop's
/// `if (d < s) s = d`), and the edges are then taken in order, the first to reach the largest
/// winning: the full search's edge and separation to the bit, -0 and +0 included. Lanes past
/// the last edge repeat edge 0 and are not read. The narrow phase's search: at a packed
/// field's pairs the shortcuts' branches, taken or not by the data, cost more than the products
/// they save (BM_NarrowPhase). Elsewhere, the plain loop.
[[gnu::always_inline]] inline FaceSeparation max_face_separation_lanes(const ConvexView& a, const ConvexView& b) {
#if defined(__SSE2__)
  FaceSeparation best;
  const Vec2 *v = a.vertices, *n = a.normals;
  auto pair = [&](const Vec2* at, int i) {  // x and y of edges i and i + 1 (0 past the end)
    const __m128d p = _mm_loadu_pd(&at[i].x);
    const __m128d q = _mm_loadu_pd(&at[i + 1 < a.count ? i + 1 : 0].x);
    return std::pair{_mm_unpacklo_pd(p, q), _mm_unpackhi_pd(p, q)};
  };
  for (int g = 0; g < a.count; g += 4) {
    const int h = g + 2 < a.count ? g + 2 : 0;
    const auto [vx0, vy0] = pair(v, g);
    const auto [nx0, ny0] = pair(n, g);
    const auto [vx1, vy1] = pair(v, h);
    const auto [nx1, ny1] = pair(n, h);
    __m128d s0 = _mm_set1_pd(std::numeric_limits<double>::infinity()), s1 = s0;
    for (int j = 0; j < b.count; ++j) {
      const __m128d px = _mm_set1_pd(b.vertices[j].x), py = _mm_set1_pd(b.vertices[j].y);
      // dot(n, p - v) = n.x (p.x - v.x) + n.y (p.y - v.y), per lane.
      const __m128d d0 = _mm_add_pd(_mm_mul_pd(nx0, _mm_sub_pd(px, vx0)), _mm_mul_pd(ny0, _mm_sub_pd(py, vy0)));
      const __m128d d1 = _mm_add_pd(_mm_mul_pd(nx1, _mm_sub_pd(px, vx1)), _mm_mul_pd(ny1, _mm_sub_pd(py, vy1)));
      s0 = _mm_min_pd(d0, s0);
      s1 = _mm_min_pd(d1, s1);
    }
    alignas(16) double s[4];
    _mm_store_pd(s, s0);
    _mm_store_pd(s + 2, s1);
    for (int l = 0; l < 4 && g + l < a.count; ++l)
      if (s[l] > best.separation) {
        best.separation = s[l];
        best.edge = g + l;
      }
  }
  return best;
#else
  return max_face_separation(a, b);
#endif
}

/// The edge of each polygon that separated most at a pair's last test (-1: none yet), where the
/// next test of the pair starts (collide()).
struct SeparationHint {
  std::int16_t a = -1, b = -1;
};

}  // namespace floedem
