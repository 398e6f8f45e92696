#include "towing/tow.hpp"

#include <algorithm>

#include "contacts/contact_loads.hpp"

namespace floedem {

RopeState rope_state(const TowSpec& tow, const BodyStatesView& s, double t) {
  RopeState r;
  r.tug = tow.tug_start + tow.displacement(0.0, t);
  const std::size_t i = tow.body;
  r.arm = Rot::from_angle(s.angle[i]).apply(tow.attachment);
  const Vec2 point = s.position[i] + r.arm;
  const Vec2 span = r.tug - point;
  r.length = length(span);
  if (r.length <= tow.length || r.length == 0.0) return r;  // slack
  r.direction = (1.0 / r.length) * span;
  // dL/dt = (v_tug - v_point) . e
  const Vec2 point_velocity = s.velocity[i] + cross(s.angular_velocity[i], r.arm);
  const double rate = dot(tow.velocity_at(t) - point_velocity, r.direction);
  r.tension = std::max(0.0, tow.stiffness * (r.length - tow.length) + tow.damping * rate);
  return r;
}

TowMonitor::TowMonitor(const Scene& scene) : scene_(scene), tow_(scene.tow) {}

Vec2 TowMonitor::tug_position(double time) const {
  if (tow_.mode == TowSpec::Mode::rope) return tow_.tug_start + tow_.displacement(0.0, time);
  return scene_.bodies[tow_.body].centroid + tow_.displacement(0.0, time);
}

void TowMonitor::before_step(const BodyStates& state, double time) {
  time_ = time;
  if (tow_.mode == TowSpec::Mode::rope) rope_ = rope_state(tow_, state, time);
}

void TowMonitor::after_step(std::span<const ContactRecord> contacts, const std::array<double, 3>& env) {
  const double dt = scene_.run.dt;
  const Vec2 contact = contact_impulse_on(static_cast<std::int32_t>(tow_.body), contacts);  // N s
  ice_ = -(1.0 / dt) * contact;
  if (tow_.mode == TowSpec::Mode::rope) {
    force_ = rope_.tension * rope_.direction;
  } else if (tow_.mode == TowSpec::Mode::velocity) {
    const BodySpec& b = scene_.bodies[tow_.body];
    const double mi = b.mass * (1.0 + b.added_mass_coefficient);
    const Vec2 inertial = mi * tow_.acceleration_at(time_ + 0.5 * dt);
    // Rope-free forcing on the body at the start of the step (the rope term is absent here).
    force_ = inertial - Vec2{env[0], env[1]} + ice_;
  }
  sum_ += force_;
  ice_sum_ += ice_;
  ++count_;
}

void TowMonitor::save(StateWriter& out) const {
  out.tag("tow");
  for (const Vec2 v : {force_, ice_, sum_, ice_sum_}) out.value(v);
  out.value(count_);
  out.value(time_);
}

void TowMonitor::restore(StateReader& in) {
  in.tag("tow");
  for (Vec2* v : {&force_, &ice_, &sum_, &ice_sum_}) in.value(*v);
  in.value(count_);
  in.value(time_);  // the rope is found again at the start of the next step
}

TowFrame TowMonitor::take_frame(double time) {
  TowFrame f;
  f.force = force_;
  f.force_mean = count_ > 0 ? (1.0 / static_cast<double>(count_)) * sum_ : force_;
  f.ice_force_mean = count_ > 0 ? (1.0 / static_cast<double>(count_)) * ice_sum_ : ice_;
  f.tug_position = tug_position(time);
  sum_ = {};
  ice_sum_ = {};
  count_ = 0;
  return f;
}

}  // namespace floedem
