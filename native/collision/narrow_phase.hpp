#pragma once
// Narrow phase: the contact manifold of two convex polygons (up to 2 points in the plane).
#include <cstdint>

#include <span>

#include "floedem/scene/scene.hpp"
#include "geometry/sat.hpp"
#include "collision/manifold.hpp"

namespace floedem {

/// Geometry of one convex part for collide(): world vertices and normals, plus the same in
/// its body's frame (centroid-relative, angle 0) and the body's placement.
struct PartGeometry {
  ConvexView world;
  const Vec2* local_vertices = nullptr;
  const Vec2* local_normals = nullptr;
  Transform body_transform;
};

/// Names what collide() does not set: m's parts (a < b), their bodies and the contact's
/// material (the scene's friction and restitution).
template <class M>
void name_pair(M& m, std::int32_t part_a, std::int32_t part_b, std::span<const std::int32_t> part_body,
               const ContactSettings& contact) {
  m.part_a = part_a;
  m.part_b = part_b;
  m.body_a = part_body[part_a];
  m.body_b = part_body[part_b];
  m.friction = contact.friction;
  m.restitution = contact.restitution;
}

/// Fills m.normal, points (point, separation, id, local_incident), reference-face data and
/// point_count (0 when the polygons are farther apart than `margin`).
/// Reference face: the face of largest separation (SAT); the incident edge of the other
/// polygon is clipped to the reference face's side planes (Sutherland-Hodgman), and every
/// clipped point closer than `margin` becomes a contact point. After Box2D v2.4's
/// b2CollidePolygons (Catto, GDC 2007 "Contact manifolds"), with zero skin radius.
/// Where clipping leaves nothing (the polygons apart, corner beside corner), the one point is the
/// closest pair of points, its normal along the line joining them (what speculative contact
/// needs: a floe sliding corner-first onto another's face within the step).
/// `hint` (optional, kept per pair by the caller): the edges to test first, updated to this
/// test's; the manifold is the same with or without it, to the bit.
void collide(const PartGeometry& a, const PartGeometry& b, double margin, double flip_tolerance, Manifold& m,
             SeparationHint* hint = nullptr);
/// The same into the narrow phase's compact manifold (NarrowManifold, what the engine keeps per
/// pair): the same fields, the same values to the bit.
void collide(const PartGeometry& a, const PartGeometry& b, double margin, double flip_tolerance,
             NarrowManifold& m, SeparationHint* hint = nullptr);

}  // namespace floedem
