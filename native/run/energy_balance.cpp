#include "run/energy_balance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace floedem {

EnergyBalance::EnergyBalance(const Scene& scene) : dt_(scene.run.dt) {
  const std::size_t n = scene.bodies.size();
  mass_.assign(n, 0.0);
  inertia_.assign(n, 0.0);
  path_body_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const BodySpec& b = scene.bodies[i];
    if (b.prescribed) {
      on_path_.push_back(i);
      path_body_[i] = 1;
    } else if (!b.fixed) {
      moving_.push_back(i);
      mass_[i] = scene.engine_mass(i);
      inertia_[i] = scene.engine_inertia(i);
    }
  }
  v_star_.resize(n);
  w_star_.resize(n);
  path_position_.resize(n);
}

double EnergyBalance::kinetic_energy(std::span<const Vec2> v, std::span<const double> w) const {
  double e = 0.0;
  for (const std::size_t i : moving_) e += 0.5 * (mass_[i] * length_squared(v[i]) + inertia_[i] * w[i] * w[i]);
  return e;
}

void EnergyBalance::before_step(const BodyStates& state) {
  for (const std::size_t i : moving_) {
    v_star_[i] = state.velocity[i];
    w_star_[i] = state.angular_velocity[i];
  }
  for (const std::size_t i : on_path_) path_position_[i] = state.position[i];
  if (!ke_before_known_) ke_before_ = kinetic_energy(v_star_, w_star_);
}

void EnergyBalance::after_step(const Loads* loads, const BodyStates& after, std::span<const ContactRecord> contacts) {
  const double ke_start = ke_before_;
  // v*: the velocities the loads alone give (a Coriolis turn first, as the engines do).
  if (loads && !loads->velocity_turn.empty())
    for (const std::size_t i : moving_) v_star_[i] = loads->velocity_turn[i].apply(v_star_[i]);
  if (loads && loads->any)
    for (const std::size_t i : moving_) {
      v_star_[i] += (dt_ / mass_[i]) * loads->force[i];
      w_star_[i] += dt_ / inertia_[i] * loads->torque[i];
    }
  const double ke_star = kinetic_energy(v_star_, w_star_);
  double path_work = 0.0;
  if (!on_path_.empty()) {
    for (const ContactRecord& c : contacts) {
      const bool a_path = path_body_[c.body_a] != 0, b_path = path_body_[c.body_b] != 0;
      if (!a_path && !b_path) continue;
      const Vec2 on_b = c.impulse();
      auto point_velocity = [&](std::int32_t k) {
        return after.velocity[k] + cross(after.angular_velocity[k], c.point - path_position_[k]);
      };
      if (a_path) path_work += dot(on_b, point_velocity(c.body_a));
      if (b_path) path_work -= dot(on_b, point_velocity(c.body_b));
    }
  }
  const double ke_after = kinetic_energy(after.velocity, after.angular_velocity);
  const double contact = ke_after - ke_star - path_work;
  ke_before_ = ke_after;  // the next step starts from this state
  ke_before_known_ = true;
  work_loads_ += ke_star - ke_start;
  work_path_ += path_work;
  work_contact_ += contact;
  const double scale = ke_star + std::abs(path_work);
  const double relative = scale > 0.0 ? contact / scale
                          : contact > 0.0 ? std::numeric_limits<double>::infinity()
                                          : 0.0;
  max_gain_ = std::max(max_gain_, relative);
}

void EnergyBalance::save(StateWriter& out) const {
  out.tag("energy_balance");
  for (const double v : {work_loads_, work_path_, work_contact_, max_gain_}) out.value(v);
}

void EnergyBalance::restore(StateReader& in) {
  in.tag("energy_balance");
  for (double* v : {&work_loads_, &work_path_, &work_contact_, &max_gain_}) in.value(*v);
}

}  // namespace floedem
