// Micro-benchmarks of the hot loops (Google Benchmark). Not tests: run them with
//   build/floedem_bench --benchmark_out=reports/bench/$(hostname).csv --benchmark_out_format=csv
// (the `bench` target does this).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>

#include "floedem/engine/registry.hpp"
#include "floe_polygon.hpp"
#include "floedem/field/field_generator.hpp"
#include "forcing/drag.hpp"
#include "forcing/drag_pass.hpp"
#include "forcing/forcing.hpp"
#include "run/stepper.hpp"
#include "floedem/scenario/scenario.hpp"
#include "collision/broad_phase.hpp"
#include "solver/contact_solver.hpp"
#include "collision/narrow_phase.hpp"
#include "solver/native_settings.hpp"
#include "collision/part_set.hpp"
#include "parallel/thread_pool.hpp"
#include "parallel/threads.hpp"

using namespace floedem;

namespace {

/// N boxes with power-law sizes (d^-2, 2 to 60 m) at about 50 % cover.
void power_law_boxes(int n, std::vector<Aabb>& boxes, std::vector<std::int32_t>& body, std::vector<std::uint8_t>& fixed) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double area = 0.0;
  std::vector<double> sizes;
  for (int i = 0; i < n; ++i) {
    const double d = 2.0 / std::sqrt(1.0 - u(rng) * (1.0 - (2.0 / 60.0) * (2.0 / 60.0)));  // truncated Pareto, alpha 2
    sizes.push_back(d);
    area += d * d;
  }
  const double side = std::sqrt(area / 0.5);
  for (int i = 0; i < n; ++i) {
    const Vec2 c{u(rng) * side, u(rng) * side};
    boxes.push_back({c - 0.5 * Vec2{sizes[i], sizes[i]}, c + 0.5 * Vec2{sizes[i], sizes[i]}});
    body.push_back(i);
    fixed.push_back(0);
  }
}

void BM_BroadPhase(benchmark::State& state) {
  std::vector<Aabb> boxes;
  std::vector<std::int32_t> body;
  std::vector<std::uint8_t> fixed;
  power_law_boxes(static_cast<int>(state.range(0)), boxes, body, fixed);
  BroadPhase bp;
  std::vector<PartPair> pairs;
  for (auto _ : state) {
    bp.find_pairs(boxes, body, fixed, pairs);
    benchmark::DoNotOptimize(pairs.data());
  }
  state.counters["pairs"] = static_cast<double>(pairs.size());
  state.counters["ns_per_box"] = benchmark::Counter(static_cast<double>(state.range(0)),
                                                    benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_BroadPhase)->RangeMultiplier(10)->Range(1000, 100000)->Complexity(benchmark::oN)->Unit(benchmark::kMicrosecond);

/// A row of N separated floes (no contacts): the step cost of forcing and integration alone.
std::string spread_floes(int n, const std::string& environment) {
  std::string t = "[run]\nduration = 1e6\ndt = 1.0\n" + environment;
  for (int i = 0; i < n; ++i) {
    const double x = 30.0 * i;
    t += "[[body]]\npolygon = [[" + std::to_string(x) + ",0],[" + std::to_string(x + 10) + ",0],[" +
         std::to_string(x + 10) + ",10],[" + std::to_string(x) + ",10]]\nthickness = 1\nvelocity = [0.1, 0.0]\n";
  }
  return t;
}

void step_scene(benchmark::State& state, const std::string& environment) {
  const Scene s = parse_scenario(spread_floes(static_cast<int>(state.range(0)), environment), "bench.toml");
  auto engine = make_engine("native", s);
  Forcing forcing(s);
  double t = 0.0;
  for (auto _ : state) {
    engine->step(forcing.evaluate(engine->state(), t));
    t += 1.0;
  }
  state.counters["terms"] = static_cast<double>(forcing.names().size());
}

const std::string kNoDrag =
    "[environment.drag]\nwater_form = 0.0\nwater_skin = 0.0\nair_form = 0.0\nair_skin = 0.0\n";

void BM_StepNoEnvironment(benchmark::State& state) { step_scene(state, ""); }
void BM_StepCoriolisOnly(benchmark::State& state) { step_scene(state, "[environment]\nlatitude = 75.0\n" + kNoDrag); }
void BM_StepFullEnvironment(benchmark::State& state) {
  step_scene(state, "[environment]\nlatitude = 75.0\nwind = [7.0, 7.0]\ncurrent = [0.1, 0.0]\n[environment.waves]\namplitude = 1.0\nperiod = 8.0\n");
}
BENCHMARK(BM_StepNoEnvironment)->Arg(1)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StepCoriolisOnly)->Arg(1)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StepFullEnvironment)->Arg(1)->Arg(1000)->Unit(benchmark::kMicrosecond);

