#pragma once
// Contact data of the native solver: manifolds from the narrow phase, carried across steps
// (accumulated impulses, for warm starting) by their feature ids.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "floedem/engine/engine.hpp"
#include "floedem/geometry/vec2.hpp"

namespace floedem {

struct ManifoldPoint {
  Vec2 point;                  ///< world, midway between the two surfaces
  double separation = 0.0;     ///< m, signed gap (< 0: overlap)
  std::uint32_t id = 0;        ///< feature id (reference edge, incident feature): same contact, same id
  Vec2 local_incident;         ///< the incident polygon's point, in its body's frame (position solve)
  double normal_impulse = 0.0; ///< N s, accumulated this step (warm start carries it over)
  double tangent_impulse = 0.0;
  double approach_velocity = 0.0;  ///< m/s, u.n before the step
  double target_velocity = 0.0;    ///< m/s, the normal velocity the solve aims at (>=)
  ContactKind kind = ContactKind::resting;
  bool persistent = false;         ///< the same point carried a normal impulse last step
  // Velocity-solve data, set by prepare().
  Vec2 ra, rb;                     ///< lever arms from the centroids
  double wnn = 0.0, wnt = 0.0, wtt = 0.0;  ///< Delassus block n.M^-1 n etc. (see contact_solver.cpp)
};

/// What the narrow phase finds at a point: ManifoldPoint's fields before the solver's.
struct NarrowPoint {
  Vec2 point;               ///< world, midway between the two surfaces
  double separation = 0.0;  ///< m, signed gap (< 0: overlap)
  std::uint32_t id = 0;     ///< feature id
  Vec2 local_incident;      ///< the incident polygon's point, in its body's frame
};

/// A pair's contact: up to two points of type Point and what they share. The solver's
/// (Manifold, below) and the narrow phase's (NarrowManifold) are this one list of fields.
template <class Point>
struct BasicManifold {
  std::int32_t part_a = 0, part_b = 0;   ///< part_a < part_b
  std::int32_t body_a = 0, body_b = 0;   ///< body_a < body_b
  Vec2 normal;                           ///< world, unit, from a to b
  int point_count = 0;
  // Beside the bodies and normal, in the manifold's first 64 bytes: the coloured sweeps'
  // packing reads a one-point manifold's first 192 bytes and this, which stood in its last 64
  // (a fourth cache line read for most of a packed field's manifolds, which have one point);
  // the same results to the bit.
  double friction = 0.0;
  Point points[2];
  // Reference face in its body's frame, for the position solve.
  bool reference_is_b = false;
  Vec2 local_normal;      ///< outward normal of the reference face
  Vec2 local_face_point;  ///< a vertex of the reference face
  double restitution = 0.0;
};

using Manifold = BasicManifold<ManifoldPoint>;

/// What the narrow phase finds for a pair: Manifold without the solver's fields of each point
/// (impulses, lever arms, Delassus blocks, targets), 192 bytes against 384. The narrow phase
/// writes one per pair every step (about 37 000 at 16k floes, packed) and the contact list
/// reads them back: at the full size, that traffic alone filled the 1 MB L2 many times a step.
using NarrowManifold = BasicManifold<NarrowPoint>;

/// Copies what `from` holds into `to`: every field but the points past point_count, which are
/// left as they were (nothing reads them). Byte ranges, not a list of fields, so a field added
/// to the struct is copied too. A copy of the whole struct compiles to a block move (rep movs),
/// whose start-up, and the wait of any load from the copy for its stores, cost more than the
/// copy of what a manifold holds.
template <class M>
inline void copy_manifold(const M& from, M& to) {
  static_assert(std::is_trivially_copyable_v<M> && std::is_standard_layout_v<M>);
  constexpr std::size_t points = offsetof(M, points);
  constexpr std::size_t after_points = points + sizeof(M::points);
  auto* const out = reinterpret_cast<unsigned char*>(&to);
  const auto* const in = reinterpret_cast<const unsigned char*>(&from);
  std::memcpy(out, in, points + static_cast<std::size_t>(from.point_count) * sizeof(M::points[0]));
  std::memcpy(out + after_points, in + after_points, sizeof(M) - after_points);
}

/// The contact list's manifold from the narrow phase's: its fields, the solver's of each point
/// as a fresh ManifoldPoint has them (no impulse, resting, not persistent), the points past
/// point_count left as they were.
inline void fill_manifold(const NarrowManifold& from, Manifold& to) {
  to.part_a = from.part_a;
  to.part_b = from.part_b;
  to.body_a = from.body_a;
  to.body_b = from.body_b;
  to.normal = from.normal;
  to.point_count = from.point_count;
  // Field by field, as ManifoldPoint{} would leave them: `p = ManifoldPoint{}` compiled to a
  // string store (rep stos) of the 144 bytes, whose start-up the next load waited for. A field
  // added to ManifoldPoint must be set here.
  static_assert(sizeof(ManifoldPoint) == 144, "fill_manifold sets every field of ManifoldPoint");
  for (int k = 0; k < from.point_count; ++k) {
    ManifoldPoint& p = to.points[k];
    const NarrowPoint& q = from.points[k];
    p.point = q.point;
    p.separation = q.separation;
    p.id = q.id;
    p.local_incident = q.local_incident;
    p.normal_impulse = p.tangent_impulse = p.approach_velocity = p.target_velocity = 0.0;
    p.kind = ContactKind::resting;
    p.persistent = false;
    p.ra = p.rb = Vec2{};
    p.wnn = p.wnt = p.wtt = 0.0;
  }
  to.reference_is_b = from.reference_is_b;
  to.local_normal = from.local_normal;
  to.local_face_point = from.local_face_point;
  to.friction = from.friction;
  to.restitution = from.restitution;
}

}  // namespace floedem
