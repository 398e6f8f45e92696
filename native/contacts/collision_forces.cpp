#include "contacts/collision_forces.hpp"

#include "floedem/scene/input_error.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace floedem {

double collision_duration(double duration_coefficient, double m_eff) { return duration_coefficient * std::sqrt(m_eff); }
double collision_mean_force(double impulse, double duration) { return impulse / duration; }
double collision_peak_force(double impulse, double duration) { return std::numbers::pi * impulse / (2.0 * duration); }

CrushingLaw CrushingLaw::of(const ContactSettings& contact) {
  CrushingLaw law;
  law.stiffness = std::pow(std::numbers::pi / contact.duration_coefficient, 2);
  law.coefficient = contact.crushing_coefficient;
  law.width_exponent = contact.crushing_width_exponent;
  law.thickness_exponent = contact.crushing_thickness_exponent;
  law.iso_thickness_exponent = !contact.has_crushing_thickness_exponent;
  return law;
}

double CrushingLaw::exponent_n(double h) const {
  // ISO 19906 A.8.2.4.3.3: n = -0.5 + h / 5 for h < 1 m, -0.3 from 1 m up.
  return iso_thickness_exponent ? std::min(-0.3, 0.2 * h - 0.5) : thickness_exponent;
}

namespace {

/// Gauss-Legendre nodes and weights on [0, 1] (Newton on P_N from Chebyshev guesses).
struct GaussLegendre {
  static constexpr int N = 24;
  std::array<double, N> x{}, w{};
  GaussLegendre() {
    for (int i = 0; i < N; ++i) {
      double z = std::cos(std::numbers::pi * (i + 0.75) / (N + 0.5)), dp = 0.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= N; ++k) {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = N * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::abs(dz) < 1e-16) break;
      }
      x[static_cast<std::size_t>(i)] = 0.5 * (1.0 - z);
      w[static_cast<std::size_t>(i)] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
  }
};

}  // namespace

CrushingPulse crushing_pulse(double J, double m, const CrushingLaw& law, const ContactWidth& cw) {
  // Loading: m from u = J / (2 m) to rest against F(delta), the energy E = m u^2 / 2 into
  // W(delta) = integral of F. Spring branch F = k delta up to delta_s = sqrt(2 E / k).
  CrushingPulse out;
  const double k = law.stiffness, u = J / (2.0 * m), E = 0.5 * m * u * u;
  const double h = cw.thickness, g = cw.growth, w0 = cw.initial;
  const double q = 1.0 + law.width_exponent;  // F_c = K w^q
  const double K = law.coefficient * std::pow(h, 1.0 + law.exponent_n(h) - law.width_exponent);
  const auto cap = [&](double d) { return K * std::pow(w0 + g * d, q); };
  const double delta_s = std::sqrt(2.0 * E / k);
  const double spring_time = 0.5 * std::numbers::pi * std::sqrt(m / k);
  if (!(J > 0.0) || !(m > 0.0) || !(h > 0.0) || k * delta_s <= cap(delta_s)) {
    // k delta - F_c is convex and <= 0 at 0: below the cap at delta_s, below it all the way.
    out.duration = 2.0 * spring_time;
    out.peak_force = k * delta_s;
    out.width = w0 + g * delta_s;
    out.overlap = delta_s;
    return out;
  }
  // The crossover delta* in [0, delta_s): k delta = F_c (one root: the difference is convex).
  double lo = 0.0, hi = delta_s;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * delta_s; ++it) {
    const double mid = 0.5 * (lo + hi);
    (k * mid <= cap(mid) ? lo : hi) = mid;
  }
  const double ds = 0.5 * (lo + hi), Ws = 0.5 * k * ds * ds, ws = w0 + g * ds;
  // Crushing branch: W(delta) - W* = K (w^(q+1) - w*^(q+1)) / (g (q+1)), or K w0^q (delta - delta*)
  // for a width that does not grow; W(delta_m) = E gives delta_m in closed form.
  double dm;
  if (g > 0.0) {
    const double wm = std::pow(std::pow(ws, q + 1.0) + (E - Ws) * g * (q + 1.0) / K, 1.0 / (q + 1.0));
    dm = (wm - w0) / g;
  } else {
    dm = ds + (E - Ws) / (K * std::pow(w0, q));
  }
  out.crushed = true;
  out.overlap = dm;
  out.width = w0 + g * dm;
  out.peak_force = cap(dm);
  // Loading time: the spring branch in closed form, sqrt(m / k) asin(delta* sqrt(k / m) / u);
  // the crushing branch integral of d delta / v, v = sqrt(2 (E - W(delta)) / m), with
  // delta = delta_m - (delta_m - delta*) s^2 to take out the 1 / sqrt singularity at rest.
  // E - W(delta) = W(delta_m) - W(delta) in a form that does not cancel as delta -> delta_m.
  const auto energy_left = [&](double d) {
    if (g > 0.0) {
      const double w = w0 + g * d, r = std::log1p(g * (dm - d) / w);
      return K * std::pow(w, q + 1.0) * std::expm1((q + 1.0) * r) / (g * (q + 1.0));
    }
    return K * std::pow(w0, q) * (dm - d);
  };
  static const GaussLegendre gl;
  double crush_time = 0.0;
  for (int i = 0; i < GaussLegendre::N; ++i) {
    const double sv = gl.x[static_cast<std::size_t>(i)], d = dm - (dm - ds) * sv * sv;
    crush_time += gl.w[static_cast<std::size_t>(i)] * 2.0 * (dm - ds) * sv / std::sqrt(2.0 * energy_left(d) / m);
  }
  const double spring_part = std::sqrt(m / k) * std::asin(std::min(1.0, ds * std::sqrt(k / m) / u));
  out.duration = 2.0 * (spring_part + crush_time);
  return out;
}

