// The coloured sweeps (native/solver/coloured_sweeps.cpp): another Gauss-Seidel order of the
// same points, four manifolds at a time. Held to: the same converged velocities as the sweeps
// in pair order (frictionless: the velocities after a converged solve are unique, the impulses
// of a redundant pack are not); Signorini and Coulomb at every point of a frictional pack; no
// kinetic energy made; a body with more contacts than there are colours; the same bits from
// every build of the sweep (baseline, AVX2, AVX-512) and on any number of threads.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "app/sanitizer.hpp"
#include "parallel/thread_pool.hpp"
#include "parallel/threads.hpp"
#include "run/stepper.hpp"
#include "floedem/scenario/scenario.hpp"
#include "geometry/lane_isa.hpp"
#include "solver/coloured_sweeps.hpp"
#include "solver/contact_solver.hpp"
#include "solver/pressed_pack.hpp"
#include "support.hpp"

using namespace floedem;
using namespace floedem::test;

namespace {

struct Solved {
  Pack state;
  int sweeps = 0;
};

// `threads`: each colour swept on the pool's threads (SweepOptions::threads).
Solved solve(const Pack& start, const SweepLimits& limits, bool colour, bool accelerate = false,
             bool warm_start = true, bool threads = false) {
  Solved s{start, 0};
  SweepWork work;
  s.sweeps = solve_velocities(
      s.state.manifolds, s.state.bodies, limits,
      work.space(s.state.manifolds.size(), accelerate, colour ? s.state.bodies.inv_mass.size() : 0),
      {.warm_start = warm_start, .accelerate = accelerate, .colour = colour, .threads = threads});
  return s;
}

double twice_kinetic_energy(const BodyArrays& b) {
  double e = 0.0;
  for (std::size_t i = 0; i < b.position.size(); ++i)
    if (b.inv_mass[i] != 0.0)
      e += length_squared(b.velocity[i]) / b.inv_mass[i] + b.angular_velocity[i] * b.angular_velocity[i] / b.inv_inertia[i];
  return e;
}

// A star: a heavy floe (body 1) with `spokes` small floes touching it all round (bodies 2...),
// each at two points, the heavy one drifting into them: more manifolds on one moving body than
// there are colours (63), so the rest are swept as rows.
Pack star(int spokes) {
  Pack p;
  const auto n = static_cast<std::size_t>(spokes) + 2;
  p.bodies.resize(n);
  p.bodies.rotation.assign(n, Rot::from_angle(0.0));
  p.bodies.inv_mass.assign(n, 0.0);
  p.bodies.inv_inertia.assign(n, 0.0);
  p.bodies.inv_mass[1] = 1.0 / 1e8;
  p.bodies.inv_inertia[1] = 1.0 / 1e12;
  p.bodies.velocity[1] = {0.3, 0.1};
  const double radius = 200.0;
  for (int k = 0; k < spokes; ++k) {
    const double angle = 2.0 * M_PI * k / spokes;
    const Vec2 out{std::cos(angle), std::sin(angle)};
    const auto b = static_cast<std::size_t>(k) + 2;
    p.bodies.position[b] = (radius + 2.0) * out;
    p.bodies.velocity[b] = {0.0, 0.0};
    p.bodies.inv_mass[b] = 1.0 / 9e4;
    p.bodies.inv_inertia[b] = 1.0 / 1.5e6;
    Manifold m;
    m.body_a = m.part_a = 1;
    m.body_b = m.part_b = static_cast<std::int32_t>(b);
    m.normal = out;
    m.friction = 0.3;
    m.restitution = 0.2;
    m.point_count = 2;
    for (int q = 0; q < 2; ++q) {
      m.points[q].point = radius * out + (q == 0 ? 1.0 : -1.0) * perp(out);
      m.points[q].separation = -0.001;
      m.points[q].id = static_cast<std::uint32_t>(q);
    }
    prepare_contact(m, p.bodies, 0.05, 0.01);
    p.manifolds.push_back(m);
  }
  return p;
}

// Signorini and Coulomb at every point: P_n >= 0 and |P_t| <= mu P_n exactly (each local solve
// ends inside the cone); returns the largest Signorini residual, max(u* - u_n, 0) or, where the
// point carries an impulse, |u_n - u*| (m/s).
double check_laws(const Pack& p) {
  double worst = 0.0;
  for (const Manifold& m : p.manifolds)
    for (int k = 0; k < m.point_count; ++k) {
      const ManifoldPoint& q = m.points[k];
      const double gap = dot(relative_velocity(p.bodies, m.body_a, m.body_b, q.ra, q.rb), m.normal) - q.target_velocity;
      CHECK(q.normal_impulse >= 0.0);
      CHECK(std::abs(q.tangent_impulse) <= m.friction * q.normal_impulse * (1.0 + 1e-12));
      worst = std::max(worst, q.normal_impulse > 0.0 ? std::abs(gap) : std::max(-gap, 0.0));
    }
  return worst;
}

}  // namespace

