#include "solver/step_context.hpp"

#include <algorithm>
#include <cmath>

namespace floedem {

ActiveSet::ActiveSet(std::size_t bodies, std::size_t parts) : settled_(bodies, 0) {
  bodies_.reserve(bodies);
  parts_.reserve(parts);
}

void ActiveSet::settle(std::int32_t body) {
  settled_[static_cast<std::size_t>(body)] = 1;
  ++settled_count_;
  stale_ = true;
}

void ActiveSet::unsettle(std::int32_t body) {
  if (!settled_[static_cast<std::size_t>(body)]) return;
  settled_[static_cast<std::size_t>(body)] = 0;
  --settled_count_;
  stale_ = true;
}

void ActiveSet::unsettle_all() {
  std::fill(settled_.begin(), settled_.end(), 0);
  settled_count_ = 0;
  stale_ = true;
}

void ActiveSet::refresh(const PartSet& parts) {
  if (!stale_) return;
  stale_ = false;
  bodies_.clear();
  parts_.clear();
  for (std::size_t b = 0; b < settled_.size(); ++b) {
    if (settled_[b]) continue;
    const auto body = static_cast<std::int32_t>(b);
    bodies_.push_back(body);
    for (std::int32_t k = parts.first_part(body); k < parts.first_part(body + 1); ++k) parts_.push_back(k);
  }
}

StepContext::StepContext(const Scene& scene)
    : settings(read_native_settings(scene)),
      contact(scene.contact),
      dt(scene.run.dt),
      parts(scene),
      active(scene.bodies.size(), parts.size()) {
  const std::size_t n = scene.bodies.size();
  bodies.position.resize(n);
  bodies.angle.assign(n, 0.0);
  bodies.rotation.assign(n, Rot{});
  bodies.velocity.resize(n);
  bodies.angular_velocity.resize(n);
  bodies.inv_mass.resize(n);
  bodies.inv_inertia.resize(n);
  moves.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const BodySpec& b = scene.bodies[i];
    bodies.position[i] = b.centroid;
    bodies.velocity[i] = b.velocity;
    bodies.angular_velocity[i] = b.angular_velocity;
    // Fixed and prescribed (towed at a given velocity) bodies have infinite mass in contacts.
    const bool infinite = b.fixed || b.prescribed;
    bodies.inv_mass[i] = infinite ? 0.0 : 1.0 / scene.engine_mass(i);
    bodies.inv_inertia[i] = infinite ? 0.0 : 1.0 / scene.engine_inertia(i);
    moves[i] = b.fixed ? 0 : 1;
    has_prescribed = has_prescribed || b.prescribed;
  }
  linear_reach.resize(n);
  angular_reach.resize(n);
}

bool StepContext::set_reach(std::size_t i) {
  // Reach: how far any point of a body can travel this step (dt times its speed after the
  // loads, plus spin times the part's radius), so that contacts are found before the bodies
  // would overlap (speculative contact) and their bounds need no rebuild within the step.
  double speed = length(bodies.velocity[i]);
  double spin = std::abs(bodies.angular_velocity[i]);
  if (loads) {
    speed += dt * length(loads->force[i]) * bodies.inv_mass[i];
    spin += dt * std::abs(loads->torque[i]) * bodies.inv_inertia[i];
  }
  const bool same = same_bits(linear_reach[i], dt * speed) && same_bits(angular_reach[i], dt * spin);
  linear_reach[i] = dt * speed;
  angular_reach[i] = dt * spin;
  return !same;
}

}  // namespace floedem
