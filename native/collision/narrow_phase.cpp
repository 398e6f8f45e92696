#include "collision/narrow_phase.hpp"

#include <algorithm>
#include <limits>
#include <type_traits>

#include "geometry/lane_isa.hpp"

namespace floedem {

namespace {

struct ClipVertex {
  Vec2 p;
  std::uint32_t feature;  ///< incident vertex index, or 0x800 | reference vertex index when clipped
};

/// Keeps the part of segment (in[0], in[1]) where dot(normal, p) <= offset.
[[gnu::always_inline]] inline int clip_segment(const ClipVertex in[2], ClipVertex out[2], Vec2 normal, double offset, std::uint32_t clip_feature) {
  int count = 0;
  const double d0 = dot(normal, in[0].p) - offset;
  const double d1 = dot(normal, in[1].p) - offset;
  if (d0 <= 0.0) out[count++] = in[0];
  if (d1 <= 0.0) out[count++] = in[1];
  if (d0 * d1 < 0.0) {
    const double t = d0 / (d0 - d1);
    out[count++] = {in[0].p + t * (in[1].p - in[0].p), clip_feature};
  }
  return count;
}

/// Closest point of segment [p, q] to x.
Vec2 closest_on_segment(Vec2 p, Vec2 q, Vec2 x) {
  const Vec2 e = q - p;
  const double ee = dot(e, e);
  const double t = ee > 0.0 ? std::clamp(dot(x - p, e) / ee, 0.0, 1.0) : 0.0;
  return p + t * e;
}

/// Closest points of two disjoint convex polygons: a vertex of one and a point of an edge of
/// the other (in the plane, one of the pair is always a vertex). Brute force over vertex-edge
/// pairs, O(n m): used only for the rare corner approach below.
struct ClosestPoints {
  Vec2 on_ref, on_inc;
  std::uint32_t ref_feature = 0, inc_feature = 0;
  double distance = std::numeric_limits<double>::infinity();
};

ClosestPoints closest_points(const ConvexView& ref, const ConvexView& inc) {
  ClosestPoints best;
  auto consider = [&](Vec2 on_ref, Vec2 on_inc, std::uint32_t rf, std::uint32_t cf) {
    const double d = length(on_inc - on_ref);
    if (d < best.distance) best = {on_ref, on_inc, rf, cf, d};
  };
  for (int i = 0; i < ref.count; ++i) {
    const Vec2 r1 = ref.vertices[i], r2 = ref.vertices[(i + 1) % ref.count];
    for (int j = 0; j < inc.count; ++j) {
      const Vec2 c1 = inc.vertices[j], c2 = inc.vertices[(j + 1) % inc.count];
      // Feature codes: 0x100 | edge for a point of an edge, the vertex index for a vertex.
      consider(closest_on_segment(r1, r2, c1), c1, 0x100u | static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j));
      consider(r1, closest_on_segment(c1, c2, r1), static_cast<std::uint32_t>(i), 0x100u | static_cast<std::uint32_t>(j));
    }
  }
  return best;
}

template <class M>
void corner_contact(const PartGeometry& ref, const PartGeometry& inc, bool flip, double margin, M& m) {
  const ClosestPoints c = closest_points(ref.world, inc.world);
  // Touching (the direction undefined) or beyond reach: no contact.
  if (!(c.distance > 1e-9) || c.distance > margin) return;
  const Vec2 n = (1.0 / c.distance) * (c.on_inc - c.on_ref);  // from the reference part to the incident one
  m.normal = flip ? -n : n;
  m.reference_is_b = flip;
  // The position solve measures the gap from this plane of the reference body to the
  // incident point, both carried with their bodies.
  m.local_normal = ref.body_transform.q.apply_inverse(n);
  m.local_face_point = ref.body_transform.apply_inverse(c.on_ref);
  auto& p = m.points[m.point_count++];
  p = std::remove_reference_t<decltype(p)>{};
  p.point = 0.5 * (c.on_ref + c.on_inc);
  p.separation = c.distance;
  p.id = (flip ? 0x80000000u : 0u) | 0x40000000u | (c.ref_feature << 16) | c.inc_feature;
  p.local_incident = inc.body_transform.apply_inverse(c.on_inc);
}

// collide() into either manifold type: the same arithmetic, the same fields.
template <class M>
[[gnu::always_inline]] inline void collide_into(const PartGeometry& a, const PartGeometry& b, double margin,
                                                double flip_tolerance, M& m, SeparationHint* hint) {
  m.point_count = 0;
  // The last test's best edges first (a pair's two floes turn little in a step): where either
  // still separates the pair by more than the margin, the pair is apart (the largest separation
  // can only be larger) and nothing more is computed. Otherwise both polygons' largest
  // separations are searched in full (max_face_separation_lanes: the plain search's edge and
  // separation to the bit), and the hint becomes this test's best edges. The manifold does not
  // depend on the hint; no hint: the full searches alone.
  SeparationHint none;
  SeparationHint& h = hint ? *hint : none;
  if (h.b >= 0 && h.b < b.world.count && edge_separation(b.world, a.world, h.b) > margin) return;
  if (h.a >= 0 && h.a < a.world.count && edge_separation(a.world, b.world, h.a) > margin) return;
  const FaceSeparation sa = max_face_separation_lanes(a.world, b.world);
  h.a = static_cast<std::int16_t>(sa.edge);
  if (sa.separation > margin) return;
  // The reference face's frame data (read below) is in arrays the search does not touch, and at
  // 16k floes mostly out of cache: asked for now, while b's search runs (a's face is the usual
  // reference). A prefetch only warms the cache: nothing computed changes.
  __builtin_prefetch(&a.local_normals[sa.edge]);
  __builtin_prefetch(&a.local_vertices[sa.edge]);
  const FaceSeparation sb = max_face_separation_lanes(b.world, a.world);
  h.b = static_cast<std::int16_t>(sb.edge);
  if (sb.separation > margin) return;

  // Prefer a's face unless b's is clearly better: keeps the choice steady between steps.
  const bool flip = sb.separation > sa.separation + flip_tolerance;
  const PartGeometry& ref = flip ? b : a;
  const PartGeometry& inc = flip ? a : b;
  const int edge = flip ? sb.edge : sa.edge;

  const ConvexView& r = ref.world;
  const ConvexView& c = inc.world;
  const Vec2 n = r.normals[edge];

  // Incident edge: the edge of `inc` whose normal is most anti-parallel to n.
  int incident = 0;
  double most = dot(n, c.normals[0]);
  for (int j = 1; j < c.count; ++j) {
    const double d = dot(n, c.normals[j]);
    if (d < most) {
      most = d;
      incident = j;
    }
  }
  const int i1 = incident;
  const int i2 = (incident + 1) % c.count;
  const ClipVertex incident_edge[2] = {{c.vertices[i1], static_cast<std::uint32_t>(i1)},
                                       {c.vertices[i2], static_cast<std::uint32_t>(i2)}};

  const int r1 = edge;
  const int r2 = (edge + 1) % r.count;
  const Vec2 v1 = r.vertices[r1];
  const Vec2 v2 = r.vertices[r2];
  const Vec2 tangent = normalized(v2 - v1);

  // Side planes of the reference face: -t.p <= -t.v1 and t.p <= t.v2.
  ClipVertex clip1[2], clip2[2];
  if (clip_segment(incident_edge, clip1, -tangent, -dot(tangent, v1), 0x800u | static_cast<std::uint32_t>(r1)) < 2 ||
      clip_segment(clip1, clip2, tangent, dot(tangent, v2), 0x800u | static_cast<std::uint32_t>(r2)) < 2) {
    // The incident edge lies wholly beyond an end of the reference face: the polygons meet
    // corner to corner. Apart, they may still close within the step (a floe sliding onto
    // another's face: drift_in_field had 13.8 mm of overlap from such an approach, unseen one
    // step before); the speculative contact is then the closest pair of points, with its
    // direction as the normal: the planes through them perpendicular to it separate the
    // polygons (both convex), so holding that gap at >= 0 keeps them apart to first order.
    // Overlapping so (the separating axes say so), no contact, as before: the vertex-edge
    // distances do not measure an overlap.
    if (std::max(sa.separation, sb.separation) > 0.0) corner_contact(ref, inc, flip, margin, m);
    return;
  }

  m.normal = flip ? -n : n;
  m.reference_is_b = flip;
  m.local_normal = ref.local_normals[edge];
  m.local_face_point = ref.local_vertices[edge];
  const double face_offset = dot(n, v1);
  for (const ClipVertex& cv : clip2) {
    const double s = dot(n, cv.p) - face_offset;
    if (s > margin) continue;
    auto& p = m.points[m.point_count++];
    p = std::remove_reference_t<decltype(p)>{};
    p.point = cv.p - 0.5 * s * n;
    p.separation = s;
    p.id = (flip ? 0x80000000u : 0u) | (static_cast<std::uint32_t>(edge) << 16) | cv.feature;
    p.local_incident = inc.body_transform.apply_inverse(cv.p);
  }
}

// collide_into built for each LaneIsa (geometry/lane_isa.hpp): the separating-axis search's
// four-edge vectors in two SSE2 registers on the baseline and one AVX register in the others
// (AVX-512's 32 registers in the last), the same IEEE operations lane by lane and the same
// scalar ones, so the same manifold to the bit.
template <class M>
void collide_baseline(const PartGeometry& a, const PartGeometry& b, double margin, double flip_tolerance, M& m,
                      SeparationHint* hint) {
  collide_into(a, b, margin, flip_tolerance, m, hint);
}
#if defined(__x86_64__)
#define FLOEDEM_HAS_AVX_NARROW 1
template <class M>
[[gnu::target("avx2")]] void collide_avx2(const PartGeometry& a, const PartGeometry& b, double margin,
                                          double flip_tolerance, M& m, SeparationHint* hint) {
  collide_into(a, b, margin, flip_tolerance, m, hint);
}
template <class M>
[[gnu::target("avx2,avx512f,avx512vl")]] void collide_avx512(const PartGeometry& a, const PartGeometry& b,
                                                             double margin, double flip_tolerance, M& m,
                                                             SeparationHint* hint) {
  collide_into(a, b, margin, flip_tolerance, m, hint);
}
#endif

template <class M>
void collide_any(const PartGeometry& a, const PartGeometry& b, double margin, double flip_tolerance, M& m,
                 SeparationHint* hint) {
  switch (lane_isa()) {
#ifdef FLOEDEM_HAS_AVX_NARROW
    case LaneIsa::avx512: return collide_avx512(a, b, margin, flip_tolerance, m, hint);
    case LaneIsa::avx2: return collide_avx2(a, b, margin, flip_tolerance, m, hint);
#endif
    default: return collide_baseline(a, b, margin, flip_tolerance, m, hint);
  }
}

}  // namespace

void collide(const PartGeometry& a, const PartGeometry& b, double margin, double flip_tolerance, Manifold& m,
             SeparationHint* hint) {
  collide_any(a, b, margin, flip_tolerance, m, hint);
}

void collide(const PartGeometry& a, const PartGeometry& b, double margin, double flip_tolerance,
             NarrowManifold& m, SeparationHint* hint) {
  collide_any(a, b, margin, flip_tolerance, m, hint);
}

}  // namespace floedem