TEST_CASE("coloured sweeps: the same converged velocities as the sweeps in pair order", "[solver][coloured]") {
  // Frictionless: the converged velocities are the projection of the free ones onto the
  // admissible set in the mass metric, unique however the impulses of a redundant pack (two
  // points a face) share the load. 20 000 sweeps with NNCG converge both orders to round-off.
  Pack start = pack(12, 8, 5, false);
  for (Manifold& m : start.manifolds) {
    m.friction = 0.0;
    for (ManifoldPoint& q : m.points) q.tangent_impulse = 0.0;
  }
  const SweepLimits limits{20000, 1e-14};
  const Solved pairs = solve(start, limits, false, true);
  const Solved colours = solve(start, limits, true, true);
  double largest = 0.0;
  for (const Vec2 v : pairs.state.bodies.velocity) largest = std::max(largest, length(v));
  REQUIRE(largest > 0.1);
  for (std::size_t b = 0; b < start.bodies.position.size(); ++b) {
    INFO("body " << b);
    // 1e-9 of the largest speed: round-off of the two orders' sums, far below any physical speed.
    CHECK(length(colours.state.bodies.velocity[b] - pairs.state.bodies.velocity[b]) <= 1e-9 * largest);
    CHECK(std::abs(colours.state.bodies.angular_velocity[b] - pairs.state.bodies.angular_velocity[b]) * 10.0 <=
          1e-9 * largest);
  }
}

TEST_CASE("coloured sweeps: a frictional pack meets Signorini and Coulomb as well as the pair order", "[solver][coloured]") {
  // With friction, Gauss-Seidel need not converge to round-off (a point that slides one sweep
  // and sticks the next), in either order: after 200 sweeps the coloured solve is held to the
  // cone exactly and to the pair order's Signorini residual, within a factor 2.
  const bool accelerate = GENERATE(false, true);
  const Pack start = pack(20, 12, 9, true);
  const double pairs = check_laws(solve(start, {200, 0.0}, false, accelerate).state);
  const double colours = check_laws(solve(start, {200, 0.0}, true, accelerate).state);
  INFO((accelerate ? "NNCG" : "plain sweeps") << ": residual " << colours << " m/s, pair order " << pairs);
  CHECK(colours <= 2.0 * pairs + 1e-12);
}

TEST_CASE("coloured sweeps: plain sweeps from zero make no kinetic energy", "[solver][coloured]") {
  // Each local update projects the velocities onto its constraint in the mass metric, in any
  // order (contact_solver.cpp): from zero impulses and without the warm start, 10 sweeps of a
  // pack with collisions and friction leave no more kinetic energy than they found.
  Pack start = pack(20, 12, 3, true);
  for (Manifold& m : start.manifolds)
    for (ManifoldPoint& q : m.points) q.normal_impulse = q.tangent_impulse = 0.0;
  const double before = twice_kinetic_energy(start.bodies);
  const Solved colours = solve(start, {10, 0.0}, true, false, /*warm_start=*/false);
  CHECK(twice_kinetic_energy(colours.state.bodies) <= before * (1.0 + 1e-14));
}

TEST_CASE("coloured sweeps: a floe with more contacts than colours", "[solver][coloured]") {
  // 100 floes round a heavy one: 63 of its manifolds get colours, 37 are swept as rows. The
  // converged solve meets the laws, and the heavy floe's velocity is the pair order's.
  const Pack start = star(100);
  const bool accelerate = GENERATE(false, true);
  INFO((accelerate ? "NNCG" : "plain sweeps"));
  const SweepLimits limits{20000, 1e-14};
  const Solved colours = solve(start, limits, true, accelerate);
  CHECK(check_laws(colours.state) <= 1e-9);  // m/s: converged to round-off
  const Solved pairs = solve(start, limits, false, accelerate);
  CHECK(length(colours.state.bodies.velocity[1] - pairs.state.bodies.velocity[1]) <= 1e-9);
  // Momentum: every impulse acts on two moving bodies, so the total is conserved to round-off.
  Vec2 before, after;
  for (std::size_t b = 1; b < start.bodies.position.size(); ++b) {
    before += (1.0 / start.bodies.inv_mass[b]) * start.bodies.velocity[b];
    after += (1.0 / start.bodies.inv_mass[b]) * colours.state.bodies.velocity[b];
  }
  CHECK(length(after - before) <= 1e-9 * length(before));
}

