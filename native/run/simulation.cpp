#include "floedem/run/simulation.hpp"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <sstream>

#include "contacts/contact_loads.hpp"
#include "io/recorder.hpp"
#include "run/energy_balance.hpp"
#include "run/stepper.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/version.hpp"

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
  Progress(bool enabled, std::int64_t first_step)
      : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1), first_(first_step) {}
  void update(std::int64_t step, std::int64_t steps) {
    if (!enabled_) return;
    const double elapsed = seconds_since(start_);
    if (elapsed < 1.0 || seconds_since(last_) < (tty_ ? 0.2 : 10.0)) return;
    last_ = clock::now();
    const double left = elapsed * static_cast<double>(steps - step) / static_cast<double>(step - first_);
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
  std::int64_t first_;
  bool shown_ = false;
  clock::time_point start_ = clock::now();
  clock::time_point last_ = clock::now() - std::chrono::hours(1);
};

/// A test hook: FLOEDEM_TEST_KILL_AT_STEP=k makes the process kill itself (SIGKILL: no
/// destructor runs, as when a job is killed) right after step k, so that a test of --resume
/// can interrupt a run at a chosen place. 0 when unset.
std::int64_t kill_at_step() {
  const char* v = std::getenv("FLOEDEM_TEST_KILL_AT_STEP");
  return v ? std::strtoll(v, nullptr, 10) : 0;
}

/// The checkpoint's layout; a file written with another one is refused on --resume.
constexpr std::uint32_t kCheckpointFormat = 4;

/// The driver's running figures: what run_scene carries from step to step besides the
/// engine, the tow, the collision tracker and the contact loads.
struct Tally {
  RunSummary summary;
  double overlap_sum = 0.0;
  std::int64_t overlaps = 0;
  std::int64_t checkpoints = 0;

  void save(StateWriter& out) const {
    out.tag("tally");
    for (const std::int64_t v : {summary.collision_impulses, summary.resting_impulses, summary.collision_events, overlaps,
                                 checkpoints})
      out.value(v);
    for (const double v : {summary.max_peak_force, summary.kinetic_energy_start, summary.max_speed_seen,
                           summary.max_penetration, summary.max_kinetic_energy, overlap_sum})
      out.value(v);
  }
  void restore(StateReader& in) {
    in.tag("tally");
    for (std::int64_t* v : {&summary.collision_impulses, &summary.resting_impulses, &summary.collision_events, &overlaps,
                            &checkpoints})
      in.value(*v);
    for (double* v : {&summary.max_peak_force, &summary.kinetic_energy_start, &summary.max_speed_seen,
                      &summary.max_penetration, &summary.max_kinetic_energy, &overlap_sum})
      in.value(*v);
  }
};

void save_rows(StateWriter& out, const RecordedRows& r) {
  out.tag("rows");
  for (const std::int64_t v : {r.frames, r.contacts, r.collisions, r.tow, r.loads}) out.value(v);
}

RecordedRows restore_rows(StateReader& in) {
  RecordedRows r;
  in.tag("rows");
  for (std::int64_t* v : {&r.frames, &r.contacts, &r.collisions, &r.tow, &r.loads}) in.value(*v);
  return r;
}

/// Reads a checkpoint's header: its layout (StateError when not this floedem's) and its step.
std::int64_t read_checkpoint_header(StateReader& in) {
  in.tag("floedem checkpoint");
  if (in.value<std::uint32_t>() != kCheckpointFormat)
    throw StateError("checkpoint written by a floedem with another checkpoint layout");
  return in.value<std::int64_t>();
}

}  // namespace

