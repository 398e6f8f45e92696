#pragma once
// What every reference adapter does alike, in one place: handing a step's loads to its library
// and classifying the contacts it reports. Each adapter supplies only the calls of its library.
#include <cstddef>

#include "floedem/engine/engine.hpp"

namespace floedem::reference {

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
