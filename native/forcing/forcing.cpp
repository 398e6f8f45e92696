// Forcing: sums the terms and takes one linearly implicit step per body.
//
// Per body, with q = (v_x, v_y, omega), inertia M = diag(m_I, m_I, I_I) including added mass
// (m_I = m (1 + C_m)), the terms' force Q, its Jacobian D = dQ/dq and a rotation rate f:
//
//   M (q_n+1 - q_n) / h = Q(q^) + s D (q_n+1 - q_n) - C (q_n + q_n+1) / 2
//
// where C q = m_I f~ (k x v, 0) and h = dt (half of it on a free body's first step, below).
// Coriolis is trapezoidal (Cayley) with f~ = (2/h) tan(f' dt / 2), f' = f m / m_I, which
// turns the velocity by exactly f' dt per step: no drift of the speed and no phase error, so
// the inertial circle closes (the requirement is 1e-4 of the radius after 10 periods at
// dt = 60 s).
//
// The engines move positions by symplectic Euler, x_n+1 = x_n + dt v_n+1: a leapfrog whose
// velocities sit at half steps, v_n ~ v(t_n - dt/2). The step is second order when its force
// is taken at t_n, between the two velocities it joins, and when the velocities start at
// dt/2: the first step turns by f' dt / 2 (half the angle), and a free body (below) is given
// half a step of force (h = dt/2; otherwise the drift is off by about its velocity change
// over half a step, times its drag time: first order in dt).
//
// Where the force is taken, q^, and the weight s of D:
// - a free body (no contact in the last step): q^ = q_n + (dt/2) a_n-1, its velocity at t_n
//   extrapolated from the acceleration the forcing gave it in the last step (second order:
//   a_n-1 = a(t_n) + O(dt)), and s = 0 while h |D| / M < 0.5. For a floe in a current with
//   Coriolis and linearised drag the position error then falls four-fold when dt halves,
//   against two-fold with q^ = q_n. One evaluation of the terms, without D.
// - a body that touched another in the last step: q^ = q_n, s = 0 while h |D| / M < 0.5.
//   Explicit, and at q_n, because the load handed on is the force of a body that moves
//   freely: a body held still by contacts would see its drag under-reported by
//   1 / (1 + s h |D| / M) (0.2 % for a 10 m floe at dt = 0.05 s with s = 1), or taken at a
//   velocity it does not reach, and the ice loads on held bodies are what users read. Its
//   first step is a whole one.
// - either, where h |D| / M >= 0.5 (a small floe at a long step): s = 1, linearly implicit
//   (Rosenbrock-Euler: stable at any dt, first order); its acceleration is not kept, so from
//   the step after it turned stiff it is seen at q_n (an extrapolation by a stiff acceleration
//   would not be stable). Such a body relaxes to the flow within a few steps.
// For a linear drag the steady state is the exact one in every case. The engines get
// M_e (q_n+1 - q_n) / dt as constant loads, M_e the mass they move (m, or m_I when added mass
// enters contacts); contacts then act by their impulse laws on top, unchanged.
#include <algorithm>
#include <cmath>
#include <limits>

#include "floedem/scene/input_error.hpp"
#include "forcing/drag_pass.hpp"
#include "forcing/coriolis_field.hpp"
#include "forcing/flow_grid.hpp"
#include "forcing/forcing.hpp"
#include "parallel/thread_pool.hpp"

