#include "solver/narrow_phase.hpp"

namespace floedem {

namespace {

struct ClipVertex {
  Vec2 p;
  std::uint32_t feature;  ///< incident vertex index, or 0x800 | reference vertex index when clipped
};

/// Keeps the part of segment (in[0], in[1]) where dot(normal, p) <= offset.
int clip_segment(const ClipVertex in[2], ClipVertex out[2], Vec2 normal, double offset, std::uint32_t clip_feature) {
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

}  // namespace

void collide(const PartGeometry& a, const PartGeometry& b, double margin, double flip_tolerance, Manifold& m) {
  m.point_count = 0;
  const FaceSeparation sa = max_face_separation(a.world, b.world);
  if (sa.separation > margin) return;
  const FaceSeparation sb = max_face_separation(b.world, a.world);
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
  if (clip_segment(incident_edge, clip1, -tangent, -dot(tangent, v1), 0x800u | static_cast<std::uint32_t>(r1)) < 2) return;
  if (clip_segment(clip1, clip2, tangent, dot(tangent, v2), 0x800u | static_cast<std::uint32_t>(r2)) < 2) return;

  m.normal = flip ? -n : n;
  m.reference_is_b = flip;
  m.local_normal = ref.local_normals[edge];
  m.local_face_point = ref.local_vertices[edge];
  const double face_offset = dot(n, v1);
  for (const ClipVertex& cv : clip2) {
    const double s = dot(n, cv.p) - face_offset;
    if (s > margin) continue;
    ManifoldPoint& p = m.points[m.point_count++];
    p = ManifoldPoint{};
    p.point = cv.p - 0.5 * s * n;
    p.separation = s;
    p.id = (flip ? 0x80000000u : 0u) | (static_cast<std::uint32_t>(edge) << 16) | cv.feature;
    p.local_incident = inc.body_transform.apply_inverse(cv.p);
  }
}

}  // namespace floedem
