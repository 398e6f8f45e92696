// The pipelined sweeps (native/solver/sweep_pipeline.cpp) against the serial ones: the same
// impulses and velocities to the bit, on several thread counts, whether the sweeps run to their
// limit, stop on the tolerance (a sweep some threads went on into is put back) or go on into
// the extra sweeps; and the native engine that routes a packed field's large island to it.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <span>

#include "parallel/thread_pool.hpp"
#include "parallel/threads.hpp"
#include "run/stepper.hpp"
#include "floedem/scenario/scenario.hpp"
#include "solver/contact_solver.hpp"
#include "solver/sweep_pipeline.hpp"
#include "solver/pressed_pack.hpp"

using namespace floedem;

namespace {

using namespace floedem::test;

struct Solved {
  Pack state;
  int sweeps = 0;
};

Solved solve(const Pack& start, const SweepLimits& limits, SweepPipeline* pipeline) {
  Solved s{start, 0};
  SweepWork work;
  s.sweeps = solve_velocities(s.state.manifolds, s.state.bodies, limits, work.space(s.state.manifolds.size(), false),
                              {.warm_start = true, .pipeline = pipeline});
  return s;
}

}  // namespace

TEST_CASE("sweep pipeline: the same impulses and velocities as the serial sweeps, to the bit", "[solver][threads]") {
  const bool shuffled = GENERATE(false, true);
  const Pack start = pack(60, 40, 7, shuffled);  // 4 700 manifolds, 9 400 rows
  // Limits: (a) 30 sweeps, no tolerance: every sweep made; (b) a tolerance the sweeps meet part
  // way (checked below on the serial run); (c) 5 sweeps and extra sweeps while a point closes.
  const SweepLimits limits = GENERATE(SweepLimits{30, 0.0}, SweepLimits{400, 1e-2}, SweepLimits{5, 1e-10, 40, 1e-4});
  const Solved serial = solve(start, limits, nullptr);
  if (limits.tolerance > 1e-6) REQUIRE(serial.sweeps < limits.iterations);  // stopped on the tolerance
  if (limits.extra_iterations > 0) REQUIRE(serial.sweeps > limits.iterations);

  for (const unsigned threads : {2u, 3u, 4u}) {
    set_thread_pool_size(threads);
    INFO("threads " << threads << (shuffled ? ", shuffled" : ""));
    REQUIRE(SweepPipeline::parts_for(2 * start.manifolds.size()) == threads);
    SweepPipeline pipeline;
    for (int repeat = 0; repeat < 3; ++repeat) {  // the pipeline's lists reused, as from step to step
      const Solved piped = solve(start, limits, &pipeline);
      CHECK(piped.sweeps == serial.sweeps);
      check_same_solve(piped.state, serial.state);
    }
  }
  set_thread_pool_size(worker_threads());
}

TEST_CASE("sweep pipeline: a sweep begun before the stop was known is put back", "[solver][threads]") {
  // Whether a thread went on into the sweep after the one that met the tolerance depends on
  // timing: over a range of tolerances (stopping at different sweeps), some do, and every
  // result is the serial one's.
  const Pack start = pack(60, 40, 11, false);
  set_thread_pool_size(2);
  SweepPipeline pipeline;
  std::int64_t put_back = 0;
  for (int k = 0; k < 40 && put_back < 3; ++k) {
    const SweepLimits limits{400, 0.1 * std::pow(0.8, k)};
    const Solved serial = solve(start, limits, nullptr);
    const std::int64_t before = pipeline.sweeps_put_back();
    const Solved piped = solve(start, limits, &pipeline);
    put_back += pipeline.sweeps_put_back() - before;
    INFO("tolerance " << limits.tolerance);
    REQUIRE(piped.sweeps == serial.sweeps);
    REQUIRE(same_bits(piped.state.bodies.velocity, serial.state.bodies.velocity));
    REQUIRE(same_bits(piped.state.bodies.angular_velocity, serial.state.bodies.angular_velocity));
    REQUIRE(same_impulses(piped.state.manifolds, serial.state.manifolds));
  }
  set_thread_pool_size(worker_threads());
  CHECK(put_back > 0);
}