namespace floedem {

namespace {
// Every term floedem has, in the order they are added.
constexpr ForceTermBuilder kTermBuilders[] = {
    build_applied_load,  build_water_form_drag,  build_water_skin_drag, build_air_form_drag, build_air_skin_drag,
    build_coriolis,      build_sea_surface_tilt, build_wave_radiation,  build_rope_tow,
};

bool plus_zero(double x) { return x == 0.0 && !std::signbit(x); }

/// Solves the 3x3 system a x = b (Cramer's rule; a is well conditioned: M/dt dominates).
std::array<double, 3> solve3(const std::array<double, 9>& a, const std::array<double, 3>& b) {
  const double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                     a[2] * (a[3] * a[7] - a[4] * a[6]);
  std::array<double, 3> x{};
  for (int c = 0; c < 3; ++c) {
    std::array<double, 9> m = a;
    for (int r = 0; r < 3; ++r) m[r * 3 + c] = b[r];
    x[c] = (m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
            m[2] * (m[3] * m[7] - m[4] * m[6])) / det;
  }
  return x;
}
}  // namespace

void Forcing::attach_tow(const TowLine& line) {
  for (const auto& term : terms_) term->attach_tow(line);
}

std::array<double, 3> Forcing::environment_force(std::size_t i) const {
  std::array<double, 3> q = sums_.q[i];
  if (sums_.any_rotation && scene_.bodies[i].prescribed) {
    const double mf = scene_.bodies[i].mass * sums_.rotation_rate[i];
    q[0] += mf * moved_velocity_[i].y;
    q[1] -= mf * moved_velocity_[i].x;
  }
  return q;
}

double Forcing::drag_rate(const std::array<double, 9>& d, double mass, double inertia) {
  // Row sums bound the eigenvalues (Gershgorin): h times this rate below 2 keeps explicit
  // Euler stable, well below 1 accurate.
  const double linear = std::max(std::abs(d[0]) + std::abs(d[1]), std::abs(d[3]) + std::abs(d[4])) / mass;
  const double angular = std::abs(d[8]) / inertia;
  return std::max(linear, angular);
}

Forcing::Forcing(const Scene& scene, bool share_drag_pass) : scene_(scene), dt_(scene.run.dt) {
  for (const ForceTermBuilder build : kTermBuilders)
    if (auto term = build(scene)) terms_.push_back(std::move(term));
  // Gridded fields, read a time slice at a time (flow_grid.hpp), shared by the terms that read
  // them; such drag terms work point by point, without the shared pass.
  const EnvironmentSpec& env = scene.environment;
  if (!env.current_grid.empty()) fields_.current = std::make_unique<FlowGrid>(env.current_grid);
  if (!env.wind_grid.empty()) fields_.wind = std::make_unique<FlowGrid>(env.wind_grid);
  if (scene.geo.present && env.coriolis) fields_.coriolis = std::make_unique<CoriolisField>(scene.geo);
  bool gridded = false;
  for (auto& t : terms_) {
    t->attach_fields(fields_);
    if (DistributedDrag* d = t->distributed_drag(); d && d->gridded()) gridded = true;
  }
  if (gridded) share_drag_pass = false;
  // The first run of consecutive drag terms (the four of a drifting field) shares a pass over
  // the floes they all act on; from then on those terms leave those floes to the pass.
  for (std::size_t k = 0; share_drag_pass && k < terms_.size(); ++k) {
    std::size_t end = k;
    while (end < terms_.size() && end - k < static_cast<std::size_t>(DragPass::kMaxTerms) &&
           terms_[end]->distributed_drag() != nullptr)
      ++end;
    if (end - k < 2) continue;
    std::vector<DistributedDrag*> run;
    for (std::size_t t = k; t < end; ++t) run.push_back(terms_[t]->distributed_drag());
    auto pass = std::make_unique<DragPass>(run, [&](std::size_t i) -> const std::vector<Vec2>& {
      return scene.bodies[i].local_polygon;
    });
    if (pass->floes() > 0) {  // else no floe was left to it: the terms add alone
      drag_pass_ = std::move(pass);
      pass_first_ = k;
      pass_count_ = end - k;
    }
    break;
  }
  const std::size_t n = scene.bodies.size();
  for (std::size_t i = 0; i < n; ++i)
    if (scene.bodies[i].prescribed) prescribed_.push_back(i);
  loads_.force.resize(n);
  loads_.torque.resize(n);
  sums_.q.resize(n);
  sums_.dq.resize(n);
  sums_.rotation_rate.resize(n);
  sums_.rotation.resize(n);
  sums_.jacobian.assign(n, 1);
  sums_.rate_bound.resize(n);
  for (auto& t : terms_)
    if (DistributedDrag* d = t->distributed_drag(); d && d->flow_varies()) varying_.push_back(d);
  list_stirred_ = std::any_of(terms_.begin(), terms_.end(), [](const auto& t) { return t->reads_stirred(); });
  moving_only_ = list_stirred_ && std::all_of(terms_.begin(), terms_.end(), [](const auto& t) { return t->idle_at_rest(); });
  if (list_stirred_) sums_.stirred.reserve(n);
  if (moving_only_) loads_.loaded.reserve(n);
  rotated_angle_.assign(n, std::numeric_limits<double>::quiet_NaN());  // NaN: none computed yet
  cached_rate_.assign(n, 0.0);
  ahead_.assign(n, {});
  cached_tan_.assign(n, 0.0);
  cached_half_tan_.assign(n, 0.0);
  // What the per-step loop reads, packed per body: the scene's bodies are large records.
  hot_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const BodySpec& b = scene.bodies[i];
    BodyHot& h = hot_[i];
    h.moves = !(b.fixed || b.prescribed);
    h.mass = b.mass;
    h.mass_with_added = b.mass * (1.0 + b.added_mass_coefficient);
    h.inertia_with_added = b.inertia * (1.0 + b.added_mass_coefficient);
    h.engine_mass = scene.engine_mass(i);
    h.engine_inertia = scene.engine_inertia(i);
  }
  // A scene whose only terms are constant rotations (Coriolis alone): with q = 0 and no
  // Jacobian the general path below is the Cayley rotation of the velocity by exactly
  // -f' dt (f' = f m / m_I; half of it on the first step), so the engines are handed that
  // turn instead of forces.
  rotation_only_ = !terms_.empty() && prescribed_.empty() &&
                   std::all_of(terms_.begin(), terms_.end(), [](const auto& t) { return t->constant_rotation_only(); });
  if (rotation_only_) {
    std::fill(sums_.rotation_rate.begin(), sums_.rotation_rate.end(), 0.0);
    BodyStates none;
    none.resize(n);
    for (const auto& t : terms_) t->add(none, 0.0, sums_);
    turn_first_.assign(n, Rot{});
    turn_later_.assign(n, Rot{});
    for (std::size_t i = 0; i < n; ++i) {
      const BodyHot& h = hot_[i];
      if (!h.moves) continue;
      const double f = sums_.rotation_rate[i] * h.mass / h.mass_with_added;
      turn_first_[i] = Rot::from_angle(-0.5 * f * dt_);
      turn_later_[i] = Rot::from_angle(-f * dt_);
    }
  }
}

