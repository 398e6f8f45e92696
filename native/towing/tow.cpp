#include "towing/tow.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "contacts/contact_loads.hpp"

namespace floedem {

Vec2 TowLine::tug_position(const TowSpec& tow, double t) const {
  return tow.mode == TowSpec::Mode::tug ? tug : tow.tug_start + tow.displacement(0.0, t);
}

Vec2 TowLine::tug_velocity(const TowSpec& tow, const EnvironmentSpec* environment, double t) const {
  if (tow.mode != TowSpec::Mode::tug) return tow.velocity_at(t);
  // A tug holds its heading and its track through the water: it moves along its heading at its
  // speed through the water, and with the surface current (its hull and rudder take the rope's
  // pull across the heading). A gridded current is not sampled at the tug.
  Vec2 v = speed * tow.heading_at(t);
  if (environment) v += environment->current_at(0.0) + environment->current_change(t);
  return v;
}

RopeState rope_state(const TowSpec& tow, const TowLine& line, const EnvironmentSpec* environment,
                     const BodyStatesView& s, double t) {
  RopeState r;
  r.tug = line.tug_position(tow, t);
  const std::size_t i = tow.body;
  r.arm = Rot::from_angle(s.angle[i]).apply(tow.attachment);
  const Vec2 point = s.position[i] + r.arm;
  const Vec2 span = r.tug - point;
  r.length = length(span);
  if (r.length == 0.0) return r;
  r.direction = (1.0 / r.length) * span;
  if (r.length <= tow.length || line.parted) return r;  // slack, or parted: no tension
  // dL/dt = (v_tug - v_point) . e
  const Vec2 point_velocity = s.velocity[i] + cross(s.angular_velocity[i], r.arm);
  const double rate = dot(line.tug_velocity(tow, environment, t) - point_velocity, r.direction);
  r.tension = std::max(0.0, tow.stiffness * (r.length - tow.length) + tow.damping * rate);
  return r;
}

std::array<double, 2> tug_pull(const TowSpec& tow, double speed, double t) {
  // A fixed-pitch propeller's thrust less the hull's resistance falls about linearly from the
  // bollard pull at rest to zero at the free-running speed (US Navy Towing Manual, SL740-AA-
  // MAN-010, 5-8; Fossen, Handbook of Marine Craft Hydrodynamics and Motion Control, 2011,
  // 9.2: thrust T = T_0 (1 - V_a / (n D)) at a fixed propeller speed). Past V_f the line goes
  // on (the hull's resistance exceeds the thrust); astern (V < 0) the pull is held at P_B.
  // A tug throttles up over pull_ramp rather than snatching a taut line at full power.
  const double pull = tow.pull_ramp > 0.0 ? std::min(1.0, t / tow.pull_ramp) * tow.bollard_pull : tow.bollard_pull;
  if (speed < 0.0) return {pull, 0.0};
  const double slope = pull / tow.free_running_speed;
  return {pull - slope * speed, -slope};
}

void TensionHistogram::add(double tension) {
  ++total_;
  if (!(tension > 0.0)) {
    ++slack_;
    return;
  }
  const int n = static_cast<int>(bins_.size());
  const int k = static_cast<int>(std::floor(std::log10(std::max(tension, 1.0)) * kBinsPerDecade));
  ++bins_[static_cast<std::size_t>(std::clamp(k, 0, n - 1))];
}

double TensionHistogram::quantile(double q) const {
  if (total_ == 0) return 0.0;
  // The smallest value with at least q of the steps at or below it.
  const auto need = static_cast<std::int64_t>(std::ceil(q * static_cast<double>(total_)));
  std::int64_t seen = slack_;
  if (seen >= need) return 0.0;
  for (std::size_t k = 0; k < bins_.size(); ++k) {
    seen += bins_[k];
    if (seen >= need) return std::pow(10.0, (static_cast<double>(k) + 0.5) / kBinsPerDecade);
  }
  return std::pow(10.0, static_cast<double>(kDecades));
}

void TensionHistogram::save(StateWriter& out) const {
  out.value(slack_);
  out.value(total_);
  out.vector(bins_);
}

void TensionHistogram::restore(StateReader& in) {
  in.value(slack_);
  in.value(total_);
  in.vector(bins_);
  if (bins_.size() != static_cast<std::size_t>(kBinsPerDecade * kDecades))
    throw StateError("checkpoint: the tow's tension histogram has another size");
}

TowMonitor::TowMonitor(const Scene& scene)
    : scene_(scene), tow_(scene.tow), direction_(scene.tow.direction()), line_(scene.tow) {}

Vec2 TowMonitor::tug_position(double time) const {
  if (tow_.has_rope()) return line_.tug_position(tow_, time);
  return scene_.bodies[tow_.body].centroid + tow_.displacement(0.0, time);
}

void TowMonitor::before_step(const BodyStates& state, double time) {
  time_ = time;
  if (!tow_.has_rope()) return;
  rope_ = rope_state(tow_, line_, water(), state, time);
  if (tow_.breaking_load > 0.0 && !line_.parted && rope_.tension > tow_.breaking_load) {
    line_.parted = true;
    line_.parted_at = time;
    rope_.tension = 0.0;
  }
  if (!line_.parted) {
    tensions_.add(rope_.tension);
    tension_max_ = std::max(tension_max_, rope_.tension);
  }
  frame_tension_max_ = std::max(frame_tension_max_, rope_.tension);
}

void TowMonitor::after_step(const BodyStates& state, std::span<const ContactRecord> contacts,
                            const std::array<double, 3>& env) {
  const double dt = scene_.run.dt;
  const Vec2 contact = contact_impulse_on(static_cast<std::int32_t>(tow_.body), contacts);  // N s
  ice_ = -(1.0 / dt) * contact;
  if (tow_.has_rope()) {
    force_ = rope_.tension * rope_.direction;
  } else if (tow_.mode == TowSpec::Mode::velocity) {
    const BodySpec& b = scene_.bodies[tow_.body];
    const double mi = b.mass * (1.0 + b.added_mass_coefficient);
    const Vec2 inertial = mi * tow_.acceleration_at(time_ + 0.5 * dt);
    // Rope-free forcing on the body at the start of the step (the rope term is absent here).
    force_ = inertial - Vec2{env[0], env[1]} + ice_;
  }
  if (tow_.mode == TowSpec::Mode::tug) {
    // The tug's speed V through the water along its heading h: m_t dV/dt = P(V) - T (e . h),
    // the rope pulling it back along e (from the iceberg to the tug) with the start of the
    // step's tension T. Linearly implicit in V (as the bodies' forcing, forcing.cpp), so that
    // neither a stiff rope nor a light tug limits the step: the rope's share of dF/dV is
    // -(c + dt k) (e . h)^2, since T grows by c and, over the step, dt k per m/s the tug
    // makes along the rope. Then the position, with the new speed (semi-implicit Euler).
    const Vec2 h = tow_.heading_at(time_);
    const auto [pull, slope] = tug_pull(tow_, line_.speed, time_);
    const double along = dot(rope_.direction, h);
    const double rope = -rope_.tension * along;
    const double jacobian = slope - (rope_.tension > 0.0 ? (tow_.damping + dt * tow_.stiffness) * along * along : 0.0);
    line_.speed += dt * (pull + rope) / (tow_.tug_mass - dt * jacobian);
    line_.tug += dt * line_.tug_velocity(tow_, water(), time_);
  }
  if (dot(state.velocity[tow_.body], direction_) < tow_.stall_speed) stalled_time_ += dt;
  sum_ += force_;
  ice_sum_ += ice_;
  ++count_;
}

TowOutcome TowMonitor::outcome(const BodyStates& state, double time) const {
  TowOutcome o;
  o.direction = direction_;
  const Vec2 moved = state.position[tow_.body] - scene_.bodies[tow_.body].centroid;
  o.distance = dot(moved, o.direction);
  o.cross_track = cross(o.direction, moved);
  o.speed_made_good = time > 0.0 ? o.distance / time : 0.0;
  o.stall_speed = tow_.stall_speed;
  o.stalled_time = stalled_time_;
  o.parted = line_.parted;
  o.parted_at = line_.parted ? line_.parted_at : std::numeric_limits<double>::quiet_NaN();
  o.tension_max = tension_max_;
  // The histogram's bin centre can lie above the largest tension itself, which is exact.
  o.tension_p99 = std::min(tensions_.quantile(0.99), tension_max_);
  return o;
}

void TowMonitor::save(StateWriter& out) const {
  out.tag("tow");
  for (const Vec2 v : {force_, ice_, sum_, ice_sum_}) out.value(v);
  out.value(count_);
  out.value(time_);
  if (!active()) return;  // a scene without a tow keeps the layout it had before the line
  out.tag("tow line");
  out.value(line_.tug);
  out.value(line_.speed);
  out.value(static_cast<std::uint8_t>(line_.parted));
  out.value(line_.parted_at);
  for (const double v : {frame_tension_max_, tension_max_, stalled_time_}) out.value(v);
  tensions_.save(out);
}

void TowMonitor::restore(StateReader& in) {
  in.tag("tow");
  for (Vec2* v : {&force_, &ice_, &sum_, &ice_sum_}) in.value(*v);
  in.value(count_);
  in.value(time_);  // the rope is found again at the start of the next step
  if (!active()) return;
  in.tag("tow line");
  in.value(line_.tug);
  in.value(line_.speed);
  line_.parted = in.value<std::uint8_t>() != 0;
  in.value(line_.parted_at);
  for (double* v : {&frame_tension_max_, &tension_max_, &stalled_time_}) in.value(*v);
  tensions_.restore(in);
}

TowFrame TowMonitor::take_frame(double time) {
  TowFrame f;
  f.force = force_;
  f.force_mean = count_ > 0 ? (1.0 / static_cast<double>(count_)) * sum_ : force_;
  f.ice_force_mean = count_ > 0 ? (1.0 / static_cast<double>(count_)) * ice_sum_ : ice_;
  f.tug_position = tug_position(time);
  f.tension_max = frame_tension_max_;
  f.tug_velocity = line_.tug_velocity(tow_, water(), time);
  sum_ = {};
  ice_sum_ = {};
  count_ = 0;
  frame_tension_max_ = 0.0;
  return f;
}

TowFrame TowMonitor::start_frame() const {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  TowFrame f;
  f.force = f.force_mean = f.ice_force_mean = {nan, nan};
  f.tug_position = tug_position(0.0);
  f.tug_velocity = line_.tug_velocity(tow_, water(), 0.0);
  return f;
}

}  // namespace floedem