double contact_thickness(const BodySpec& body) {
  return body.kind == BodyKind::iceberg ? body.draft + body.freeboard : body.thickness;
}

namespace {

/// The corner of `body` (pose x, angle) nearest `point`: its distance and 2 tan(alpha / 2),
/// alpha its interior angle (a reflex corner, alpha >= 180 deg, is no corner: growth infinite).
std::pair<double, double> nearest_corner(const BodySpec& body, Vec2 x, double angle, Vec2 point) {
  const Vec2 p = Rot::from_angle(angle).apply_inverse(point - x);
  const std::vector<Vec2>& poly = body.local_polygon;
  const std::size_t n = poly.size();
  double best = std::numeric_limits<double>::infinity(), growth = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const double d = length(poly[i] - p);
    if (!(d < best)) continue;
    best = d;
    // Counter-clockwise polygon: the interior angle between the edges to the neighbours.
    const Vec2 to_prev = normalized(poly[(i + n - 1) % n] - poly[i]), to_next = normalized(poly[(i + 1) % n] - poly[i]);
    const double turn = cross(to_next, to_prev), alpha = std::atan2(turn, dot(to_next, to_prev));
    growth = alpha > 0.0 && alpha < std::numbers::pi * (1.0 - 1e-9) ? 2.0 * std::tan(0.5 * alpha)
                                                                      : std::numeric_limits<double>::infinity();
  }
  return {best, growth};
}

}  // namespace