Forcing::~Forcing() = default;

std::size_t Forcing::drag_pass_floes() const { return drag_pass_ ? drag_pass_->floes() : 0; }

std::vector<std::string_view> Forcing::names() const {
  std::vector<std::string_view> out;
  for (const auto& t : terms_) out.push_back(t->name());
  return out;
}

const Loads* Forcing::evaluate(const BodyStates& state, double time, std::span<const Rot> rotations,
                               std::span<const std::uint8_t> touching) {
  if (empty()) return nullptr;
  touching_ = touching.size() == hot_.size() ? touching : std::span<const std::uint8_t>{};
  loads_.prescribed.clear();
  for (const std::size_t i : prescribed_) {
    // Mid-step velocity: dt times it is the path's exact displacement (piecewise linear).
    const Vec2 v = scene_.tow.displacement(time, time + dt_);
    loads_.prescribed.push_back({static_cast<std::int32_t>(i), (1.0 / dt_) * v, 0.0});
  }
  loads_.any = !terms_.empty();
  if (terms_.empty()) return &loads_;
  if (rotation_only_) {
    loads_.any = false;
    const std::vector<Rot>& turn = time == 0.0 ? turn_first_ : turn_later_;
    if (turn_handed_ != &turn) {  // copied twice per run: at the first step and the second
      loads_.velocity_turn = turn;
      turn_handed_ = &turn;
    }
    return &loads_;
  }
  if (!varying_.empty()) set_flows(time);
  const BodyStatesView at = state_seen(state);
  place_rotations(at, rotations);
  sums_.stirred.clear();
  if (list_stirred_)
    for (std::size_t i = 0; i < hot_.size(); ++i) {
      const Vec2 v = at.velocity[i];
      if (v.x != 0.0 || v.y != 0.0 || at.angular_velocity[i] != 0.0) sums_.stirred.push_back(static_cast<std::int32_t>(i));
    }
  // Moving bodies alone (moving_only_): every term is idle at rest, so a body at rest gets
  // Q = +0, no Jacobian and no rate bound, hence no load (load_body's first skip), and its
  // entries stay as the full path would set them once those the last step wrote are zeroed.
  // The same sums and loads to the bit.
  const bool sparse = moving_only_ && have_dirty_;
  const std::span<const std::int32_t> moving = sums_.stirred;
  if (sparse) {
    for (const std::int32_t i : loads_.loaded) {
      sums_.rate_bound[i] = {};
      sums_.q[i] = {};
      if (sums_.any_jacobian) sums_.dq[i] = {};
      loads_.force[i] = {};
      loads_.torque[i] = 0.0;
    }
  }
  choose_jacobians(at, sparse);
  if (sums_.any_rotation) std::fill(sums_.rotation_rate.begin(), sums_.rotation_rate.end(), 0.0);
  sums_.any_jacobian = sums_.any_rotation = false;
  for (std::size_t k = 0; k < terms_.size(); ++k) {
    if (drag_pass_ && k == pass_first_) {  // the run's terms, the shared floes in one pass
      drag_pass_->add(at, time, sums_);
      k += pass_count_ - 1;
      continue;
    }
    terms_[k]->add(at, time, sums_);
  }
  if (fields_.current || fields_.wind) check_fields();

  const bool first_step = time == 0.0;
  // Per body, independent: blocks on the pool's threads (the same result on any number).
  if (sparse) {
    thread_pool().for_blocks(moving.size(), 2048, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) load_body(static_cast<std::size_t>(moving[k]), state, first_step);
    });
  } else {
    thread_pool().for_blocks(hot_.size(), 2048, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) load_body(i, state, first_step);
    });
  }
  // The moving bodies: the next step zeroes what they hold; after the first step, the loads
  // name them as the only bodies with a load (those at rest zeroed above).
  if (moving_only_) {
    loads_.loaded.assign(moving.begin(), moving.end());
    have_dirty_ = true;
  }
  loads_.listed = sparse;
  note_ahead();
  return &loads_;
}

