#include "solver/island_stage.hpp"

#include <algorithm>
#include <limits>

#include "engine/headroom.hpp"
#include "parallel/thread_pool.hpp"
#include "solver/coloured_sweeps.hpp"
#include "solver/contact_solver.hpp"

namespace floedem {

namespace {

// m |v|^2 + I w^2 of moving body i: twice its kinetic energy, enough to compare before and after.
double twice_kinetic_energy(const BodyArrays& s, std::size_t i) {
  return length_squared(s.velocity[i]) / s.inv_mass[i] + s.angular_velocity[i] * s.angular_velocity[i] / s.inv_inertia[i];
}

double kinetic_energy_of(const BodyArrays& s, std::span<const std::int32_t> bodies) {
  double e = 0.0;
  for (const std::int32_t i : bodies) e += twice_kinetic_energy(s, static_cast<std::size_t>(i));
  return e;
}

// Twice the kinetic energy of every moving body.
double contact_kinetic_energy(const BodyArrays& s) {
  double e = 0.0;
  const std::size_t nb = s.position.size();
  for (std::size_t i = 0; i < nb; ++i)
    if (s.inv_mass[i] != 0.0) e += twice_kinetic_energy(s, i);
  return e;
}

// Work of the contact impulses of bodies on a prescribed path on the bodies they touch (fixed
// bodies do none: their points do not move).
double kinematic_work(const BodyArrays& s, const Manifold& m) {
  const bool a_kinematic = s.inv_mass[m.body_a] == 0.0, b_kinematic = s.inv_mass[m.body_b] == 0.0;
  if (!a_kinematic && !b_kinematic) return 0.0;
  double w = 0.0;
  const Vec2 t = perp(m.normal);
  for (int k = 0; k < m.point_count; ++k) {
    const ManifoldPoint& p = m.points[k];
    const Vec2 impulse_on_b = p.normal_impulse * m.normal + p.tangent_impulse * t;
    if (a_kinematic) w += dot(impulse_on_b, s.velocity[m.body_a] + cross(s.angular_velocity[m.body_a], p.ra));
    if (b_kinematic) w -= dot(impulse_on_b, s.velocity[m.body_b] + cross(s.angular_velocity[m.body_b], p.rb));
  }
  return w;
}

double kinematic_work(const BodyArrays& s, std::span<const Manifold> manifolds) {
  double w = 0.0;
  for (const Manifold& m : manifolds) w += kinematic_work(s, m);
  return w;
}

// A body moved on a prescribed path (towing at constant speed) does work on the floes it
// pushes: W = sum over its contact points of p . u_k, p the impulse on the floe and u_k the
// velocity of the towed body's point there. For one contact with target -e u_r, the floe's
// change of kinetic energy is W + lambda u_r (1 - e) / 2 <= W (lambda >= 0 the impulse,
// u_r < 0 the approach speed); so the test is Delta KE <= W, which is Delta KE <= 0 where
// nothing moves on a path (the floes' energy gain from the iceberg is real, not the warm
// start's: without W nearly every towing step was solved twice).
bool contacts_gain_energy(const StepContext& ctx, std::span<const Manifold> manifolds, double before) {
  return contact_kinetic_energy(ctx.bodies) - (ctx.has_prescribed ? 2.0 * kinematic_work(ctx.bodies, manifolds) : 0.0) >
         before;
}

}  // namespace

IslandStage::IslandStage(const Scene& scene, const StepContext& ctx) {
  double lightest = std::numeric_limits<double>::infinity(), heaviest = 0.0;  // moving bodies, kg
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].fixed || scene.bodies[i].prescribed) continue;
    heaviest = std::max(heaviest, scene.engine_mass(i));
    lightest = std::min(lightest, scene.engine_mass(i));
  }
  heavy_light_ = ctx.settings.direct_solve && heaviest >= ctx.settings.direct_solve_mass_ratio * lightest;
}