TEST_CASE("coloured sweeps: every build of the sweep gives the same impulses to the bit", "[solver][coloured]") {
  const std::vector<LaneIsa> isas = available_lane_isas();
  REQUIRE(isas.front() == LaneIsa::baseline);
  const bool accelerate = GENERATE(false, true);
  for (const Pack& start : {pack(30, 20, 17, true), star(80)}) {
    use_lane_isa(LaneIsa::baseline);
    const Solved reference = solve(start, {40, 0.0, 20, 1e-6}, true, accelerate);
    for (const LaneIsa isa : isas) {
      INFO("build " << static_cast<int>(isa) << (accelerate ? ", NNCG" : ""));
      use_lane_isa(isa);
      const Solved other = solve(start, {40, 0.0, 20, 1e-6}, true, accelerate);
      CHECK(other.sweeps == reference.sweeps);
      check_same_solve(other.state, reference.state);
    }
  }
  use_fastest_lane_isa();
  CHECK_THROWS(use_lane_isa(static_cast<LaneIsa>(7)));
}

TEST_CASE("coloured sweeps: two-point manifolds placed first, the same impulses to the bit", "[solver][coloured]") {
  // Plain sweeps place each colour's manifolds of two points in its first bundles (fewer
  // bundle-points to sweep); the bundles of a colour share no moving body, so the impulses and
  // velocities are those of the given order to the bit. A pack with about every third manifold
  // cut to one point: colours whose two kinds meet inside a bundle (filled out of lane order),
  // bundles of one kind, and a colour's partly empty last bundle.
  Pack start = pack(30, 20, 23, true);
  std::mt19937 rng(5);
  std::size_t one = 0;
  for (Manifold& m : start.manifolds)
    if (rng() % 3 == 0) {
      m.point_count = 1;
      ++one;
    }
  REQUIRE(one > 100);
  REQUIRE(one + 100 < start.manifolds.size());
  for (const Pack& p : {start, star(80)}) {
    const SweepLimits limits{40, 0.0, 20, 1e-6};
    Solved given{p, 0}, placed{p, 0};
    SweepWork work;
    given.sweeps = solve_velocities(given.state.manifolds, given.state.bodies, limits,
                                    work.space(p.manifolds.size(), false, p.bodies.inv_mass.size()),
                                    {.warm_start = true, .colour = true, .given_order = true});
    placed.sweeps = solve_velocities(placed.state.manifolds, placed.state.bodies, limits,
                                     work.space(p.manifolds.size(), false, p.bodies.inv_mass.size()),
                                     {.warm_start = true, .colour = true});
    CHECK(placed.sweeps == given.sweeps);
    check_same_solve(placed.state, given.state);
    // Not a solve that leaves everything where it was.
    CHECK(!same_bits(placed.state.bodies.velocity, p.bodies.velocity));
  }
}

TEST_CASE("coloured sweeps: each colour on the pool's threads, the same impulses to the bit", "[solver][coloured][threads]") {
  // 4 700 manifolds: colours of up to about 1 200 manifolds, 300 bundles, 5 blocks of 64: the
  // largest go to the pool (4 blocks or more), their sweeps and NNCG steps alike, the rest on the calling thread; and
  // 4 096 manifolds or more are packed on the pool's threads, with the warm start on one of them.
  const bool accelerate = GENERATE(false, true);
  const Pack start = pack(60, 40, 21, true);
  const SweepLimits limits{30, 0.0, 20, 1e-6};
  const Solved serial = solve(start, limits, true, accelerate);
  for (const unsigned threads : {1u, 2u, 3u}) {
    INFO(threads << " threads" << (accelerate ? ", NNCG" : ""));
    set_thread_pool_size(threads);
    const Solved pooled = solve(start, limits, true, accelerate, true, /*threads=*/true);
    CHECK(pooled.sweeps == serial.sweeps);
    check_same_solve(pooled.state, serial.state);
  }
  set_thread_pool_size(worker_threads());
}