ContactWidth contact_width_law(const BodySpec& a, Vec2 xa, double angle_a, const BodySpec& b, Vec2 xb, double angle_b,
                               Vec2 point, double spread) {
  ContactWidth cw;
  cw.thickness = std::min(contact_thickness(a), contact_thickness(b));
  cw.initial = spread;
  const double size = std::sqrt(std::min(a.area, b.area)), tolerance = 0.01 * size;
  if (spread > tolerance) return cw;  // a face on a face: the width is the points' spread
  const auto [da, ga] = nearest_corner(a, xa, angle_a, point);
  const auto [db, gb] = nearest_corner(b, xb, angle_b, point);
  double g = std::numeric_limits<double>::infinity();
  if (da <= tolerance) g = std::min(g, ga);
  if (db <= tolerance) g = std::min(g, gb);
  // No corner at the point (two faces touching at one point, as a compliant engine's single
  // point may be): the width is what the points give, and does not grow.
  cw.growth = std::isfinite(g) ? g : 0.0;
  if (cw.growth == 0.0 && cw.initial <= 0.0) cw.initial = tolerance;
  return cw;
}

double effective_mass(Vec2 n, Vec2 r_a, double inv_mass_a, double inv_inertia_a, Vec2 r_b, double inv_mass_b,
                      double inv_inertia_b) {
  const double ra = cross(r_a, n), rb = cross(r_b, n);
  const double k = inv_mass_a + ra * ra * inv_inertia_a + inv_mass_b + rb * rb * inv_inertia_b;
  return k > 0.0 ? 1.0 / k : 0.0;
}

CompliantContact compliant_contact(const ContactSettings& contact) {
  CompliantContact c;
  c.stiffness = std::pow(std::numbers::pi / contact.duration_coefficient, 2);
  const double log_e = std::log(contact.restitution);
  c.damping_ratio = contact.restitution > 0.0 ? -log_e / std::sqrt(std::numbers::pi * std::numbers::pi + log_e * log_e) : 1.0;
  return c;
}

CompliantContacts::CompliantContacts(const Scene& scene) : law_(compliant_contact(scene.contact)) {
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    inv_mass_.push_back(scene.engine_inverse_mass(i));
    inv_inertia_.push_back(scene.engine_inverse_inertia(i));
  }
}

CompliantContacts::PerPoint CompliantContacts::per_point(std::size_t a, std::size_t b, Vec2 normal, Vec2 r_a, Vec2 r_b,
                                                         int points) const {
  const double m_eff = effective_mass(normal, r_a, inv_mass_[a], inv_inertia_[a], r_b, inv_mass_[b], inv_inertia_[b]);
  const double share = 1.0 / points;
  return {share * law_.stiffness, share * 2.0 * law_.damping_ratio * std::sqrt(law_.stiffness * m_eff)};
}

void CompliantContacts::describe(std::map<std::string, std::string>& settings) const {
  settings["contact_stiffness"] = setting_text(law_.stiffness);
  settings["contact_damping_ratio"] = setting_text(law_.damping_ratio);
}

DurationModel duration_model_of(const EngineInfo& engine) {
  const auto it = engine.settings.find("contact_model");
  return it != engine.settings.end() && it->second == "compliant" ? DurationModel::measured : DurationModel::estimated;
}

const char* describe(DurationModel model) {
  return model == DurationModel::measured
             ? "measured on a compliant contact: first to last step with contact force; peak = largest step "
               "impulse / dt; mean = J / duration"
             : "estimated from the impulse: tau = duration_coefficient sqrt(effective_mass) (docs/model.md 4)";
}

CollisionTracker::CollisionTracker(const Scene& scene, DurationModel model)
    : scene_(scene),
      c_tau_(scene.contact.duration_coefficient),
      dt_(scene.run.dt),
      threshold_(scene.contact.collision_threshold),
      model_(model),
      crushing_(scene.contact.force_model == ContactSettings::ForceModel::pressure_area),
      crushing_law_(CrushingLaw::of(scene.contact)) {
  // A compliant engine measures its pulses on its own spring: a crushing cap would have to be
  // in that spring, which no reference engine has.
  if (crushing_ && model_ == DurationModel::measured)
    throw InputError(input_message(scene.source_path, 0, "contact.force_model",
                                   "\"pressure_area\" estimates pulses from impulses; an engine with "
                                   "contact_model = \"compliant\" measures its own: use \"linear\" there"));
}

