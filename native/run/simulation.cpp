#include "run/simulation.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "contacts/contact_loads.hpp"
#include "io/recorder.hpp"
#include "run/stepper.hpp"
#include "version.hpp"

namespace floedem {

double kinetic_energy(const Scene& scene, const BodyStates& state) {
  double e = 0.0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    if (b.fixed) continue;
    e += 0.5 * b.mass * length_squared(state.velocity[i]) +
         0.5 * b.inertia * state.angular_velocity[i] * state.angular_velocity[i];
  }
  return e;
}

namespace {

bool finite_state(const BodyStates& s) {
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    if (!std::isfinite(s.position[i].x) || !std::isfinite(s.position[i].y) || !std::isfinite(s.angle[i]) ||
        !std::isfinite(s.velocity[i].x) || !std::isfinite(s.velocity[i].y) || !std::isfinite(s.angular_velocity[i]))
      return false;
  }
  return true;
}

class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1) {}
  void update(std::int64_t step, std::int64_t steps) {
    if (!enabled_) return;
    const double elapsed = seconds_since(start_);
    if (elapsed < 1.0 || seconds_since(last_) < (tty_ ? 0.2 : 10.0)) return;
    last_ = clock::now();
    const double left = elapsed * static_cast<double>(steps - step) / static_cast<double>(step);
    std::fprintf(stderr, "%sstep %lld/%lld (%3.0f%%), %.1f s elapsed, ~%.1f s left%s", tty_ ? "\r" : "",
                 static_cast<long long>(step), static_cast<long long>(steps),
                 100.0 * static_cast<double>(step) / static_cast<double>(steps), elapsed, left, tty_ ? "" : "\n");
    shown_ = true;
  }
  void done() {
    if (shown_ && tty_) std::fprintf(stderr, "\n");
  }

 private:
  using clock = std::chrono::steady_clock;
  static double seconds_since(clock::time_point t) { return std::chrono::duration<double>(clock::now() - t).count(); }
  bool enabled_, tty_;
  bool shown_ = false;
  clock::time_point start_ = clock::now();
  clock::time_point last_ = clock::now() - std::chrono::hours(1);
};

}  // namespace