TEST_CASE("sweep pipeline: bodies whose spread overflows a double are placed in parts all the same",
          "[solver][threads]") {
  // Two floes at -1e308 and 1e308 m: the island's extent is infinite, so the slabs' scale is 0
  // and the far floe's place along it inf * 0 = NaN. Rows are placed in parts from their
  // bodies' positions only (the sweeps read lever arms, not positions), so the sweeps are the
  // serial ones' all the same; a NaN cast to a bin index read far outside the bins.
  Pack start = pack(60, 40, 13, false);
  start.bodies.position[1] = {-1e308, 0.0};
  start.bodies.position[start.bodies.position.size() - 1] = {1e308, 0.0};
  const SweepLimits limits{20, 0.0};
  const Solved serial = solve(start, limits, nullptr);
  set_thread_pool_size(2);
  SweepPipeline pipeline;
  const Solved piped = solve(start, limits, &pipeline);
  set_thread_pool_size(worker_threads());
  CHECK(piped.sweeps == serial.sweeps);
  CHECK(same_bits(piped.state.bodies.velocity, serial.state.bodies.velocity));
  CHECK(same_impulses(piped.state.manifolds, serial.state.manifolds));
}

TEST_CASE("sweep pipeline: too few rows for a second thread", "[solver][threads]") {
  set_thread_pool_size(2);
  CHECK(SweepPipeline::parts_for(100) == 1);
  CHECK(SweepPipeline::parts_for(5000) == 2);
  set_thread_pool_size(1);
  CHECK(SweepPipeline::parts_for(100000) == 1);
  set_thread_pool_size(worker_threads());
}

namespace {

// Contact points of the largest island at the engine's last step: groups of moving bodies
// joined by contacts (a fixed body joins nothing, as in the engine's islands). Each point is
// at least one sweep row, so this bounds the island's rows from below.
std::size_t largest_island_points(const Scene& scene, std::span<const ContactRecord> contacts) {
  std::vector<std::size_t> root(scene.bodies.size());
  for (std::size_t i = 0; i < root.size(); ++i) root[i] = i;
  auto find = [&](std::size_t i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  auto moving = [&](std::int32_t b) { return !scene.bodies[static_cast<std::size_t>(b)].fixed; };
  for (const ContactRecord& c : contacts)
    if (moving(c.body_a) && moving(c.body_b))
      root[find(static_cast<std::size_t>(c.body_a))] = find(static_cast<std::size_t>(c.body_b));
  std::vector<std::size_t> points(root.size(), 0);
  std::size_t most = 0;
  for (const ContactRecord& c : contacts) {
    const std::int32_t b = moving(c.body_a) ? c.body_a : c.body_b;
    most = std::max(most, ++points[find(static_cast<std::size_t>(b))]);
  }
  return most;
}

}  // namespace

TEST_CASE("sweep pipeline: the native engine on a packed field gives the same state on 1 and 2 threads",
          "[solver][threads]") {
  // The 4k field benchmark in pair order with plain sweeps (the pipeline's case: NNCG is not
  // pipelined) driven onto its wall at twice its current for 45 s: by then many
  // floes touch and the largest island has rows enough for two parts, so on two threads the
  // engine solves it pipelined (native_engine.cpp, solve_contacts) while the small islands go to
  // the islands' blocks. Every body's velocity and position, bit for bit.
  const Scene scene = load_scenario(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/bench/field_wall_4k.toml",
                                    {"environment.current=[1.0, 0.0]", "engine.native.coloured_sweeps=false",
                                     "engine.native.accelerate=false", "engine.native.extra_iterations=0",
                                     "engine.native.velocity_iterations=10"});
  constexpr int kSteps = 900;  // 45 s at dt 0.05 s
  BodyStates states[2];
  for (const unsigned threads : {1u, 2u}) {
    set_thread_pool_size(threads);
    Stepper stepper(scene, "native");
    for (int k = 0; k < kSteps; ++k) stepper.step();
    if (threads == 2) {
      const std::size_t points = largest_island_points(scene, stepper.contacts());
      INFO("largest island: " << points << " contact points");
      REQUIRE(SweepPipeline::parts_for(points) == 2);  // it was pipelined
    }
    states[threads - 1] = stepper.state();
  }
  set_thread_pool_size(worker_threads());
  check_same_state(states[0], states[1]);
}