CollisionTracker::Event CollisionTracker::open_event(double t_end, const StepPair& p, const BodyStates& after) const {
  Event e;
  e.first_step = e.last_step = step_;
  CollisionRow& row = e.row;
  row.time = t_end;
  row.body_a = p.a;
  row.body_b = p.b;
  const auto a = static_cast<std::size_t>(p.a), b = static_cast<std::size_t>(p.b);
  // Impulse-weighted point, normal and approach speed over the impact step's collision points.
  const Vec2 point = (1.0 / p.collision_impulse) * p.weighted_point;
  const Vec2 normal = normalized(p.weighted_normal);
  const double approach = p.weighted_approach / p.collision_impulse;
  // Centroids at the start of the step: x - dt v after it (exact for symplectic Euler, the
  // native scheme; O(dt^2) for the references). The contact points are from the step's start.
  const Vec2 xa = after.position[a] - dt_ * after.velocity[a];
  const Vec2 xb = after.position[b] - dt_ * after.velocity[b];
  const Vec2 ra = point - xa, rb = point - xb;
  row.effective_mass = effective_mass(normal, ra, scene_.engine_inverse_mass(a), scene_.engine_inverse_inertia(a), rb,
                                      scene_.engine_inverse_mass(b), scene_.engine_inverse_inertia(b));
  row.approach_speed = approach;
  // Separation speed after the step at the same material points (the turn of the lever arms
  // within the step is second order in dt w: neglected). The measured model replaces it once
  // the pair has separated, from the point kept in each body's frame.
  const Vec2 va = after.velocity[a] + cross(after.angular_velocity[a], ra);
  const Vec2 vb = after.velocity[b] + cross(after.angular_velocity[b], rb);
  row.restitution_achieved = approach > 0.0 ? dot(vb - va, normal) / approach : 0.0;
  if (crushing_) {
    const double ta = after.angle[a] - dt_ * after.angular_velocity[a];
    const double tb = after.angle[b] - dt_ * after.angular_velocity[b];
    e.width = contact_width_law(scene_.bodies[a], xa, ta, scene_.bodies[b], xb, tb, point, p.spread_max - p.spread_min);
  }
  if (model_ == DurationModel::measured) {
    e.normal = normal;
    e.local_a = Rot::from_angle(after.angle[a]).apply_inverse(point - after.position[a]);
    e.local_b = Rot::from_angle(after.angle[b]).apply_inverse(point - after.position[b]);
  }
  return e;
}

void CollisionTracker::sum_by_pair(std::span<const ContactRecord> contacts) {
  // This step's contacts summed by pair, each pair's records in their order in the list (so
  // the sums do not depend on how the pairs are interleaved). A pair's points need not be
  // adjacent (concave bodies are several convex parts; a reference engine lists its contacts
  // in its own order): the records are then taken in a stable sort by pair.
  step_pairs_.clear();
  auto add = [&](const ContactRecord& c) {
    if (step_pairs_.empty() || step_pairs_.back().a != c.body_a || step_pairs_.back().b != c.body_b) {
      StepPair& fresh = step_pairs_.emplace_back();
      fresh.a = c.body_a;
      fresh.b = c.body_b;
    }
    StepPair& p = step_pairs_.back();
    if (c.normal_impulse > 0.0) p.impulse += c.normal_impulse;
    if (crushing_) {
      // The touching points' extent across the pair's (first) normal: the contact's width.
      if (p.tangent == Vec2{}) {
        p.tangent = perp(c.normal);
        p.spread_min = p.spread_max = dot(c.point, p.tangent);
      }
      const double s = dot(c.point, p.tangent);
      p.spread_min = std::min(p.spread_min, s);
      p.spread_max = std::max(p.spread_max, s);
    }
    // What starts an event: an impulse at a point approaching faster than the threshold
    // (the engines' collision kind; a compliant engine's records say the same).
    const bool impact = model_ == DurationModel::estimated ? c.kind == ContactKind::collision
                                                           : -c.approach_velocity > threshold_;
    if (!impact || !(c.normal_impulse > 0.0)) return;
    p.collision_impulse += c.normal_impulse;
    p.weighted_point += c.normal_impulse * c.point;
    p.weighted_normal += c.normal_impulse * c.normal;
    p.weighted_approach += c.normal_impulse * -c.approach_velocity;
  };
  auto key = [&](std::size_t k) { return PairKey{contacts[k].body_a, contacts[k].body_b}; };
  std::size_t k = 1;
  while (k < contacts.size() && !(key(k) < key(k - 1))) ++k;
  if (k >= contacts.size()) {
    for (const ContactRecord& c : contacts) add(c);
    return;
  }
  order_.resize(contacts.size());
  for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<std::int32_t>(i);
  // Stable by the index as the tie-break (std::stable_sort would allocate a buffer each step).
  std::sort(order_.begin(), order_.end(), [&](std::int32_t x, std::int32_t y) {
    const PairKey kx = key(static_cast<std::size_t>(x)), ky = key(static_cast<std::size_t>(y));
    return kx < ky || (kx == ky && x < y);
  });
  for (const std::int32_t i : order_) add(contacts[static_cast<std::size_t>(i)]);
}