void IslandStage::restore_counts(std::int64_t sweeps, std::int64_t islands, std::int64_t cold, std::int64_t direct,
                                 std::int64_t reverted) {
  total_sweeps_ = sweeps;
  total_islands_ = islands;
  cold_restarts_ = cold;
  direct_solves_ = direct;
  direct_reverted_ = reverted;
}

void IslandStage::solve(StepContext& ctx, std::span<Manifold> manifolds, std::span<const std::uint8_t> resolve) {
  // Islands (contact_islands.hpp) share no moving body, so each is solved apart: its sweeps
  // stop when its own impulses have converged (or its limits are spent), and its energy is
  // checked on its own. One island's hard case (the pile ahead of a towed iceberg, a pressed
  // chain) no longer keeps every other contact of the scene sweeping, and an island that made
  // energy is solved again without touching the rest. A scene that is one island is solved
  // exactly as one solve over all its manifolds.
  const NativeSettings& settings = ctx.settings;
  const bool checked = settings.warm_start || settings.accelerate;
  const double before = heavy_light_ ? contact_kinetic_energy(ctx.bodies) : 0.0;
  islands_.build(manifolds, ctx.bodies);
  // Blocks of islands on the pool's threads: an island touches only its own manifolds and
  // moving bodies (the velocity of a fixed or prescribed body is never written, see
  // apply_impulse), and each is solved the same way on any thread, so the result does not
  // depend on the thread count.
  const std::size_t n = islands_.size();
  // A redetection solves only the islands it marked (redetection.cpp); an island is marked whole.
  const bool partial = !resolve.empty();
  auto kept = [&](std::size_t i) { return partial && !resolve[islands_.bodies(i)[0]]; };
  const std::size_t blocks = std::max<std::size_t>(1, (n + kIslandGrain - 1) / kIslandGrain);
  if (island_work_.size() < blocks) island_work_.resize(blocks + blocks / 2);
  bool any_coloured = false;
  for (std::size_t i = 0; i < n && !any_coloured; ++i) any_coloured = coloured(ctx, i);
  const std::size_t colour_bodies = any_coloured ? ctx.bodies.inv_mass.size() : 0;
  sweep_work_.reserve(manifolds.size(), settings.accelerate, colour_bodies);
  if (any_coloured) {
    // The islands coloured first, so that each island's bundles get a slice of exactly their
    // number (a bound per island, bundles_for, came to a bundle a manifold for the many small
    // islands: a 768-byte bundle each, and a total that grew as the pack broke up and closed again).
    resize_with_headroom(island_bundles_, n + 1);
    island_bundles_[0] = 0;
    for (std::size_t i = 0; i < n; ++i) {
      island_bundles_[i + 1] = island_bundles_[i];
      if (!coloured(ctx, i) || kept(i)) continue;
      const SweepSpace space = sweep_work_.slice(islands_.manifold_offset(i), islands_.manifolds(i).size());
      island_bundles_[i + 1] += colour_manifolds(manifolds, islands_.manifolds(i), ctx.bodies, space.overflow,
                                                 space.body_colours);
    }
    sweep_work_.reserve(manifolds.size(), settings.accelerate, colour_bodies, island_bundles_[n]);
  }
  if (checked) {
    resize_with_headroom(island_velocity_, islands_.body_count());
    resize_with_headroom(island_angular_velocity_, islands_.body_count());
  }
  for (IslandWork& w : island_work_) {
    w.longest = w.cold_restarts = 0;
    w.out_of_sweeps = false;
  }
  // A large island swept in colour order (the packed field's one large island) is left out of
  // the blocks and solved after them on every thread at once, its colours swept on the pool:
  // on two threads, the rest of the islands and it would otherwise wait for the one thread
  // that has it.
  const bool threads = thread_pool().size() > 1;
  auto large = [&](std::size_t i) {
    return threads && coloured(ctx, i) && islands_.manifolds(i).size() >= kColouredOnThreads;
  };
  thread_pool().for_blocks(n, kIslandGrain, [&](std::size_t begin, std::size_t end) {
    IslandWork& w = island_work_[begin / kIslandGrain];
    for (std::size_t i = begin; i < end; ++i)
      if (!large(i) && !kept(i)) w.longest = std::max(w.longest, solve_island(ctx, manifolds, i, checked, w, false));
  });
  for (std::size_t i = 0; threads && i < n; ++i)
    if (large(i) && !kept(i)) {
      IslandWork& w = island_work_[i / kIslandGrain];
      w.longest = std::max(w.longest, solve_island(ctx, manifolds, i, checked, w, true));
    }
  int longest = 0;
  bool out_of_sweeps = false;
  for (const IslandWork& w : island_work_) {
    longest = std::max(longest, w.longest);
    cold_restarts_ += w.cold_restarts;
    out_of_sweeps = out_of_sweeps || w.out_of_sweeps;
  }
  total_sweeps_ += longest;
  std::size_t solved = n;  // a redetection counts the islands it solved again
  if (partial)
    for (std::size_t i = 0; i < n; ++i) solved -= kept(i);
  total_islands_ += static_cast<std::int64_t>(solved);

  // Out of sweeps: an island Gauss-Seidel cannot hold (heavy-light chains) gets its normal
  // impulses solved directly. Below a mass ratio of a few hundred the sweeps hold a chain
  // (the stress suite: 0.5 mm at 1e2 with 50 sweeps, 5 mm at 1e3), and a scene without such a
  // ratio between any two moving bodies never looks (heavy_light_). It looks at every island,
  // those a redetection kept too: one that the step's first pass left out of sweeps was solved
  // directly then, unless that would have made energy, and may be tried again.
  if (heavy_light_ && out_of_sweeps) solve_islands_directly(ctx, manifolds, before);
}