RunSummary run_scene(const Scene& scene, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Stepper stepper(scene, options.engine);
  RunInfo info;
  for (const auto name : stepper.forcing().names()) info.forcing_terms.emplace_back(name);
  info.floedem_version = kFloedemVersion;
  Recorder recorder(options.output, scene, stepper.engine().info(), info);

  RunSummary summary;
  summary.engine = options.engine;
  const std::int64_t steps = scene.run.steps();
  summary.kinetic_energy_start = kinetic_energy(scene, stepper.state());
  TowMonitor& tow = stepper.tow();
  ContactLoads loads(scene);
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  if (tow.active()) recorder.write_tow(0.0, {{nan, nan}, {nan, nan}, {nan, nan}, tow.tug_position(0.0)});  // no step yet
  recorder.write_frame(0.0, stepper.state());
  CollisionTracker collisions(scene, duration_model_of(stepper.engine().info()));
  std::vector<CollisionRow> ended;
  auto record_collisions = [&] {
    for (const CollisionRow& r : ended) summary.max_peak_force = std::max(summary.max_peak_force, r.peak_force);
    summary.collision_events += static_cast<std::int64_t>(ended.size());
    recorder.write_collisions(ended);
    ended.clear();
  };
  Progress progress(options.progress);
  double overlap_sum = 0.0;
  std::int64_t overlaps = 0;
  // Without forcing or towing nothing may add energy: the largest kinetic energy of the run is
  // then a check (recorded, summary_max_kinetic_energy); with forcing it is not, and not computed.
  const bool track_energy = stepper.forcing().names().empty() && !tow.active();
  summary.max_kinetic_energy = summary.kinetic_energy_start;
  for (std::int64_t k = 1; k <= steps; ++k) {
    stepper.step();
    const double t_end = stepper.time();
    const BodyStates& state = stepper.state();
    if (!finite_state(state))
      throw SolverFailure("non-finite body state at step " + std::to_string(k) + " (t = " + std::to_string(t_end) +
                          " s); output so far kept in " + recorder.partial_path());
    const auto contacts = stepper.contacts();
    for (const ContactRecord& c : contacts) {
      ++(c.kind == ContactKind::collision ? summary.collision_impulses : summary.resting_impulses);
      if (c.separation < 0.0) {
        summary.max_penetration = std::max(summary.max_penetration, -c.separation);
        overlap_sum -= c.separation;
        ++overlaps;
      }
    }
    // Stability figures for the stress suite: cheap (one pass over the bodies).
    for (const Vec2 v : state.velocity) summary.max_speed_seen = std::max(summary.max_speed_seen, length_squared(v));
    if (track_energy) summary.max_kinetic_energy = std::max(summary.max_kinetic_energy, kinetic_energy(scene, state));
    recorder.write_contacts(t_end, contacts);
    collisions.observe(t_end, contacts, state, ended);
    if (!ended.empty()) record_collisions();
    if (tow.active() && (k % scene.tow_every() == 0 || k == steps)) recorder.write_tow(t_end, tow.take_frame(t_end));
    if (loads.active()) {
      loads.after_step(contacts);
      if (k % scene.load_every() == 0 || k == steps) recorder.write_loads(t_end, loads.take_row());
    }
    if (k % scene.run.output_every == 0 || k == steps) recorder.write_frame(t_end, state);
    progress.update(k, steps);
  }
  progress.done();
  collisions.finish(stepper.state(), ended);
  record_collisions();
  const BodyStates& state = stepper.state();
  summary.steps = steps;
  summary.kinetic_energy_end = kinetic_energy(scene, state);
  summary.max_speed_seen = std::sqrt(summary.max_speed_seen);
  summary.mean_penetration = overlaps > 0 ? overlap_sum / static_cast<double>(overlaps) : 0.0;
  if (!track_energy) summary.max_kinetic_energy = std::numeric_limits<double>::quiet_NaN();
  for (const Vec2 v : state.velocity) summary.max_speed = std::max(summary.max_speed, length(v));
  summary.frames = recorder.frames();
  summary.contact_rows = recorder.contact_rows();
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  recorder.update_engine_info(stepper.engine().info());
  recorder.finish({{"steps", static_cast<double>(summary.steps)},
                   {"kinetic_energy_start", summary.kinetic_energy_start},
                   {"kinetic_energy_end", summary.kinetic_energy_end},
                   {"collision_impulses", static_cast<double>(summary.collision_impulses)},
                   {"resting_impulses", static_cast<double>(summary.resting_impulses)},
                   {"collision_events", static_cast<double>(summary.collision_events)},
                   {"max_peak_force", summary.max_peak_force},
                   {"max_speed", summary.max_speed_seen},
                   {"max_penetration", summary.max_penetration},
                   {"mean_penetration", summary.mean_penetration},
                   {"max_kinetic_energy", summary.max_kinetic_energy}});
  // No wall time in the file: two runs of one scene give bit-identical files.
  return summary;
}

std::string format_summary(const Scene& scene, const RunSummary& s, const std::string& output) {
  std::size_t fixed = 0;
  for (const auto& b : scene.bodies) fixed += b.fixed ? 1 : 0;
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "floedem run: %s on %s\n"
                "  bodies      %zu (%zu fixed)\n"
                "  steps       %lld (dt %g s, %g s of model time), %lld frames recorded\n"
                "  impulses    %lld collision, %lld resting (%lld contact rows recorded)\n"
                "  collisions  %lld events, largest peak force %.4g N\n"
                "  kinetic energy %.6g J -> %.6g J; fastest body %.4g m/s\n"
                "  wall time   %.3f s (%.4f ms per step)\n"
                "  output      %s\n",
                scene.source_path.c_str(), s.engine.c_str(), scene.bodies.size(), fixed,
                static_cast<long long>(s.steps), scene.run.dt, static_cast<double>(s.steps) * scene.run.dt,
                static_cast<long long>(s.frames), static_cast<long long>(s.collision_impulses),
                static_cast<long long>(s.resting_impulses), static_cast<long long>(s.contact_rows),
                static_cast<long long>(s.collision_events), s.max_peak_force,
                s.kinetic_energy_start, s.kinetic_energy_end, s.max_speed, s.wall_seconds,
                1e3 * s.wall_seconds / static_cast<double>(std::max<std::int64_t>(s.steps, 1)), output.c_str());
  return buf;
}

}  // namespace floedem