RunSummary run_scene(const Scene& scene, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Stepper stepper(scene, options.engine);
  RunInfo info;
  for (const auto name : stepper.forcing().names()) info.forcing_terms.emplace_back(name);
  info.floedem_version = version();
  TowMonitor& tow = stepper.tow();
  ContactLoads loads(scene);
  CollisionTracker collisions(scene, duration_model_of(stepper.engine().info()));
  EnergyBalance energy(scene);
  Tally tally;
  RunSummary& summary = tally.summary;
  summary.engine = options.engine;
  const std::int64_t steps = scene.run.steps();

  // A fresh run, or one continued from its checkpoint: every part reads back its state, in
  // the order of checkpoint() below, and the file is cut back to the rows written by then.
  std::int64_t first = 1;
  std::unique_ptr<Recorder> recorder_owner;
  if (options.resume_state) {
    const std::vector<std::uint8_t>& bytes = *options.resume_state;
    StateReader in(bytes.data(), bytes.size());
    const std::int64_t at = read_checkpoint_header(in);
    if (at > steps)
      throw InputError(scene.source_path + ": run.duration " + setting_text(scene.run.duration) +
                       " s ends before the checkpoint (t = " + setting_text(static_cast<double>(at) * scene.run.dt) +
                       " s) that the run continues from");
    const RecordedRows rows = restore_rows(in);
    stepper.restore(in);
    tally.restore(in);
    collisions.restore(in);
    loads.restore(in);
    energy.restore(in);
    if (in.left() != 0) throw StateError("checkpoint: more state than this run reads");
    if (stepper.steps_done() != at) throw StateError("checkpoint: the engine's step count differs from the run's");
    first = at + 1;
    recorder_owner = std::make_unique<Recorder>(options.output, scene, info, rows);
  } else {
    recorder_owner = std::make_unique<Recorder>(options.output, scene, stepper.engine().info(), info);
    summary.kinetic_energy_start = kinetic_energy(scene, stepper.state());
    summary.max_kinetic_energy = summary.kinetic_energy_start;
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    if (tow.active()) recorder_owner->write_tow(0.0, {{nan, nan}, {nan, nan}, {nan, nan}, tow.tug_position(0.0)});  // no step yet
    recorder_owner->write_frame(0.0, stepper.state());
  }
  Recorder& recorder = *recorder_owner;

  std::vector<CollisionRow> ended;
  auto record_collisions = [&] {
    for (const CollisionRow& r : ended) summary.max_peak_force = std::max(summary.max_peak_force, r.peak_force);
    summary.collision_events += static_cast<std::int64_t>(ended.size());
    recorder.write_collisions(ended);
    ended.clear();
  };
  // A checkpoint after each full chunk of frames (when the frames are written anyway): the
  // state after step k and the rows written by then. Engines that cannot save their state
  // get none (--resume then runs them again from the start).
  StateWriter checkpoint_bytes;
  bool checkpoints = true;
  auto checkpoint = [&](std::int64_t k) {
    StateWriter& out = checkpoint_bytes;
    out.clear();
    out.tag("floedem checkpoint");
    out.value(kCheckpointFormat);
    out.value(k);
    save_rows(out, recorder.rows());
    if (!stepper.save(out)) {
      checkpoints = false;
      return;
    }
    ++tally.checkpoints;
    tally.save(out);
    collisions.save(out);
    loads.save(out);
    energy.save(out);
    recorder.write_checkpoint(tally.checkpoints - 1, k, out.bytes());
  };
  Progress progress(options.progress, first - 1);
  // Without forcing or towing nothing may add energy: the largest kinetic energy of the run is
  // then a check (recorded, summary_max_kinetic_energy); with forcing it is not, and not computed.
  const bool track_energy = stepper.forcing().names().empty() && !tow.active();
  const std::int64_t kill_at = kill_at_step();
  for (std::int64_t k = first; k <= steps; ++k) {
    energy.before_step(stepper.state());
    stepper.step();
    const double t_end = stepper.time();
    const BodyStates& state = stepper.state();
    if (!finite_state(state))
      throw SolverFailure("non-finite body state at step " + std::to_string(k) + " (t = " + std::to_string(t_end) +
                          " s); output so far kept in " + recorder.partial_path());
    const auto contacts = stepper.contacts();
    energy.after_step(stepper.last_loads(), state, contacts);
    for (const ContactRecord& c : contacts) {
      ++(c.kind == ContactKind::collision ? summary.collision_impulses : summary.resting_impulses);
      if (c.separation < 0.0) {
        summary.max_penetration = std::max(summary.max_penetration, -c.separation);
        tally.overlap_sum -= c.separation;
        ++tally.overlaps;
      }
    }
    // Stability figures for the stress suite: cheap (one pass over the bodies).
    for (const Vec2 v : state.velocity) summary.max_speed_seen = std::max(summary.max_speed_seen, length_squared(v));
    if (track_energy) summary.max_kinetic_energy = std::max(summary.max_kinetic_energy, kinetic_energy(scene, state));
    recorder.write_contacts(t_end, contacts);
    collisions.observe(t_end, contacts, state, ended);
    if (!ended.empty()) record_collisions();
    // Rows on their cadence here; the last step's rows off the cadence after the loop, so
    // that a checkpoint is the same whether the run ends there or goes on (--resume with a
    // longer run.duration).
    if (tow.active() && k % scene.tow_every() == 0) recorder.write_tow(t_end, tow.take_frame(t_end));
    if (loads.active()) {
      loads.after_step(contacts);
      if (k % scene.load_every() == 0) recorder.write_loads(t_end, loads.take_row());
    }
    if (k % scene.run.output_every == 0) {
      recorder.write_frame(t_end, state);
      if (checkpoints && recorder.frames() % recorder.frame_chunk() == 0) checkpoint(k);
    }
    progress.update(k, steps);
    if (k == kill_at) std::raise(SIGKILL);
  }
  progress.done();
  const BodyStates& state = stepper.state();
  const double t_end = stepper.time();
  if (tow.active() && steps % scene.tow_every() != 0) recorder.write_tow(t_end, tow.take_frame(t_end));
  if (loads.active() && steps % scene.load_every() != 0) recorder.write_loads(t_end, loads.take_row());
  if (steps % scene.run.output_every != 0) recorder.write_frame(t_end, state);
  collisions.finish(state, ended);
  record_collisions();
  summary.steps = steps;
  summary.kinetic_energy_end = kinetic_energy(scene, state);
  summary.max_speed_seen = std::sqrt(summary.max_speed_seen);
  summary.mean_penetration = tally.overlaps > 0 ? tally.overlap_sum / static_cast<double>(tally.overlaps) : 0.0;
  if (!track_energy) summary.max_kinetic_energy = std::numeric_limits<double>::quiet_NaN();
  for (const Vec2 v : state.velocity) summary.max_speed = std::max(summary.max_speed, length(v));
  summary.work_of_loads = energy.work_of_loads();
  summary.work_of_paths = energy.work_of_paths();
  summary.contact_work = energy.contact_work();
  summary.max_relative_energy_gain = energy.max_relative_gain();
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
                   {"max_kinetic_energy", summary.max_kinetic_energy},
                   {"work_of_loads", summary.work_of_loads},
                   {"work_of_paths", summary.work_of_paths},
                   {"contact_work", summary.contact_work},
                   {"max_relative_energy_gain", summary.max_relative_energy_gain}});
  // No wall time in the file: two runs of one scene give bit-identical files.
  summary.headline = read_run_headline(options.output);
  return summary;
}

