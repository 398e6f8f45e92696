#include "floedem/run/bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "floedem/run/simulation.hpp"
#include "floedem/scene/input_error.hpp"
#include "run/stepper.hpp"

namespace floedem {

namespace {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  const auto k = static_cast<std::size_t>(std::clamp(p, 0.0, 1.0) * static_cast<double>(v.size() - 1) + 0.5);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

BenchResult bench_scene(const Scene& scene, const BenchOptions& options) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  Stepper stepper(scene, options.engine);
  BenchResult r;
  r.setup_seconds = std::chrono::duration<double>(clock::now() - start).count();
  r.engine_version = stepper.engine().info().version;

  r.steps = scene.run.steps();
  if (r.steps < 1)
    throw InputError(scene.source_path + ": run.duration is shorter than one step of run.dt: nothing to time");
  r.timed_steps = options.window > 0.0 ? std::clamp<std::int64_t>(std::llround(options.window / scene.run.dt), 1, r.steps)
                                       : r.steps;
  const std::int64_t first_timed = r.steps - r.timed_steps + 1;
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(r.timed_steps));
  for (const BodySpec& b : scene.bodies) r.moving_bodies += b.fixed ? 0 : 1;
  std::vector<std::uint8_t> touched(scene.bodies.size());
  double contact_fraction_sum = 0.0, penetration_sum = 0.0;
  std::int64_t overlaps = 0;
  std::uint64_t allocations_at_window = 0;
  std::vector<WorkCount> work_at_window;
  auto last_progress = clock::now();
  for (std::int64_t k = 1; k <= r.steps; ++k) {
    if (k == first_timed) {
      stepper.engine().add_work_counts(work_at_window);  // before the count: its strings are not a step's
      if (options.allocations) allocations_at_window = options.allocations();
      stepper.time_stages(options.stages);  // the stages' sums cover the timed steps alone
    }
    const auto t0 = clock::now();
    stepper.step();
    const auto t1 = clock::now();
    if (k < first_timed) continue;
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    // What the timed steps achieved (outside the timing; no allocation: `touched` is reused).
    std::fill(touched.begin(), touched.end(), 0);
    for (const ContactRecord& c : stepper.contacts()) {
      touched[static_cast<std::size_t>(c.body_a)] = touched[static_cast<std::size_t>(c.body_b)] = 1;
      if (c.separation < 0.0) {
        r.max_penetration = std::max(r.max_penetration, -c.separation);
        penetration_sum -= c.separation;
        ++overlaps;
      }
    }
    std::size_t in_contact = 0;
    for (std::size_t i = 0; i < touched.size(); ++i) in_contact += touched[i] && !scene.bodies[i].fixed;
    contact_fraction_sum +=
        r.moving_bodies > 0 ? static_cast<double>(in_contact) / static_cast<double>(r.moving_bodies) : 0.0;
    if (options.progress && std::chrono::duration<double>(t1 - last_progress).count() > 10.0) {
      last_progress = t1;
      options.progress(k, r.steps);
    }
  }
  const auto timed = static_cast<double>(r.timed_steps);
  r.allocations_per_step =
      options.allocations ? static_cast<double>(options.allocations() - allocations_at_window) / timed : std::nan("");
  if (options.stages)
    for (StageTime t : stepper.stage_times()) {
      t.seconds /= timed;
      r.stages.push_back(t);
    }
  stepper.engine().add_work_counts(r.work);
  for (std::size_t i = 0; i < r.work.size() && i < work_at_window.size(); ++i)
    r.work[i].count = (r.work[i].count - work_at_window[i].count) / timed;
  for (const Vec2 p : stepper.state().position)
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) throw SolverFailure("non-finite body state at the end of the run");
  r.total_seconds = std::chrono::duration<double>(clock::now() - start).count();
  for (const double x : ms) r.mean_ms += x;
  r.mean_ms /= static_cast<double>(std::max<std::size_t>(ms.size(), 1));
  r.median_ms = percentile(ms, 0.5);
  r.p10_ms = percentile(ms, 0.1);
  r.p90_ms = percentile(ms, 0.9);
  r.contact_fraction = contact_fraction_sum / timed;
  r.mean_penetration = overlaps > 0 ? penetration_sum / static_cast<double>(overlaps) : 0.0;
  return r;
}

}  // namespace floedem
