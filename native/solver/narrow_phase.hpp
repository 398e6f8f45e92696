#pragma once
// Narrow phase: the contact manifold of two convex polygons (up to 2 points in the plane).
#include <cstdint>

#include "geometry/sat.hpp"
#include "solver/contact_types.hpp"

namespace floedem {

/// Geometry of one convex part for collide(): world vertices and normals, plus the same in
/// its body's frame (centroid-relative, angle 0) and the body's placement.
struct PartGeometry {
  ConvexView world;
  const Vec2* local_vertices = nullptr;
  const Vec2* local_normals = nullptr;
  Transform body_transform;
};

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