int IslandStage::solve_island(StepContext& ctx, std::span<Manifold> manifolds_all, std::size_t island, bool checked,
                              IslandWork& work, bool threads) {
  // Gauss-Seidel from zero impulses cannot raise the kinetic energy: with a non-positive target
  // each local update moves the velocity to the constraint set along M^-1 J^T, which never
  // raises 1/2 v'Mv (a projection in the metric of M). Warm starting (last step's impulses
  // applied before the sweeps) and the conjugate-gradient steps leave that argument: when the
  // sweep limit stops the solve short of convergence (long pressed chains), what remains of the
  // warm start, or of a step, can raise it. So an island whose contact impulses would add
  // kinetic energy is solved again from zero with plain sweeps (the test: contacts_gain_energy).
  BodyArrays& s = ctx.bodies;
  const std::span<const std::int32_t> manifolds = islands_.manifolds(island);
  const std::span<const std::int32_t> bodies = islands_.bodies(island);
  const std::size_t at = islands_.body_offset(island);  // its bodies' slice of the saved velocities
  double before = 0.0;
  if (checked) {
    before = kinetic_energy_of(s, bodies);
    for (std::size_t x = 0; x < bodies.size(); ++x) {
      island_velocity_[at + x] = s.velocity[bodies[x]];
      island_angular_velocity_[at + x] = s.angular_velocity[bodies[x]];
    }
  }
  SweepSpace space = sweep_work_.slice(islands_.manifold_offset(island), manifolds.size());
  const bool colour = coloured(ctx, island);
  if (colour) {
    space = sweep_work_.slice(islands_.manifold_offset(island), manifolds.size(), island_bundles_[island],
                              island_bundles_[island + 1] - island_bundles_[island]);
    space.colours_given = true;  // by solve()
  }
  SweepLimits limits = sweep_limits(ctx, manifolds.size());
  // A heavy-light island gets no extra sweeps: they run only while a point closes by more than
  // the allowed overlap in the step, which triggers the direct solve anyway (solve_islands_directly),
  // and the sweeps of such an island hand on m / M of the reaction a sweep: up to
  // extra_iterations of them, only to be solved directly after all.
  if (heavy_light_ && IslandSolver::heavy_light(bodies, s, ctx.settings.direct_solve_mass_ratio))
    limits.extra_iterations = 0;
  // Out of sweeps: the island spent its count (the direct solve's trigger looks then).
  auto spent = [&](int sweeps) {
    if (sweeps >= limits.iterations) work.out_of_sweeps = true;
    return sweeps;
  };
  // A large island's few sweeps are plain: NNCG's conjugate steps pay over tens of sweeps (a
  // load carried across a chain in N sweeps, not N^2), and over five its pass over the points
  // cost the packed 1k field's solve 0.41 against 0.28 ms a step.
  int sweeps = solve_velocities(manifolds_all, manifolds, s, limits, space,
                                {.warm_start = ctx.settings.warm_start,
                                 .accelerate = ctx.settings.accelerate && !large_island(ctx, manifolds.size()),
                                 .colour = colour,
                                 .threads = threads});
  if (!checked) return spent(sweeps);
  double pushed = 0.0;  // the work of towed bodies on this island's floes (contacts_gain_energy)
  if (ctx.has_prescribed)
    for (const std::int32_t k : manifolds) pushed += kinematic_work(s, manifolds_all[static_cast<std::size_t>(k)]);
  if (kinetic_energy_of(s, bodies) - 2.0 * pushed <= before) return spent(sweeps);
  for (std::size_t x = 0; x < bodies.size(); ++x) {
    s.velocity[bodies[x]] = island_velocity_[at + x];
    s.angular_velocity[bodies[x]] = island_angular_velocity_[at + x];
  }
  for (const std::int32_t k : manifolds) {
    Manifold& m = manifolds_all[static_cast<std::size_t>(k)];
    for (int j = 0; j < m.point_count; ++j) m.points[j].normal_impulse = m.points[j].tangent_impulse = 0.0;
  }
  space.colours_given = false;  // the first solve kept its list of rows beyond the colours there: colour again
  sweeps += solve_velocities(manifolds_all, manifolds, s, limits, space,  // plain sweeps: no energy made
                             {.colour = colour, .threads = threads});
  ++work.cold_restarts;
  return spent(sweeps);
}