/// Drag quadrature (a third of a step in a drifting field): N floes, 5 to 9 corners, 5 to 30 m,
/// drifting and turning in a current, water form and skin drag. First argument 1: the terms'
/// packed quadrature (drag.cpp); 0: the point-by-point rule it reproduces to the bit, over point
/// lists made once per floe (as the terms held them before they were packed). Second: N, 1 000
/// (the points in L2) or 16 000 (the speed benchmark's field: about 20 MB of points, streamed
/// from L3 or memory each step, as in the field's step).
/// The sums of n floes of a field before the drag terms add: never stiff (Q alone).
ForceSums floe_sums(std::size_t n) {
  ForceSums sums;
  sums.q.assign(n, {});
  sums.dq.assign(n, {});
  sums.rotation_rate.assign(n, 0.0);
  sums.jacobian.assign(n, 0);
  sums.rate_bound.assign(n, {});
  return sums;
}

void BM_DragQuadrature(benchmark::State& state) {
  const bool packed = state.range(0) != 0;
  const auto n = static_cast<int>(state.range(1));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  EnvironmentSpec env;
  const auto water = DistributedDrag::Medium::water;
  DistributedDrag form("form", DistributedDrag::Kind::form, env, water),
      skin("skin", DistributedDrag::Kind::skin, env, water);
  std::vector<std::vector<EdgePoint>> edges;  // the rule's points, made once as the terms' were
  std::vector<std::vector<AreaPoint>> points;
  BodyStates s;
  s.resize(n);
  ForceSums sums = floe_sums(n);
  const Vec2 current{0.3, 0.1};
  for (int i = 0; i < n; ++i) {
    const int corners = 5 + i % 5;
    const double size = 2.5 + 12.5 * (1.0 + u(rng)) / 2.0;
    const std::vector<Vec2> poly = test::jittered_polygon(rng, corners, size);
    form.add_body(static_cast<std::size_t>(i), poly, {{0.5 * 1025.0 * 0.6 * 1.0, 1.0, current}});
    skin.add_body(static_cast<std::size_t>(i), poly, {{1025.0 * 0.0055, 1.0, current}});
    edges.push_back(edge_points(poly));
    points.push_back(area_points(poly));
    s.velocity[i] = {0.2 + 0.1 * u(rng), 0.1 * u(rng)};
    s.angular_velocity[i] = 0.01 * u(rng);
    sums.rotation.push_back(Rot::from_angle(u(rng)));
  }
  const DragSettings settings{env.rotational_damping, env.drag_reference_speed};
  for (auto _ : state) {
    if (packed) {
      form.add(s, 0.0, sums);
      skin.add(s, 0.0, sums);
    } else {
      for (int i = 0; i < n; ++i) {
        BodySum sum = sums.load(static_cast<std::size_t>(i));
        add_form_drag(sum, edges[i], 1.0, 0.5 * 1025.0 * 0.6, current, s.velocity[i],
                      s.angular_velocity[i], sums.rotation[i], settings, false);
        add_skin_drag(sum, points[i], 1.0, 1025.0 * 0.0055, current, s.velocity[i],
                      s.angular_velocity[i], sums.rotation[i], settings, false);
        sums.store(static_cast<std::size_t>(i), sum);
      }
    }
    benchmark::DoNotOptimize(sums.q.data());
  }
  state.counters["ns_per_floe"] =
      benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_DragQuadrature)->Args({0, 1000})->Args({1, 1000})->Args({1, 16000})->Unit(benchmark::kMicrosecond);

