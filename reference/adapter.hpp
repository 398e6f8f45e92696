#pragma once
// What every reference adapter does alike, in one place: handing a step's loads to its library
// and classifying the contacts it reports. Each adapter supplies only the calls of its library.
#include <cstddef>
#include <cstdint>
#include <string>

#include "floedem/engine/engine.hpp"
#include "floedem/scene/scene.hpp"
#include "scenario/table_reader.hpp"

namespace floedem::reference {

/// The scenario's `[engine.NAME]` table read by `read(TableReader&)`, then any key it did not
/// read refused with one line; no table: the adapter's defaults stand, `read` is not called.
template <class Read>
void read_settings(const Scene& scene, const std::string& name, Read read) {
  const auto it = scene.engine_settings.find(name);
  if (it == scene.engine_settings.end()) return;
  TableReader r(it->second, scene.source_path, "engine." + name);
  read(r);
  r.reject_unknown();
}

/// A contact point as a library reports it between bodies i and j (any order): the normal from
/// i towards j and the impulse on j over the step. floedem's record orders the pair (a < b)
/// and states both from a to b: the normal from a to b and the impulse on b, split along the
/// normal and its left perpendicular. Each adapter's own sign convention stays in its call.
inline ContactRecord oriented_record(std::int32_t i, std::int32_t j, Vec2 point, Vec2 normal_ij, Vec2 impulse_on_j,
                                     double separation) {
  const bool flip = i > j;
  ContactRecord r;
  r.body_a = flip ? j : i;
  r.body_b = flip ? i : j;
  r.point = point;
  r.normal = flip ? -normal_ij : normal_ij;
  const Vec2 on_b = flip ? -impulse_on_j : impulse_on_j;
  r.normal_impulse = dot(on_b, r.normal);
  r.tangent_impulse = dot(on_b, perp(r.normal));
  r.separation = separation;
  return r;
}

/// A step's loads, in the order every adapter applies them: the towed bodies' prescribed
/// motions (`prescribe`), then, for each free body (`is_free(i)`), Coriolis as its exact
/// velocity turn where the loads carry one (`velocity(i)` read, `set_velocity(i, v)` written),
/// then its force and torque (`push(i, force, torque)`) where any load acts.
template <class IsFree, class Prescribe, class Velocity, class SetVelocity, class Push>
void hand_loads(const Loads& loads, std::size_t bodies, IsFree is_free, Prescribe prescribe, Velocity velocity,
                SetVelocity set_velocity, Push push) {
  for (const PrescribedMotion& p : loads.prescribed) prescribe(p);
  if (!loads.velocity_turn.empty())
    for (std::size_t i = 0; i < bodies; ++i)
      if (is_free(i)) set_velocity(i, loads.velocity_turn[i].apply(velocity(i)));
  if (loads.any)
    for (std::size_t i = 0; i < bodies; ++i)
      if (is_free(i)) push(i, loads.force[i], loads.torque[i]);
}

/// The normal closing speed at the record's point from the bodies' velocities `before` the
/// step, and from it the scene's rule, the same for every reference: a collision where the
/// bodies close faster than the collision threshold, else a resting contact.
inline void classify(ContactRecord& r, const BodyStates& before, double collision_threshold) {
  const auto at = [&](std::int32_t i) {
    const std::size_t u = static_cast<std::size_t>(i);
    return before.velocity[u] + cross(before.angular_velocity[u], r.point - before.position[u]);
  };
  r.approach_velocity = dot(at(r.body_b) - at(r.body_a), r.normal);
  r.kind = r.approach_velocity < -collision_threshold ? ContactKind::collision : ContactKind::resting;
}

}  // namespace floedem::reference