TEST_CASE("coloured sweeps: the native engine gives the same state on 1 and 2 threads", "[solver][coloured][threads]") {
  // The 1k field benchmark driven onto its wall at twice its current, with coloured sweeps and
  // the default NNCG: each island is one task on any thread, so the state is the same to the bit.
  const Scene scene = load_scenario(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/bench/field_wall_1k.toml",
                                    {"environment.current=[1.0, 0.0]", "engine.native.coloured_sweeps=true",
                                     "engine.native.accelerate=true", "engine.native.extra_iterations=100"});
  constexpr int kSteps = 600;  // 30 s at dt 0.05 s
  BodyStates states[2];
  for (const unsigned threads : {1u, 2u}) {
    set_thread_pool_size(threads);
    Stepper stepper(scene, "native");
    for (int k = 0; k < kSteps; ++k) stepper.step();
    states[threads - 1] = stepper.state();
  }
  set_thread_pool_size(worker_threads());
  check_same_state(states[0], states[1]);
}

TEST_CASE("coloured sweeps: an island solved on every thread at once gives the same state on 1 and 2 threads",
          "[solver][coloured][threads]") {
  // An island of at least kColouredOnThreads manifolds is left out of the blocks of islands and
  // solved after them, its colours swept on the pool (IslandStage::solve), the path
  // of a packed field on its wall; the fields of the tests above do not pack into one that
  // large within their steps. Here 50 x 50 floes of 10 m, each touching its neighbours (4 900
  // manifolds, one island), closing on the middle (0.2 m/s at the edges, neighbours 8 mm/s
  // apart) with random velocities of up to 0.05 m/s on top: collisions, pressed contacts,
  // sticking and sliding from the first step.
  constexpr int kSide = 50, kSteps = 20;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::string text = header_toml(1.0, 0.05, 0.1, 0.3);
  for (int r = 0; r < kSide; ++r)
    for (int c = 0; c < kSide; ++c)
      text += body_toml({"floe-" + std::to_string(r * kSide + c), box({10.0 * c, 10.0 * r}, 10, 10),
                         Vec2{245.0 - 10.0 * c, 245.0 - 10.0 * r} * (0.2 / 245.0) + Vec2{0.05 * u(rng), 0.05 * u(rng)},
                         0.002 * u(rng)});
  const Scene scene = scene_from(text);
  BodyStates states[2];
  for (const unsigned threads : {1u, 2u}) {
    set_thread_pool_size(threads);
    auto e = native(scene);
    e->step(nullptr);
    // The path asked for: one island a step, of more manifolds than kColouredOnThreads (a
    // manifold records at most two points).
    REQUIRE(e->contacts().size() > 2 * kColouredOnThreads);
    for (int k = 1; k < kSteps; ++k) e->step(nullptr);
    REQUIRE(e->info().settings.at("mean_islands_per_step") == "1");
    states[threads - 1] = e->state();
  }
  set_thread_pool_size(worker_threads());
  check_same_state(states[0], states[1]);
}

TEST_CASE("coloured_from picks the order per island: its bounds are the shorthand's two orders", "[solver][coloured]") {
  // `coloured_from = 0` colours every island, as `coloured_sweeps = true`; a bound above every
  // island colours none, as `false`; a bound between the field's islands mixes the two orders,
  // and differs from both (the field packs on its wall into one large island and small ones).
  auto run = [](const std::string& setting) {
    const Scene scene = load_scenario(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/bench/field_wall_1k.toml",
                                      {"environment.current=[1.0, 0.0]", "engine.native." + setting});
    Stepper stepper(scene, "native");
    // 40 s (20 s under a sanitizer, five runs at a fifth of the speed): islands of some tens of
    // manifolds and more by then.
    for (int k = 0; k < (kSanitizerAllocator ? 400 : 800); ++k) stepper.step();
    return stepper.state();
  };
  check_same_state(run("coloured_from=0"), run("coloured_sweeps=true"));
  check_same_state(run("coloured_from=1000000000"), run("coloured_sweeps=false"));
  const BodyStates mixed = run("coloured_from=20"), all = run("coloured_from=0"), none = run("coloured_from=1000000000");
  bool differs_all = false, differs_none = false;
  for (std::size_t i = 0; i < mixed.position.size(); ++i) {
    differs_all = differs_all || mixed.position[i].x != all.position[i].x;
    differs_none = differs_none || mixed.position[i].x != none.position[i].x;
  }
  CHECK(differs_all);
  CHECK(differs_none);
}