void Forcing::set_flows(double time) {
  // The flows at the step's start, t_n: the leapfrog takes its force there (the comment at the
  // top), so a flow that changes in time keeps the step second order.
  for (FlowGrid* g : {fields_.current.get(), fields_.wind.get()})
    if (g) g->prepare(time);
  for (DistributedDrag* d : varying_) d->set_time(time);
  if (drag_pass_) drag_pass_->refresh_flows();
}

void Forcing::check_fields() {
  // A point off a grid or on its fill value was noted while the terms read it (from the pool's
  // threads); the run stops here, between steps, with the file and what was found.
  for (FlowGrid* g : {fields_.current.get(), fields_.wind.get()})
    if (g)
      if (const std::string problem = g->take_problem(); !problem.empty())
        throw InputError(input_message(g->spec().file, 0, g->spec().u,
                                       problem));
}

BodyStatesView Forcing::state_seen(const BodyStates& state) {
  // A prescribed body feels the forcing at the velocity it will have over the step.
  // Only the velocities are copied (the terms read positions and angles from the state).
  BodyStatesView at = state;
  if (!prescribed_.empty()) {
    moved_velocity_.assign(state.velocity.begin(), state.velocity.end());
    moved_angular_velocity_.assign(state.angular_velocity.begin(), state.angular_velocity.end());
    for (const PrescribedMotion& p : loads_.prescribed) {
      moved_velocity_[p.body] = p.velocity;
      moved_angular_velocity_[p.body] = p.angular_velocity;
    }
    at.velocity = moved_velocity_;
    at.angular_velocity = moved_angular_velocity_;
  }
  // A free body feels the terms at its mid-step velocity q_n + (dt/2) a_n-1 (the comment at
  // the top; a_n-1 is zero for a touching or stiff body, and before the first step).
  if (any_ahead_) {
    if (prescribed_.empty()) {
      moved_velocity_.assign(state.velocity.begin(), state.velocity.end());
      moved_angular_velocity_.assign(state.angular_velocity.begin(), state.angular_velocity.end());
      at.velocity = moved_velocity_;
      at.angular_velocity = moved_angular_velocity_;
    }
    const double half = 0.5 * dt_;
    thread_pool().for_blocks(hot_.size(), 8192, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::array<double, 3>& a = ahead_[i];
        if (!free_body(i) || (a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0)) continue;
        moved_velocity_[i] += half * Vec2{a[0], a[1]};
        moved_angular_velocity_[i] += half * a[2];
      }
    });
  }
  return at;
}