std::int32_t CollisionTracker::store(const Event& event) {
  if (free_slots_.empty()) {
    events_.push_back(event);
    return static_cast<std::int32_t>(events_.size() - 1);
  }
  const std::int32_t slot = free_slots_.back();
  free_slots_.pop_back();
  events_[static_cast<std::size_t>(slot)] = event;
  return slot;
}

void CollisionTracker::observe(double t_end, std::span<const ContactRecord> contacts, const BodyStates& after,
                               std::vector<CollisionRow>& finished) {
  ++step_;
  sum_by_pair(contacts);
  // The step's pairs merged with the open events, both in pair order: a pair with a collision
  // impulse and no open event opens one; an open event whose pair has contact force this step
  // goes on; one whose pair has none (no contact, or contact without force) has separated and
  // ends. Ended events are appended in pair order.
  next_open_.clear();
  std::size_t i = 0, j = 0;
  auto end_event = [&](const OpenEvent& o) {
    finished.push_back(complete(events_[static_cast<std::size_t>(o.slot)], after));
    free_slots_.push_back(o.slot);
  };
  while (j < step_pairs_.size()) {
    const StepPair& p = step_pairs_[j++];
    const PairKey key{p.a, p.b};
    for (; i < open_.size() && open_[i].key < key; ++i) end_event(open_[i]);
    OpenEvent o{key, 0};
    if (i < open_.size() && open_[i].key == key) {
      o.slot = open_[i++].slot;
    } else {
      if (!(p.collision_impulse > 0.0)) continue;  // resting contact only: no event
      o.slot = store(open_event(t_end, p, after));
    }
    Event& e = events_[static_cast<std::size_t>(o.slot)];
    if (model_ == DurationModel::estimated) {
      e.row.normal_impulse += p.collision_impulse;
    } else {
      e.row.normal_impulse += p.impulse;
      e.peak_step_impulse = std::max(e.peak_step_impulse, p.impulse);
    }
    if (p.impulse > 0.0) e.last_step = step_;
    if (e.last_step == step_)
      next_open_.push_back(o);
    else
      end_event(o);
  }
  for (; i < open_.size(); ++i) end_event(open_[i]);
  std::swap(open_, next_open_);
}

