#include "solver/contact_solver.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "engine/prefetch.hpp"
#include "parallel/thread_pool.hpp"
#include "solver/coloured_sweeps.hpp"
#include "solver/headroom.hpp"
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
// a step against 21). It costs a pass over the moving points per sweep (the 4k field at 10
// sweeps: +6 %), which the extra sweeps alone do not replace: a row of 50 floes at dt 0.01 s
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
    return solve_coloured(manifolds, {}, s, limits, space, options.warm_start, options.accelerate, options.threads,
                          options.given_order);
  return solve_rows(AllRows{manifolds}, s, limits, space, options);
}

int solve_velocities(std::span<Manifold> manifolds, std::span<const std::int32_t> island, BodyArrays& s,
                     const SweepLimits& limits, SweepSpace space, SweepOptions options) {
  if (options.colour)
    return solve_coloured(manifolds, island, s, limits, space, options.warm_start, options.accelerate,
                          options.threads, options.given_order);
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

double solve_positions(std::span<const Manifold> manifolds, BodyArrays& s, const NativeSettings& settings,
                       ProjectionWork& work) {
  // A manifold whose two bodies kept their poses, to the bit, since its gaps were last measured
  // has the same gaps again, so it corrects nothing (had it corrected, its bodies would have
  // moved) and its deepest gap is the one measured then: it is left as it was. Only the first
  // sweep measures every manifold; a later one measures those near what the sweeps before it
  // moved (in a packed field, the few deep contacts and their neighbours). The same positions
  // and the same deepest overlap, to the bit, as measuring every manifold in every sweep.
  //
  // The later sweeps find those manifolds without a pass over all of them (at 10^5 floes each
  // such pass read every manifold's bodies, out of cache, for a few hundred measured): a body
  // that moves marks its manifolds stale (a bit each), and a sweep measures the stale ones in
  // ascending order, marks set ahead of it this sweep, those behind it the next; a manifold's
  // mark is cleared as it is measured, and set again if it moves its own bodies. That is the
  // set of manifolds, in the same order, that the clocks (moved against evaluated) pick.
  const std::size_t bodies = s.position.size();
  const std::size_t nm = manifolds.size();
  if (work.moved.size() != bodies) work.moved.assign(bodies, 0);
  resize_with_headroom(work.evaluated, nm);
  resize_with_headroom(work.depth, nm);
  reserve_with_headroom(work.moved_bodies, bodies);
  work.moved_bodies.clear();
  const std::uint64_t start = work.clock;
  bool marking = false;  // after the first sweep: moves mark their manifolds stale
  auto mark = [&](int body) {
    const auto b = static_cast<std::size_t>(body);
    for (std::int32_t k = work.body_first[b]; k < work.body_first[b + 1]; ++k) {
      const auto i = static_cast<std::size_t>(work.body_manifolds[static_cast<std::size_t>(k)]);
      work.stale[i / 64] |= std::uint64_t{1} << (i % 64);
    }
  };
  // A pose written back with other bits (however small the change) makes the body moved.
  auto move = [&](int body, Vec2 position, double angle) {
    if (same_bits(position.x, s.position[body].x) && same_bits(position.y, s.position[body].y) &&
        same_bits(angle, s.angle[body]))
      return;
    s.position[body] = position;
    s.angle[body] = angle;
    s.rotation[body] = Rot::from_angle(angle);
    if (marking)
      mark(body);
    else if (work.moved[static_cast<std::size_t>(body)] <= start)
      work.moved_bodies.push_back(body);  // its first move in this call
    work.moved[static_cast<std::size_t>(body)] = work.clock;
  };
  // Point k's gap at the current poses, from the material points that made the contact: the
  // reference face's normal n_ref and point, and the incident point q; gap = (q - face).n_ref.
  struct PointGap {
    Vec2 n_ref, q;
    double gap;
  };
  auto point_gap = [&](const Manifold& m, int k) {
    const int ref = m.reference_is_b ? m.body_b : m.body_a;
    const int inc = m.reference_is_b ? m.body_a : m.body_b;
    const Vec2 n_ref = s.rotation[ref].apply(m.local_normal);
    const Vec2 face = s.position[ref] + s.rotation[ref].apply(m.local_face_point);
    const Vec2 q = s.position[inc] + s.rotation[inc].apply(m.points[k].local_incident);
    return PointGap{n_ref, q, dot(q - face, n_ref)};
  };
  // C = beta (gap + slop), clamped to [-max_correction, 0]: a point corrects where C < 0.
  auto correction = [&](double gap) {
    return std::clamp(settings.position_correction * (gap + settings.allowed_penetration), -settings.max_correction,
                      0.0);
  };
  // Measures manifold i's gaps and corrects them; returns its deepest gap.
  auto measure = [&](std::size_t i) {
    const Manifold& m = manifolds[i];
    const int a = m.body_a, b = m.body_b;
    work.evaluated[i] = ++work.clock;
    double depth = 0.0;
    const double ma = s.inv_mass[a], mb = s.inv_mass[b];
    const double ia = s.inv_inertia[a], ib = s.inv_inertia[b];
    for (int k = 0; k < m.point_count; ++k) {
      const auto [n_ref, q, gap] = point_gap(m, k);
      depth = std::max(depth, -gap);
      // Solve K dlambda = -C with K = n.M^-1 n at the current configuration, and move
      // positions only.
      const double c = correction(gap);
      if (c >= 0.0) continue;
      const Vec2 n = m.reference_is_b ? -n_ref : n_ref;
      const Vec2 point = q - 0.5 * gap * n_ref;
      const Vec2 ra = point - s.position[a];
      const Vec2 rb = point - s.position[b];
      const double rna = cross(ra, n), rnb = cross(rb, n);
      const double k_eff = ma + mb + ia * rna * rna + ib * rnb * rnb;
      if (k_eff == 0.0) continue;  // two sleeping bodies, or a sleeping and a fixed one: held as they are
      const Vec2 impulse = (-c / k_eff) * n;
      move(a, s.position[a] - ma * impulse, s.angle[a] - ia * cross(ra, impulse));
      move(b, s.position[b] + mb * impulse, s.angle[b] + ib * cross(rb, impulse));
    }
    work.depth[i] = depth;
    return depth;
  };
  if (settings.position_iterations <= 0) return 0.0;
  // The first sweep: every manifold. Its gaps are measured over the threads first, at the poses
  // the sweep starts from, with each manifold's two bodies noted (for the lists below, which
  // then need not read the manifolds again) and whether any point would correct. The sweep
  // proper then goes in order and measures again only a manifold that corrects or whose bodies
  // an earlier one moved; any other's gaps are those measured (same poses, same expressions,
  // same bits), and it moves nothing. So the poses and depths are those of measuring every
  // manifold in turn, on any thread count; in a settled field few manifolds correct, and the
  // sweep's cost (reading every manifold and its bodies' poses) is shared by the threads.
  resize_with_headroom(work.ends, 2 * nm);
  resize_with_headroom(work.corrects, nm);
  thread_pool().for_blocks(nm, 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      // The manifold four on, every line of it asked for ahead: this pass reads the first line,
      // each point's and the reference face's (the last), out of cache at 16k floes, and its
      // hottest load waited on the last line (perf). A prefetch changes no value.
      if (i + 4 < end) prefetch_lines(&manifolds[i + 4], sizeof(Manifold));
      const Manifold& m = manifolds[i];
      work.ends[2 * i] = m.body_a;
      work.ends[2 * i + 1] = m.body_b;
      double depth = 0.0;
      bool corrects = false;
      for (int k = 0; k < m.point_count; ++k) {
        const double gap = point_gap(m, k).gap;
        depth = std::max(depth, -gap);
        corrects = corrects || correction(gap) < 0.0;
      }
      work.depth[i] = depth;
      work.corrects[i] = corrects;
    }
  });
  double deepest = 0.0;
  for (std::size_t i = 0; i < nm; ++i) {
    const auto a = static_cast<std::size_t>(work.ends[2 * i]), b = static_cast<std::size_t>(work.ends[2 * i + 1]);
    if (work.corrects[i] || work.moved[a] > start || work.moved[b] > start) {
      deepest = std::max(deepest, measure(i));
    } else {
      work.evaluated[i] = ++work.clock;  // as measure() would stamp it
      deepest = std::max(deepest, work.depth[i]);
    }
  }
  if (settings.position_iterations == 1 || deepest <= 1.5 * settings.allowed_penetration) return deepest;

  // Each body's manifolds (counting sort), then the manifolds stale after the first sweep: those
  // with a body it moved at or after their measurement (moved >= evaluated, as the clocks say).
  work.body_first.assign(bodies + 1, 0);
  for (std::size_t e = 0; e < 2 * nm; ++e) ++work.body_first[static_cast<std::size_t>(work.ends[e]) + 1];
  for (std::size_t b = 0; b < bodies; ++b) work.body_first[b + 1] += work.body_first[b];
  resize_with_headroom(work.body_manifolds, 2 * nm);
  for (std::size_t e = 0; e < 2 * nm; ++e)
    work.body_manifolds[static_cast<std::size_t>(work.body_first[static_cast<std::size_t>(work.ends[e])]++)] =
        static_cast<std::int32_t>(e / 2);
  for (std::size_t b = bodies; b > 0; --b) work.body_first[b] = work.body_first[b - 1];  // back to the starts
  work.body_first[0] = 0;
  const std::size_t words = (nm + 63) / 64;
  resize_with_headroom(work.stale, words);
  std::fill(work.stale.begin(), work.stale.begin() + static_cast<std::ptrdiff_t>(words), 0);
  for (const std::int32_t body : work.moved_bodies) {
    const auto b = static_cast<std::size_t>(body);
    for (std::int32_t k = work.body_first[b]; k < work.body_first[b + 1]; ++k) {
      const auto i = static_cast<std::size_t>(work.body_manifolds[static_cast<std::size_t>(k)]);
      if (work.moved[b] >= work.evaluated[i]) work.stale[i / 64] |= std::uint64_t{1} << (i % 64);
    }
  }
  marking = true;
  for (int iteration = 1; iteration < settings.position_iterations; ++iteration) {
    for (std::size_t w = 0; w < words; ++w) {
      // The word is read again after each measure: marks set in it ahead of the one measured
      // are this sweep's; those behind it wait for the next.
      std::uint64_t ahead = ~std::uint64_t{0};
      while (const std::uint64_t bits = work.stale[w] & ahead) {
        const int j = std::countr_zero(bits);
        const std::uint64_t bit = std::uint64_t{1} << j;
        work.stale[w] &= ~bit;
        ahead = j == 63 ? 0 : ~std::uint64_t{0} << (j + 1);
        measure(64 * w + static_cast<std::size_t>(j));
      }
    }
    // The deepest gap of every manifold: those not measured keep theirs (max is exact in any order).
    deepest = 0.0;
    for (std::size_t i = 0; i < nm; ++i) deepest = std::max(deepest, work.depth[i]);
    if (deepest <= 1.5 * settings.allowed_penetration) break;
  }
  return deepest;
}

}  // namespace floedem