std::string format_summary(const Scene& scene, const RunSummary& s, const std::string& output) {
  std::size_t fixed = 0;
  for (const auto& b : scene.bodies) fixed += b.fixed ? 1 : 0;
  char head[1024], tail[1024];
  std::snprintf(head, sizeof head,
                "floedem run: %s on %s\n"
                "  bodies      %zu (%zu fixed)\n"
                "  steps       %lld (dt %g s, %g s of model time), %lld frames recorded\n"
                "  impulses    %lld collision, %lld resting (%lld contact rows recorded)\n"
                "  collisions  %lld events\n",
                scene.source_path.c_str(), s.engine.c_str(), scene.bodies.size(), fixed,
                static_cast<long long>(s.steps), scene.run.dt, static_cast<double>(s.steps) * scene.run.dt,
                static_cast<long long>(s.frames), static_cast<long long>(s.collision_impulses),
                static_cast<long long>(s.resting_impulses), static_cast<long long>(s.contact_rows),
                static_cast<long long>(s.collision_events));
  std::snprintf(tail, sizeof tail,
                "  kinetic energy %.6g J -> %.6g J; fastest body %.4g m/s\n"
                "  wall time   %.3f s (%.4f ms per step)\n"
                "  output      %s\n",
                s.kinetic_energy_start, s.kinetic_energy_end, s.max_speed, s.wall_seconds,
                1e3 * s.wall_seconds / static_cast<double>(std::max<std::int64_t>(s.steps, 1)), output.c_str());
  // The headline figures (the tow, the loads, the largest collision) between the counts and the cost.
  return head + format_run_headline(s.headline) + tail;
}

}  // namespace floedem