CollisionRow CollisionTracker::complete(const Event& e, const BodyStates& now) const {
  CollisionRow row = e.row;
  if (model_ == DurationModel::estimated) {
    row.duration = collision_duration(c_tau_, row.effective_mass);
    row.mean_force = collision_mean_force(row.normal_impulse, row.duration);
    row.peak_force = collision_peak_force(row.normal_impulse, row.duration);
    if (crushing_) {
      const CrushingPulse pulse = crushing_pulse(row.normal_impulse, row.effective_mass, crushing_law_, e.width);
      row.duration = pulse.duration;
      row.mean_force = collision_mean_force(row.normal_impulse, pulse.duration);
      row.peak_force = pulse.peak_force;
      row.contact_width = pulse.width;
      row.crushed = pulse.crushed ? 1 : 0;
    }
    return row;
  }
  row.duration = static_cast<double>(e.last_step - e.first_step + 1) * dt_;
  row.mean_force = row.normal_impulse / row.duration;
  row.peak_force = e.peak_step_impulse / dt_;
  // Restitution once separated: the relative normal velocity at the contact's material points.
  const auto a = static_cast<std::size_t>(row.body_a), b = static_cast<std::size_t>(row.body_b);
  const Vec2 ra = Rot::from_angle(now.angle[a]).apply(e.local_a), rb = Rot::from_angle(now.angle[b]).apply(e.local_b);
  const Vec2 va = now.velocity[a] + cross(now.angular_velocity[a], ra);
  const Vec2 vb = now.velocity[b] + cross(now.angular_velocity[b], rb);
  row.restitution_achieved = row.approach_speed > 0.0 ? dot(vb - va, e.normal) / row.approach_speed : 0.0;
  return row;
}

void CollisionTracker::finish(const BodyStates& now, std::vector<CollisionRow>& finished) {
  for (const OpenEvent& o : open_) finished.push_back(complete(events_[static_cast<std::size_t>(o.slot)], now));
  open_.clear();
  events_.clear();
  free_slots_.clear();
}

void CollisionTracker::save(StateWriter& out) const {
  // Field by field: no padding bytes reach the checkpoint (its bytes are part of the output).
  out.tag("collisions");
  out.value(step_);
  out.value(static_cast<std::uint64_t>(open_.size()));
  for (const OpenEvent& o : open_) {
    const Event& e = events_[static_cast<std::size_t>(o.slot)];
    const CollisionRow& r = e.row;
    out.value(o.key.first);
    out.value(o.key.second);
    for (const double v : {r.time, r.normal_impulse, r.effective_mass, r.approach_speed, r.restitution_achieved,
                           r.duration, r.mean_force, r.peak_force, e.peak_step_impulse})
      out.value(v);
    out.value(r.body_a);
    out.value(r.body_b);
    out.value(e.first_step);
    out.value(e.last_step);
    for (const Vec2 v : {e.normal, e.local_a, e.local_b}) out.value(v);
    if (crushing_)  // only then: the linear model's checkpoints keep their bytes
      for (const double v : {e.width.thickness, e.width.initial, e.width.growth}) out.value(v);
  }
}

void CollisionTracker::restore(StateReader& in) {
  in.tag("collisions");
  in.value(step_);
  const auto n = in.value<std::uint64_t>();
  if (n > in.left()) throw StateError("checkpoint: truncated");
  open_.clear();
  events_.clear();
  free_slots_.clear();
  for (std::uint64_t k = 0; k < n; ++k) {
    PairKey key;
    in.value(key.first);
    in.value(key.second);
    Event e;
    CollisionRow& r = e.row;
    for (double* v : {&r.time, &r.normal_impulse, &r.effective_mass, &r.approach_speed, &r.restitution_achieved,
                      &r.duration, &r.mean_force, &r.peak_force, &e.peak_step_impulse})
      in.value(*v);
    in.value(r.body_a);
    in.value(r.body_b);
    in.value(e.first_step);
    in.value(e.last_step);
    for (Vec2* v : {&e.normal, &e.local_a, &e.local_b}) in.value(*v);
    if (crushing_)
      for (double* v : {&e.width.thickness, &e.width.initial, &e.width.growth}) in.value(*v);
    if (!open_.empty() && !(open_.back().key < key)) throw StateError("checkpoint: collision events out of pair order");
    open_.push_back({key, store(e)});
  }
}

}  // namespace floedem