void Forcing::place_rotations(const BodyStatesView& at, std::span<const Rot> rotations) {
  // Per body: its rotation, the engine's where it has them (the same Rot::from_angle of the
  // same angle: a copy, not a sine and cosine per body), else made where it turned (blocks on
  // the pool's threads).
  if (rotations.size() == hot_.size()) {
    std::copy(rotations.begin(), rotations.end(), sums_.rotation.begin());
    rotations_copied_ = true;
    return;
  }
  if (rotations_copied_) {  // the angles the rotations were made for are not known
    std::fill(rotated_angle_.begin(), rotated_angle_.end(), std::numeric_limits<double>::quiet_NaN());
    rotations_copied_ = false;
  }
  thread_pool().for_blocks(hot_.size(), 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      if (at.angle[i] != rotated_angle_[i]) {  // the body turned (or the first step)
        sums_.rotation[i] = Rot::from_angle(at.angle[i]);
        rotated_angle_[i] = at.angle[i];
      }
  });
}

void Forcing::choose_jacobians(const BodyStatesView& at, bool sparse) {
  // Which bodies need D: where the terms' bound on dt |D| / M stays below the explicit limit,
  // load_body would find the body explicit whatever D is, so D is not computed (the terms then
  // skip its nine products per quadrature point). The margin covers rounding in the sums.
  if (!sparse) std::fill(sums_.rate_bound.begin(), sums_.rate_bound.end(), std::array<double, 2>{});
  bool bounded = true;
  for (std::size_t k = 0; k < terms_.size(); ++k) {
    if (drag_pass_ && k == pass_first_) {  // the run's terms (drag: always bounded)
      drag_pass_->add_rate_bound(at, sums_);
      k += pass_count_ - 1;
      continue;
    }
    bounded = terms_[k]->add_rate_bound(at, sums_) && bounded;
  }
  auto needs_jacobian = [&](std::size_t i) {
    const BodyHot& h = hot_[i];
    const std::array<double, 2>& b = sums_.rate_bound[i];
    if (b[0] == 0.0 && b[1] == 0.0) {  // nothing bounded here (a body at rest in still water): rate 0
      sums_.jacobian[i] = !bounded;
      return;
    }
    const double rate = std::max(b[0] / h.mass_with_added, b[1] / h.inertia_with_added);
    sums_.jacobian[i] = !bounded || (h.moves && dt_ * rate * (1.0 + 1e-6) > kExplicitLimit);
  };
  if (sparse) {
    const std::span<const std::int32_t> moving = sums_.stirred;
    thread_pool().for_blocks(moving.size(), 8192, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) needs_jacobian(static_cast<std::size_t>(moving[k]));
    });
  } else {
    thread_pool().for_blocks(hot_.size(), 8192, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) needs_jacobian(i);
    });
    std::fill(sums_.q.begin(), sums_.q.end(), std::array<double, 3>{});
    if (sums_.any_jacobian) std::fill(sums_.dq.begin(), sums_.dq.end(), std::array<double, 9>{});
  }
}

