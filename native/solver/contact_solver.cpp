#include "solver/contact_solver.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "engine/prefetch.hpp"
#include "parallel/thread_pool.hpp"
#include "solver/coloured_sweeps.hpp"
#include "engine/headroom.hpp"
#include "solver/local_law.hpp"
#include "solver/sweep_row.hpp"
#include "solver/sweep_schedule.hpp"

// Contact constraint, per point, between bodies a and b (normal n from a to b, tangent t = k x n):
//
//   relative velocity   u = (v_b + w_b k x r_b) - (v_a + w_a k x r_a),  u_n = u.n, u_t = u.t
//   Jacobian (normal)   J_n = [-n, -(r_a x n), n, (r_b x n)]  (same with t for friction)
//   impulse             P = P_n n + P_t t on b, -P on a
//   Delassus block      W = J M^-1 J^T:
//       W_nn = 1/m_a + 1/m_b + (r_a x n)^2 / I_a + (r_b x n)^2 / I_b
//       W_tt = 1/m_a + 1/m_b + (r_a x t)^2 / I_a + (r_b x t)^2 / I_b
//       W_nt = (r_a x n)(r_a x t) / I_a + (r_b x n)(r_b x t) / I_b
//   so that u+ = u_free + W (P_n, P_t). The effective mass along n is 1 / W_nn.
//
// Conditions (Moreau 1988; Jean 1999, "The non-smooth contact dynamics method"; Glocker and
// Pfeiffer 1995 for the impact law with friction in the plane):
//   normal:   P_n >= 0,  u_n+ - u* >= 0,  P_n (u_n+ - u*) = 0,
//             u* = -e u_n-  for a collision (Newton's law on the approach velocity u_n- before
//             the step), u* = -max(gap, 0)/dt for a resting contact (no bounce; closes a
//             speculative gap exactly, never further);
//   friction: |P_t| <= mu P_n; |P_t| < mu P_n => u_t+ = 0; u_t+ != 0 => P_t = -mu P_n sign(u_t+).
// solve_single_contact() solves this 2x2 problem exactly by enumerating its cases (separate,
// stick, slide either way); Gauss-Seidel over the points then converges to the multi-contact
// solution (Jean's NSCD / Catto's sequential impulses with a block-exact local solver).