/// A drifting floe's four drag terms (water form and skin in the current, air form and skin in
/// the wind), rate bound and sums: the terms one after the other (0) or in one shared pass (1,
/// forcing/drag_pass.hpp; the same sums to the bit). In cache at 1 000 floes; at 16 000 the
/// terms' packed points (about 19 MB) no longer fit, as in the speed benchmark's step.
void BM_DragTerms(benchmark::State& state) {
  const bool shared = state.range(0) != 0;
  const auto n = static_cast<std::size_t>(state.range(1));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  EnvironmentSpec env;
  using Kind = DistributedDrag::Kind;
  using Medium = DistributedDrag::Medium;
  DistributedDrag water_form("water_form", Kind::form, env, Medium::water),
      water_skin("water_skin", Kind::skin, env, Medium::water), air_form("air_form", Kind::form, env, Medium::air),
      air_skin("air_skin", Kind::skin, env, Medium::air);
  std::vector<std::vector<Vec2>> polys(n);
  BodyStates s;
  s.resize(n);
  ForceSums sums = floe_sums(n);
  const Vec2 current{0.3, 0.1}, wind{6.0, 4.0};
  for (std::size_t i = 0; i < n; ++i) {
    const int corners = 5 + static_cast<int>(i % 5);
    const double size = 2.5 + 12.5 * (1.0 + u(rng)) / 2.0;
    polys[i] = test::jittered_polygon(rng, corners, size);
    water_form.add_body(i, polys[i], {{0.5 * 1025.0 * 0.6 * 0.9, 1.0, current}});
    water_skin.add_body(i, polys[i], {{1025.0 * 0.0055, 1.0, current}});
    air_form.add_body(i, polys[i], {{0.5 * 1.3 * 0.4 * 0.1, 1.0, wind}});
    air_skin.add_body(i, polys[i], {{1.3 * 0.0025, 1.0, wind}});
    s.velocity[i] = {0.2 + 0.1 * u(rng), 0.1 * u(rng)};
    s.angular_velocity[i] = 0.01 * u(rng);
    sums.rotation.push_back(Rot::from_angle(u(rng)));
    sums.stirred.push_back(static_cast<std::int32_t>(i));
  }
  const std::vector<DistributedDrag*> terms{&water_form, &water_skin, &air_form, &air_skin};
  std::unique_ptr<DragPass> pass;  // the terms leave their floes to it from then on
  if (shared) pass = std::make_unique<DragPass>(terms, [&](std::size_t i) -> const std::vector<Vec2>& { return polys[i]; });
  if (shared && pass->floes() != n) state.SkipWithError("the pass did not take every floe");
  for (auto _ : state) {
    if (shared) {
      pass->add_rate_bound(s, sums);
      pass->add(s, 0.0, sums);
    } else {
      for (const DistributedDrag* t : terms) t->add_rate_bound(s, sums);
      for (const DistributedDrag* t : terms) t->add(s, 0.0, sums);
    }
    benchmark::DoNotOptimize(sums.q.data());
  }
  state.counters["ns_per_floe"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_DragTerms)->Args({0, 1000})->Args({1, 1000})->Args({0, 16000})->Args({1, 16000})->Unit(benchmark::kMicrosecond);

/// Field generation (the speed targets: 1e4 floes under 2 s, 1e5 under 20 s on 2 cores):
/// alpha 2, d 2..50 m, C 0.5, default irregularity; the square domain holds N floes.
void BM_FieldGenerator(benchmark::State& state) {
  FieldSpec s;
  s.concentration = 0.5;
  s.alpha = 2.0;
  s.d_min = 2.0;
  s.d_max = 50.0;
  s.thickness.value = 1.0;
  const double side = std::sqrt(static_cast<double>(state.range(0)) *
                                TruncatedPowerLaw{s.alpha, s.d_min, s.d_max}.mean_area() / s.concentration);
  s.width = s.height = side;
  std::size_t floes = 0;
  for (auto _ : state) {
    const Field f = generate_field(s);
    floes = f.stats.floes;
    benchmark::DoNotOptimize(f.floes.data());
  }
  state.counters["floes"] = static_cast<double>(floes);
}
BENCHMARK(BM_FieldGenerator)->Arg(10000)->Arg(100000)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

/// A packed field's contacts, for the two loops that take 40 % of its step (the contact sweeps
/// and the narrow phase): the speed benchmark's 1 000 floes (scenarios/bench/field_wall_1k.toml)
/// run 100 s onto their wall, the state the speed figures are timed in. Its pairs are found
/// (broad phase over boxes grown by the margin) and collided as the native engine does, with a
/// margin of two floes' reach at the drift speed (0.5 m/s over a step) plus the allowed overlap,
/// and the engine's flip tolerance; its contacts are classified, and solved once from zero for a
/// warm start. The step, sweep limits and overlap are the scenario's. Made once.
struct PackedField {
  // FLOEDEM_BENCH_FIELD=4k or 16k: that field instead (its contacts out of cache; made in
  // about a minute at 16k).
  static std::string field_size() {
    const char* const size = std::getenv("FLOEDEM_BENCH_FIELD");
    if (size == nullptr || *size == '\0') return "1k";
    const std::string s = size;
    if (s != "1k" && s != "4k" && s != "16k") {
      std::fprintf(stderr, "floedem_bench: FLOEDEM_BENCH_FIELD must be 1k, 4k or 16k (scenarios/bench/field_wall_*.toml), not '%s'\n",
                   s.c_str());
      std::exit(2);
    }
    return s;
  }
  Scene scene;
  NativeSettings settings;
  SweepLimits limits;
  double margin;
  PartSet parts;
  BodyArrays bodies;
  std::vector<PartPair> pairs;
  std::vector<Manifold> manifolds;

  PartGeometry geometry(std::int32_t part) const {
    const std::int32_t b = parts.body()[part];
    return parts.geometry(part, bodies.position[b], bodies.rotation[b]);
  }
  void collide_pair(PartPair pair, Manifold& m) const {
    collide(geometry(pair.a), geometry(pair.b), margin, 0.1 * settings.allowed_penetration, m);
  }

  PackedField()
      : scene(load_scenario(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/bench/field_wall_" + field_size() + ".toml",
                            {"run.duration=100.0"})),
        settings(read_native_settings(scene)),
        limits{settings.velocity_iterations, settings.tolerance},
        margin(2.0 * 0.5 * scene.run.dt + settings.allowed_penetration),
        parts(scene) {
    Stepper stepper(scene, "native");
    for (std::int64_t step = 0; step < scene.run.steps(); ++step) stepper.step();
    const BodyStates& state = stepper.state();
    static_cast<BodyStates&>(bodies) = state;
    for (std::size_t i = 0; i < state.position.size(); ++i) {
      bodies.rotation.push_back(Rot::from_angle(state.angle[i]));
      bodies.inv_mass.push_back(scene.engine_inverse_mass(i));
      bodies.inv_inertia.push_back(scene.engine_inverse_inertia(i));
    }
    parts.place(bodies.position, bodies.rotation);
    std::vector<Aabb> boxes;
    const Vec2 grow{0.5 * margin, 0.5 * margin};
    for (const Aabb& b : parts.boxes()) boxes.push_back({b.lo - grow, b.hi + grow});
    BroadPhase().find_pairs(boxes, parts.body(), parts.immovable(), pairs);
    for (const PartPair pair : pairs) {
      Manifold m;
      collide_pair(pair, m);
      if (m.point_count == 0) continue;
      name_pair(m, pair.a, pair.b, parts.body(), scene.contact);
      prepare_contact(m, bodies, scene.run.dt, scene.contact.collision_threshold);
      manifolds.push_back(m);
    }
    BodyArrays scratch = bodies;
    SweepWork work;
    solve_velocities(manifolds, scratch, limits, work.space(manifolds.size(), false));
  }
};

const PackedField& packed_field() {
  static const PackedField field;
  return field;
}

/// One step's contact sweeps on the packed field, timed: the warm start and 10 plain
/// Gauss-Seidel sweeps (the speed benchmark's settings), from the same impulses and velocities
/// each time; in colour order four manifolds at a time with `colour` (coloured_sweeps.hpp), its
/// colours on the pool's threads with `threads`. Returns the contact points.
std::size_t time_contact_sweeps(benchmark::State& state, bool colour = false, bool threads = false) {
  const PackedField& field = packed_field();
  std::vector<Manifold> manifolds = field.manifolds;
  BodyArrays bodies = field.bodies;
  std::size_t points = 0;
  for (const Manifold& m : manifolds) points += static_cast<std::size_t>(m.point_count);
  int sweeps = 0;
  SweepWork work;
  for (auto _ : state) {
    state.PauseTiming();
    manifolds = field.manifolds;
    bodies.velocity = field.bodies.velocity;
    bodies.angular_velocity = field.bodies.angular_velocity;
    state.ResumeTiming();
    sweeps = solve_velocities(manifolds, bodies, field.limits,
                              work.space(manifolds.size(), false, colour ? bodies.inv_mass.size() : 0),
                              {.warm_start = true, .colour = colour, .threads = threads});
    benchmark::DoNotOptimize(bodies.velocity.data());
  }
  state.counters["manifolds"] = static_cast<double>(manifolds.size());
  state.counters["points"] = static_cast<double>(points);
  state.counters["sweeps"] = sweeps;
  state.counters["ns_per_point_sweep"] = benchmark::Counter(static_cast<double>(points) * sweeps,
                                                            benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  return points;
}

/// The sweeps on one thread. ns_per_point_sweep: the cost of one point's local solve.
void BM_ContactSweeps(benchmark::State& state) { time_contact_sweeps(state); }
BENCHMARK(BM_ContactSweeps)->Unit(benchmark::kMicrosecond);

/// The sweeps in colour order, four manifolds at a time (`coloured_sweeps`), on one thread.
void BM_ContactSweepsColoured(benchmark::State& state) { time_contact_sweeps(state, true); }
BENCHMARK(BM_ContactSweepsColoured)->Unit(benchmark::kMicrosecond);

/// The sweeps in colour order with each colour on a pool of state.range(0) threads: the same
/// impulses to the bit, in wall time (on a machine with fewer cores than threads, the threads
/// take turns). The pool is set back to FLOEDEM_THREADS after.
void BM_ContactSweepsColouredThreads(benchmark::State& state) {
  set_thread_pool_size(static_cast<unsigned>(state.range(0)));
  time_contact_sweeps(state, true, true);
  set_thread_pool_size(worker_threads());
}
BENCHMARK(BM_ContactSweepsColouredThreads)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMicrosecond)->UseRealTime();

/// The narrow phase of one step on the packed field: every pair of the broad phase collided
/// (no reuse of last step's manifolds, no separation hints). ns_per_pair: one pair's test.
void BM_NarrowPhase(benchmark::State& state) {
  const PackedField& field = packed_field();
  Manifold m;
  std::size_t contacts = 0;
  for (auto _ : state) {
    contacts = 0;
    for (const PartPair pair : field.pairs) {
      field.collide_pair(pair, m);
      contacts += m.point_count > 0;
    }
    benchmark::DoNotOptimize(contacts);
  }
  state.counters["pairs"] = static_cast<double>(field.pairs.size());
  state.counters["contacts"] = static_cast<double>(contacts);
  state.counters["ns_per_pair"] = benchmark::Counter(static_cast<double>(field.pairs.size()),
                                                     benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_NarrowPhase)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