void IslandStage::solve_islands_directly(StepContext& ctx, std::span<Manifold> manifolds, double before) {
  // Trigger (IslandSolver::Trigger), in an island of mass ratio direct_solve_mass_ratio: a
  // point the sweeps leave approaching faster than its target (u* - u_n > 0: the overlap the
  // step adds, over dt, since a resting point's target is -gap / dt) by more than 1e-3 of
  // allowed_penetration / dt, and either by more than allowed_penetration / dt (the step alone
  // adds more than the allowed overlap) or by enough to leave it deeper than the allowed
  // overlap. In a heavy-light chain the position projection, Gauss-Seidel too, cannot take an
  // overlap back, so a creep that goes on step after step (an iceberg the sweeps leave pressing
  // at 5 mm/s on floes against a wall) must be solved before it passes the allowed overlap. A
  // point that creeps within it is left to the sweeps: in a jammed pack about a heavy iceberg
  // most points creep by a little, and solving each of those steps directly (with its friction
  // sweeps, four times the sweeps alone) holds no overlap that the sweeps do not. Once
  // triggered, the solve holds every normal velocity to 1e-5 allowed_penetration / dt (an
  // overlap growing by 1e-8 m a step at the defaults).
  const NativeSettings& settings = ctx.settings;
  BodyArrays& s = ctx.bodies;
  const double closing_speed = settings.allowed_penetration / ctx.dt;
  const IslandSolver::Trigger trigger{.creep = 1e-3 * closing_speed,
                                      .closing = closing_speed,
                                      .dt = ctx.dt,
                                      .allowed_overlap = settings.allowed_penetration,
                                      .tolerance = 1e-5 * closing_speed};
  if (!island_solver_.select(manifolds, s, trigger, settings.direct_solve_mass_ratio)) return;
  // Once an island is solved, its normals are solved again wherever the sweeps that follow
  // (below) leave a point approaching beyond the creep alone: they end the step exact, not
  // merely within the allowed overlap.
  IslandSolver::Trigger again = trigger;
  again.closing = trigger.creep;
  saved_impulses_.clear();
  for (const Manifold& m : manifolds)
    for (int k = 0; k < m.point_count; ++k) {
      saved_impulses_.push_back(m.points[k].normal_impulse);
      saved_impulses_.push_back(m.points[k].tangent_impulse);
    }
  saved_velocity_ = s.velocity;
  saved_angular_velocity_ = s.angular_velocity;
  // First the normals alone, friction taken off: the sweeps' friction was found against their
  // wrong normals (in a heavy-light chain, tangential impulses of the size of the wrong normal
  // ones), and held it throws light floes sideways.
  if (!island_solver_.solve(manifolds, s, /*without_friction=*/true)) return;
  // Then sweeps bring friction back to its law for the exact normals, and the normals are
  // solved again with the friction they leave (the sweeps cannot hold the normals of a
  // heavy-light chain themselves), until the sweeps leave them within the trigger. Last,
  // friction beyond a fallen normal's cone is cut back to it, and the normals solved again with
  // the cut friction held, in turn until nothing is cut (a staggered projection: Kaufman, Sueda,
  // James and Pai, "Staggered projections for frictional contact in multibody systems", 2008).
  // Cutting alone undid the normals: a floe wedged between the iceberg and heavy floes was left
  // approaching at 0.1 m/s after 112 cuts, 18 mm of overlap in the next step (drift_in_field,
  // field seed 3). In drift_in_field 88 % of these solves cut nothing and 99 % stop within two
  // rounds, hence kFrictionRounds.
  // The sweeps run on the islands' manifolds alone (the rest stays as Gauss-Seidel left it):
  // copied out, solved, copied back.
  island_index_.assign(island_solver_.island_manifolds().begin(), island_solver_.island_manifolds().end());
  island_manifolds_.clear();
  for (const std::int32_t k : island_index_) island_manifolds_.push_back(manifolds[static_cast<std::size_t>(k)]);
  // The normals again with friction held, where a point is still left beyond the creep.
  auto solve_normals_again = [&] {
    return island_solver_.select(island_manifolds_, s, again, settings.direct_solve_mass_ratio) &&
           island_solver_.solve(island_manifolds_, s, /*without_friction=*/false);
  };
  for (int pass = 0; pass < 3; ++pass) {
    total_sweeps_ += solve_velocities(island_manifolds_, s, {settings.velocity_iterations, settings.tolerance},
                                      sweep_work_.space(island_manifolds_.size(), false));
    if (!solve_normals_again()) break;
  }
  for (int round = 0; round < kFrictionRounds && clamp_friction(island_manifolds_, s) > 0; ++round)
    if (!solve_normals_again()) break;
  for (std::size_t x = 0; x < island_index_.size(); ++x)
    manifolds[static_cast<std::size_t>(island_index_[x])] = island_manifolds_[x];
  ++direct_solves_;
  if (!contacts_gain_energy(ctx, manifolds, before)) return;
  // Newton's law on several simultaneous collisions can make energy in a joint solve (it cannot
  // in Gauss-Seidel's point by point): keep Gauss-Seidel's answer then.
  s.velocity = saved_velocity_;
  s.angular_velocity = saved_angular_velocity_;
  std::size_t x = 0;
  for (Manifold& m : manifolds)
    for (int k = 0; k < m.point_count; ++k) {
      m.points[k].normal_impulse = saved_impulses_[x++];
      m.points[k].tangent_impulse = saved_impulses_[x++];
    }
  ++direct_reverted_;
}

}  // namespace floedem