namespace floedem {

LocalImpulse solve_single_contact(double ufn, double uft, double target, double mu, double wnn, double wnt,
                                  double wtt) {
  LocalImpulse r;
  local_law<ScalarOps>(ufn, uft, target, mu, wnn, wnt, wtt, r.normal, r.tangent);
  return r;
}

void prepare_contact(Manifold& m, const BodyArrays& s, double dt, double collision_threshold, const Manifold* held) {
  const int a = m.body_a, b = m.body_b;
  const Vec2 n = m.normal;
  const double ma = s.inv_mass[a], mb = s.inv_mass[b];
  const double ia = s.inv_inertia[a], ib = s.inv_inertia[b];
  for (int k = 0; k < m.point_count; ++k) {
    ManifoldPoint& p = m.points[k];
    p.ra = p.point - s.position[a];
    p.rb = p.point - s.position[b];
    const DelassusBlock<double> w = delassus_block(ma, ia, mb, ib, p.ra.x, p.ra.y, p.rb.x, p.rb.y, n.x, n.y);
    p.wnn = w.wnn;
    p.wnt = w.wnt;
    p.wtt = w.wtt;
    p.approach_velocity = dot(relative_velocity(s, a, b, p.ra, p.rb), n);
    // Found again in a redetection, the velocities are those after the loads: a floe pressed on
    // a wall by its load approaches it at F dt / m there, and would be taken for a collision.
    for (int j = 0; held && j < held->point_count; ++j)
      if (held->points[j].id == p.id) p.approach_velocity = held->points[j].approach_velocity;
    const double gap = std::max(p.separation, 0.0);
    // A collision: a new contact, approaching faster than the threshold, reached within the
    // step. A point that was pressed last step is resting whatever its approach speed: bodies
    // already in contact do not collide, and their approach speed is solver residual (in a
    // pressed pack, classifying it as a collision would make the pack bounce in place).
    if (!p.persistent && p.approach_velocity < -collision_threshold && gap + dt * p.approach_velocity < 0.0) {
      p.kind = ContactKind::collision;
      // Newton's law; with e = 0 the bodies still close a speculative gap exactly.
      p.target_velocity = std::max(-m.restitution * p.approach_velocity, -gap / dt);
      p.normal_impulse = p.tangent_impulse = 0.0;
    } else {
      p.kind = ContactKind::resting;
      p.target_velocity = -gap / dt;
    }
  }
}

void apply_accumulated_impulses(std::span<const Manifold> manifolds, BodyArrays& s, double sign) {
  for (const Manifold& m : manifolds) {
    const Vec2 t = perp(m.normal);
    for (int k = 0; k < m.point_count; ++k) {
      const ManifoldPoint& p = m.points[k];
      if (p.normal_impulse != 0.0 || p.tangent_impulse != 0.0)
        apply_impulse(s, m, p, sign * (p.normal_impulse * m.normal + p.tangent_impulse * t));
    }
  }
}

// Extra sweeps: a sweep limit alone leaves a pressed pack closing at whatever speed the last
// sweep left (the jam at dt 0.5 s: 0.04 m/s, 20 mm a step, more than the position projection
// takes back). Past `iterations`, the sweeps go on while a point approaches faster than its
// target by more than `closing_speed` (the engine's: allowed_penetration / dt, the overlap the
// step may add), looked at every SweepLimits::check_every sweeps, up to `extra_iterations` more;
// once a pack holds, the warm start keeps it within the ordinary limit. SweepSchedule
// (sweep_schedule.hpp) holds these rules and the step's below, for both sweep orders.
//
// Acceleration (Silcowitz, Niebe and Erleben 2010, "A nonsmooth nonlinear conjugate gradient
// method for interactive contact force problems", The Visual Computer 26(6-8), alg. 2): a sweep
// is x_{k+1} = PGS(x_k); its change r_{k+1} = x_{k+1} - x_k is minus the gradient of the
// nonsmooth merit function, and the Fletcher-Reeves step
//
//   beta = |r_{k+1}|^2 / |r_k|^2,   x_{k+1} += beta p_k,   p_{k+1} = beta p_k + r_{k+1}
//
// follows (p_1 = r_1; beta > 1, the merit not falling, restarts with p = 0). Gauss-Seidel hands a
// load on by one contact per sweep, so a pressed pack N floes deep needs of order N^2 sweeps;
// the conjugate directions carry it across in of order N (a row of 50 pressed floes: 9.4 sweeps
// a step against 21). It costs a pass over the moving points per sweep, which the extra
// sweeps alone do not replace: a row of 50 floes at dt 0.01 s
// creeps into its wall at 1.5 cm/s under 50 plain sweeps, each step's closing far below the
// allowed overlap, and piles 10 mm of overlap. The sweep's local solve removes a point's own
// impulse before solving it, so an iterate the step left outside the cone (P_n < 0 or
// |P_t| > mu P_n) is brought back by the next sweep; the solve always ends on a sweep, never on
// a step, so its impulses keep their laws.
namespace {

// The manifolds a solve runs over: all of a span, or an island's (indices into it, in order).
struct AllRows {
  std::span<Manifold> m;
  std::size_t size() const { return m.size(); }
  Manifold& operator[](std::size_t i) const { return m[i]; }
};
struct IslandRows {
  std::span<Manifold> m;
  std::span<const std::int32_t> index;
  std::size_t size() const { return index.size(); }
  Manifold& operator[](std::size_t i) const { return m[static_cast<std::size_t>(index[i])]; }
};


// The manifolds' points as rows, in sweep order; with the warm start, each point's accumulated
// impulse applied as it is copied (apply_accumulated_impulses' order and arithmetic).
template <class Rows>
std::size_t gather_rows(const Rows& manifolds, BodyArrays& s, bool warm_start, std::span<SweepRow> rows) {
  std::size_t x = 0;
  for (std::size_t mi = 0; mi < manifolds.size(); ++mi) {
    const Manifold& m = manifolds[mi];
    const Vec2 t = perp(m.normal);
    for (int k = 0; k < m.point_count; ++k) {
      const ManifoldPoint& p = m.points[k];
      rows[x++] = {m.body_a, m.body_b, m.normal, p.ra, p.rb, p.wnn, p.wnt, p.wtt, p.target_velocity, m.friction,
                   p.normal_impulse, p.tangent_impulse};
      if (warm_start && (p.normal_impulse != 0.0 || p.tangent_impulse != 0.0))
        apply_impulse(s, m, p, 1.0 * (p.normal_impulse * m.normal + p.tangent_impulse * t));
    }
  }
  return x;
}

// The rows' impulses back into their manifolds' points.
template <class Rows>
void scatter_rows(const Rows& manifolds, std::span<const SweepRow> rows) {
  std::size_t x = 0;
  for (std::size_t mi = 0; mi < manifolds.size(); ++mi) {
    Manifold& m = manifolds[mi];
    for (int k = 0; k < m.point_count; ++k, ++x) {
      m.points[k].normal_impulse = rows[x].normal_impulse;
      m.points[k].tangent_impulse = rows[x].tangent_impulse;
    }
  }
}

int run_sweeps(std::span<SweepRow> rows, BodyArrays& s, const SweepLimits& limits, SweepSpace work,
               bool accelerate) {
  if (accelerate) {
    work.change = work.change.first(2 * rows.size());
    work.direction = work.direction.first(2 * rows.size());
    work.step = work.step.first(2 * rows.size());
    std::fill(work.change.begin(), work.change.end(), 0.0);
    std::fill(work.direction.begin(), work.direction.end(), 0.0);
  }
  SweepSchedule schedule(limits);
  while (schedule.next()) {
    double largest_change = 0.0;
    double largest_impulse = 0.0;
    double size = 0.0;  // |r_{k+1}|^2
    for (std::size_t i = 0; i < rows.size(); ++i) {
      SweepRow& p = rows[i];
      const RowChange d = sweep_row(p, s);
      const double dpn = d.normal, dpt = d.tangent;
      largest_change = std::max(largest_change, std::abs(dpn) + std::abs(dpt));
      largest_impulse = std::max(largest_impulse, p.normal_impulse + std::abs(p.tangent_impulse));
      if (accelerate) {
        work.change[2 * i] = dpn;
        work.change[2 * i + 1] = dpt;
        size += dpn * dpn + dpt * dpt;
      }
    }
    if (schedule.done(largest_change, largest_impulse, [&] { return largest_shortfall_of(rows, s); })) break;
    if (!accelerate || schedule.last()) continue;
    const std::span<double> p = work.direction;
    const std::span<const double> r = work.change;
    const ConjugateStep c = schedule.conjugate_step(size);
    if (c.kind == ConjugateStep::Kind::restart) {
      std::fill(p.begin(), p.end(), 0.0);
    } else {
      const double beta = c.beta;  // 0 at the start: p = r, no step
      // Over the dense arrays, in two passes: the step beta p and the new direction (a loop
      // the compiler vectorises), then the step applied where it is not zero: a point that
      // neither moved nor carries a direction (a speculative contact kept apart) costs no look
      // at its row.
      const std::span<double> step = work.step;
      for (std::size_t i = 0; i < p.size(); ++i) {
        step[i] = beta * p[i];
        p[i] = step[i] + r[i];
      }
      for (std::size_t i = 0; i < p.size(); i += 2) {
        const double sn = step[i], st = step[i + 1];
        if (sn == 0.0 && st == 0.0) continue;
        SweepRow& q = rows[i / 2];
        apply_row_impulse(s, q, sn * q.normal + st * perp(q.normal));
        q.normal_impulse += sn;
        q.tangent_impulse += st;
      }
    }
  }
  return schedule.sweeps();
}

template <class Rows>
int solve_rows(const Rows& manifolds, BodyArrays& s, const SweepLimits& limits, SweepSpace space,
               SweepOptions options) {
  if (space.rows.size() < 2 * manifolds.size() || (options.accelerate && space.change.size() < 4 * manifolds.size()))
    throw std::logic_error("solve_velocities: the sweep space holds fewer manifolds than the solve");
  const std::span<SweepRow> rows = space.rows.first(gather_rows(manifolds, s, options.warm_start, space.rows));
  const int sweeps = run_sweeps(rows, s, limits, space, options.accelerate);
  scatter_rows(manifolds, rows);
  return sweeps;
}

}  // namespace

double largest_shortfall(std::span<const Manifold> manifolds, const BodyArrays& s) {
  double worst = 0.0;
  for (const Manifold& m : manifolds) {
    for (int k = 0; k < m.point_count; ++k) {
      const ManifoldPoint& p = m.points[k];
      worst = std::max(worst, p.target_velocity - dot(relative_velocity(s, m.body_a, m.body_b, p.ra, p.rb), m.normal));
    }
  }
  return worst;
}

void SweepWork::reserve(std::size_t manifolds, bool accelerate, std::size_t colour_bodies, std::size_t bundles) {
  // Half as many again when it grows: no allocation each time a pack gains a contact.
  auto grow = [](auto& v, std::size_t n) {
    if (v.size() < n) v.resize(n + n / 2);
  };
  grow(rows_, 2 * manifolds);
  if (accelerate) {
    grow(change_, 4 * manifolds);
    grow(direction_, 4 * manifolds);
    grow(step_, 4 * manifolds);
  }
  if (colour_bodies > 0) {
    grow(bundles_, bundles);
    if (accelerate) {
      grow(bundle_change_, kBundleNncg * bundles);
      grow(bundle_direction_, kBundleNncg * bundles);
      grow(moving_bodies_, 2 * manifolds);
      if (body_steps_.size() < colour_bodies) body_steps_.resize(colour_bodies);
    }
    grow(overflow_, manifolds);
    if (body_colours_.size() < colour_bodies) body_colours_.resize(colour_bodies, 0);  // zero, and kept zero by each solve
  }
}

SweepSpace SweepWork::slice(std::size_t first, std::size_t count, std::size_t bundle_first, std::size_t bundle_count) {
  auto part = [](auto& v, std::size_t at, std::size_t n) {
    using T = typename std::remove_reference_t<decltype(v)>::value_type;
    return v.size() >= at + n ? std::span<T>(v).subspan(at, n) : std::span<T>();
  };
  return {part(rows_, 2 * first, 2 * count),
          part(change_, 4 * first, 4 * count),
          part(direction_, 4 * first, 4 * count),
          part(step_, 4 * first, 4 * count),
          part(bundles_, bundle_first, bundle_count),
          part(overflow_, first, count),
          std::span<std::uint64_t>(body_colours_),
          part(bundle_change_, kBundleNncg * bundle_first, kBundleNncg * bundle_count),
          part(bundle_direction_, kBundleNncg * bundle_first, kBundleNncg * bundle_count),
          part(moving_bodies_, 2 * first, 2 * count),
          std::span<BodyStep>(body_steps_)};
}

int solve_velocities(std::span<Manifold> manifolds, BodyArrays& s, const SweepLimits& limits, SweepSpace space,
                     SweepOptions options) {
  if (options.colour)
    return solve_coloured(manifolds, {}, s, limits, space, options);
  return solve_rows(AllRows{manifolds}, s, limits, space, options);
}

int solve_velocities(std::span<Manifold> manifolds, std::span<const std::int32_t> island, BodyArrays& s,
                     const SweepLimits& limits, SweepSpace space, SweepOptions options) {
  if (options.colour)
    return solve_coloured(manifolds, island, s, limits, space, options);
  return solve_rows(IslandRows{manifolds, island}, s, limits, space, options);
}

int clamp_friction(std::span<Manifold> manifolds, BodyArrays& s) {
  int cut = 0;
  for (Manifold& m : manifolds) {
    const Vec2 t = perp(m.normal);
    for (int k = 0; k < m.point_count; ++k) {
      ManifoldPoint& p = m.points[k];
      const double limit = m.friction * p.normal_impulse;
      const double pt = std::clamp(p.tangent_impulse, -limit, limit);
      if (pt == p.tangent_impulse) continue;
      apply_impulse(s, m, p, (pt - p.tangent_impulse) * t);
      p.tangent_impulse = pt;
      ++cut;
    }
  }
  return cut;
}

}  // namespace floedem
