// Micro-benchmarks of the hot loops (Google Benchmark). Not tests: run them with
//   build/floedem_bench --benchmark_out=reports/bench/$(hostname).csv --benchmark_out_format=csv
// (the `bench` target does this).
#include <benchmark/benchmark.h>

#include <random>

#include "engine/registry.hpp"
#include "field/field_generator.hpp"
#include "forcing/drag.hpp"
#include "forcing/force_term.hpp"
#include "geometry/polygon.hpp"
#include "scenario/scenario.hpp"
#include "solver/broad_phase.hpp"

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
/// drifting and turning in a current, water form and skin drag. Arg(1): the terms' packed
/// quadrature (drag.cpp); Arg(0): the point-by-point rule it reproduces to the bit, over point
/// lists made once per floe (as the terms held them before they were packed).
void BM_DragQuadrature(benchmark::State& state) {
  const bool packed = state.range(0) != 0;
  const int n = 1000;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  EnvironmentSpec env;
  DistributedDrag form("form", DistributedDrag::Kind::form, env), skin("skin", DistributedDrag::Kind::skin, env);
  std::vector<std::vector<EdgePoint>> edges;  // the rule's points, made once as the terms' were
  std::vector<std::vector<AreaPoint>> points;
  BodyStates s;
  s.resize(n);
  ForceSums sums;
  sums.q.assign(n, {});
  sums.dq.assign(n, {});
  sums.rotation_rate.assign(n, 0.0);
  sums.jacobian.assign(n, 0);  // floes of a field: never stiff, Q alone
  sums.rate_bound.assign(n, {});
  const Vec2 current{0.3, 0.1};
  for (int i = 0; i < n; ++i) {
    const int corners = 5 + i % 5;
    const double size = 2.5 + 12.5 * (1.0 + u(rng)) / 2.0;
    std::vector<Vec2> poly;
    for (int k = 0; k < corners; ++k) {
      const double a = 2.0 * M_PI * (k + 0.3 * u(rng)) / corners;
      poly.push_back({size * std::cos(a), size * std::sin(a)});
    }
    const Vec2 c = area_moments(poly).centroid;
    for (Vec2& p : poly) p = p - c;
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
BENCHMARK(BM_DragQuadrature)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

/// Field generation (issue 4's targets: 1e4 floes under 2 s, 1e5 under 20 s on 2 cores):
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

}  // namespace

BENCHMARK_MAIN();