void Forcing::load_body(std::size_t i, const BodyStates& state, bool first_step) {
  const BodyHot& h = hot_[i];
  ahead_[i] = {};
  if (!h.moves) {
    loads_.force[i] = {};
    loads_.torque[i] = 0.0;
    return;
  }
  const double mi = h.mass_with_added;
  const double ii = h.inertia_with_added;
  const std::array<double, 3>& q = sums_.q[i];
  std::array<double, 3> dv;
  // The step's length and whether it is implicit (the comment at the top).
  const bool free = free_body(i);
  const double step = free && first_step ? 0.5 * dt_ : dt_;
  const bool implicit = sums_.any_jacobian && step * drag_rate(sums_.dq[i], mi, ii) > kExplicitLimit;
  // A body no term pushed (Q = +0), explicit, that Coriolis cannot turn (at rest, or no
  // rotation) gets no load: the paths below give +0 to the bit (rhs = +0 whatever the sign
  // of a zero velocity), here without their divisions (the rotation rate's too, when the
  // body is at rest). Most floes of the towing case.
  const bool unpushed = !implicit && plus_zero(q[0]) && plus_zero(q[1]) && plus_zero(q[2]);
  if (unpushed && state.velocity[i].x == 0.0 && state.velocity[i].y == 0.0) {
    loads_.force[i] = {};
    loads_.torque[i] = 0.0;
    return;
  }
  const double f = sums_.any_rotation ? sums_.rotation_rate[i] * h.mass / mi : 0.0;
  if (unpushed && f == 0.0) {
    loads_.force[i] = {};
    loads_.torque[i] = 0.0;
    return;
  }
  if (!implicit && f == 0.0) {
    dv = {step * q[0] / mi, step * q[1] / mi, step * q[2] / ii};
  } else {
    // f~ = (2 / h) tan(angle / 2), so that the Cayley turn is exactly the angle; tan is
    // cached per body (the rate rarely changes).
    if (f != cached_rate_[i]) {
      cached_rate_[i] = f;
      cached_tan_[i] = std::tan(0.5 * f * dt_);
      cached_half_tan_[i] = std::tan(0.25 * f * dt_);
    }
    const double ft = (2.0 / step) * (first_step ? cached_half_tan_[i] : cached_tan_[i]);
    const double cv = mi * ft;  // C = cv [[0, -1], [1, 0]] on v
    const Vec2 v = state.velocity[i];
    const std::array<double, 3> rhs{q[0] + cv * v.y, q[1] - cv * v.x, q[2]};
    if (!implicit) {
      // [[M, -c], [c, M]] dv = rhs with M = m_I / h, c = cv / 2: closed form.
      const double m = mi / step, c = 0.5 * cv;
      const double det = m * m + c * c;
      dv = {(m * rhs[0] + c * rhs[1]) / det, (m * rhs[1] - c * rhs[0]) / det, step * q[2] / ii};
    } else {
      std::array<double, 9> a = sums_.dq[i];
      for (double& x : a) x = -x;
      a[0] += mi / step;
      a[4] += mi / step;
      a[8] += ii / step;
      a[1] += -0.5 * cv;
      a[3] += 0.5 * cv;
      dv = solve3(a, rhs);
    }
  }
  if (free && !implicit) ahead_[i] = {dv[0] / step, dv[1] / step, dv[2] / step};
  loads_.force[i] = {h.engine_mass * dv[0] / dt_, h.engine_mass * dv[1] / dt_};
  loads_.torque[i] = h.engine_inertia * dv[2] / dt_;
}

void Forcing::velocities_at_step_end(std::span<Vec2> v, std::span<double> w) const {
  // v_n+1 ~ v(t_n+1 - dt/2) (the comment at the top), and ahead_ holds the step's mean
  // acceleration a_n = (q_n+1 - q_n) / h, a(t_n) to first order: v(t_n+1) = v_n+1 + (dt/2) a_n
  // + O(dt^2). A scene of Coriolis alone turns its velocities exactly: half the step's turn.
  if (rotation_only_) {
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = turn_first_[i].apply(v[i]);
    return;
  }
  if (!any_ahead_) return;
  const double half = 0.5 * dt_;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::array<double, 3>& a = ahead_[i];
    v[i] += half * Vec2{a[0], a[1]};
    w[i] += half * a[2];
  }
}

void Forcing::note_ahead() {
  any_ahead_ = std::any_of(ahead_.begin(), ahead_.end(), [](const std::array<double, 3>& a) {
    return a[0] != 0.0 || a[1] != 0.0 || a[2] != 0.0;
  });
}

void Forcing::save(StateWriter& out) const {
  out.tag("forcing");
  out.vector(ahead_);
}

void Forcing::restore(StateReader& in) {
  in.tag("forcing");
  in.vector(ahead_, hot_.size(), "forcing: accelerations");
  note_ahead();
}

}  // namespace floedem
