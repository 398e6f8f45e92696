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
#include "floedem/engine/registry.hpp"
#include "forcing/forcing.hpp"
#include "io/recorder.hpp"
#include "run/energy_balance.hpp"
#include "run/stepper.hpp"
#include "towing/tow.hpp"
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

/// Test hooks: FLOEDEM_TEST_KILL_AT_STEP=k makes the process kill itself (SIGKILL: no
/// destructor runs, as when a job is killed) right after step k, FLOEDEM_TEST_TERM_AT_STEP=k
/// send itself SIGTERM (a batch system's notice), so that a test of --resume can interrupt a
/// run at a chosen place. 0 when unset.
std::int64_t test_signal_step(const char* name) {
  const char* v = std::getenv(name);
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

namespace {

/// One run of a scene: its parts, and the stages of run_scene (open, the steps, the end).
class SceneRun {
 public:
  SceneRun(const Scene& scene, const RunOptions& options)
      : scene_(scene),
        options_(options),
        stepper_(scene, options.engine),
        tow_(stepper_.tow()),
        loads_(scene),
        collisions_(scene, duration_model_of(stepper_.engine().info())),
        energy_(scene),
        summary_(tally_.summary),
        steps_(scene.run.steps()),
        // Without forcing or towing nothing may add energy: the largest kinetic energy of the
        // run is then a check (recorded, summary_max_kinetic_energy); with forcing it is not,
        // and not computed.
        track_energy_(stepper_.forcing().names().empty() && !tow_.active()) {
    for (const auto name : stepper_.forcing().names()) info_.forcing_terms.emplace_back(name);
    info_.floedem_version = version();
    summary_.engine = options.engine;
  }

  /// A fresh run, or one continued from its checkpoint: every part reads back its state, in
  /// the order of checkpoint() below, and the file is cut back to the rows written by then.
  /// Returns the first step to make.
  std::int64_t open() {
    if (!options_.resume_state) {
      recorder_ = std::make_unique<Recorder>(options_.output, scene_, stepper_.engine().info(), info_);
      summary_.kinetic_energy_start = kinetic_energy(scene_, stepper_.state());
      summary_.max_kinetic_energy = summary_.kinetic_energy_start;
      if (tow_.active()) recorder_->write_tow(0.0, tow_.start_frame());
      write_frame(0.0);
      return 1;
    }
    const std::vector<std::uint8_t>& bytes = *options_.resume_state;
    StateReader in(bytes.data(), bytes.size());
    const std::int64_t at = read_checkpoint_header(in);
    if (at > steps_)
      throw InputError(scene_.source_path + ": run.duration " + setting_text(scene_.run.duration) +
                       " s ends before the checkpoint (t = " + setting_text(static_cast<double>(at) * scene_.run.dt) +
                       " s) that the run continues from");
    const RecordedRows rows = restore_rows(in);
    stepper_.restore(in);
    tally_.restore(in);
    collisions_.restore(in);
    loads_.restore(in);
    energy_.restore(in);
    if (in.left() != 0) throw StateError("checkpoint: more state than this run reads");
    if (stepper_.steps_done() != at) throw StateError("checkpoint: the engine's step count differs from the run's");
    recorder_ = std::make_unique<Recorder>(options_.output, scene_, info_, rows);
    return at + 1;
  }

  /// Step k, and the rows it writes.
  void step(std::int64_t k) {
    Recorder& recorder = *recorder_;
    energy_.before_step(stepper_.state());
    stepper_.step();
    const double t_end = stepper_.time();
    const BodyStates& state = stepper_.state();
    if (!finite_state(state))
      throw SolverFailure("non-finite body state at step " + std::to_string(k) + " (t = " + std::to_string(t_end) +
                          " s); output so far kept in " + recorder.partial_path());
    const auto contacts = stepper_.contacts();
    energy_.after_step(stepper_.last_loads(), state, contacts);
    for (const ContactRecord& c : contacts) {
      ++(c.kind == ContactKind::collision ? summary_.collision_impulses : summary_.resting_impulses);
      if (c.separation < 0.0) {
        summary_.max_penetration = std::max(summary_.max_penetration, -c.separation);
        tally_.overlap_sum -= c.separation;
        ++tally_.overlaps;
      }
    }
    // Stability figures for the stress suite: cheap (one pass over the bodies).
    for (const Vec2 v : state.velocity) summary_.max_speed_seen = std::max(summary_.max_speed_seen, length_squared(v));
    if (track_energy_)
      summary_.max_kinetic_energy = std::max(summary_.max_kinetic_energy, kinetic_energy(scene_, state));
    recorder.write_contacts(t_end, contacts);
    collisions_.observe(t_end, contacts, state, ended_);
    if (!ended_.empty()) record_collisions();
    // Rows on their cadence here; the last step's rows off the cadence after the loop, so
    // that a checkpoint is the same whether the run ends there or goes on (--resume with a
    // longer run.duration).
    if (tow_.active() && k % scene_.tow_every() == 0) recorder.write_tow(t_end, tow_.take_frame(t_end));
    if (loads_.active()) {
      loads_.after_step(contacts);
      if (k % scene_.load_every() == 0) recorder.write_loads(t_end, loads_.take_row());
    }
    if (k % scene_.run.output_every == 0) {
      write_frame(t_end);
      if (checkpoints_ && recorder.frames() % recorder.frame_chunk() == 0) checkpoint(k);
    }
  }

  /// The last rows, the summary, and the file made whole.
  RunSummary finish(std::chrono::steady_clock::time_point start) {
    Recorder& recorder = *recorder_;
    const BodyStates& state = stepper_.state();
    const double t_end = stepper_.time();
    if (tow_.active() && steps_ % scene_.tow_every() != 0) recorder.write_tow(t_end, tow_.take_frame(t_end));
    if (loads_.active() && steps_ % scene_.load_every() != 0) recorder.write_loads(t_end, loads_.take_row());
    if (steps_ % scene_.run.output_every != 0) write_frame(t_end);
    collisions_.finish(state, ended_);
    record_collisions();
    RunSummary& summary = summary_;
    summary.steps = steps_;
    summary.kinetic_energy_end = kinetic_energy(scene_, state);
    summary.max_speed_seen = std::sqrt(summary.max_speed_seen);
    summary.mean_penetration = tally_.overlaps > 0 ? tally_.overlap_sum / static_cast<double>(tally_.overlaps) : 0.0;
    if (!track_energy_) summary.max_kinetic_energy = std::numeric_limits<double>::quiet_NaN();
    for (const Vec2 v : state.velocity) summary.max_speed = std::max(summary.max_speed, length(v));
    summary.work_of_loads = energy_.work_of_loads();
    summary.work_of_paths = energy_.work_of_paths();
    summary.contact_work = energy_.contact_work();
    summary.max_relative_energy_gain = energy_.max_relative_gain();
    summary.frames = recorder.frames();
    summary.contact_rows = recorder.contact_rows();
    summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    recorder.update_engine_info(stepper_.engine().info());
    std::vector<std::pair<std::string, double>> attributes{{"steps", static_cast<double>(summary.steps)},
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
                     {"max_relative_energy_gain", summary.max_relative_energy_gain}};
    if (tow_.active()) {
      const TowOutcome outcome = tow_.outcome(state, t_end);
      for (auto& a : outcome.attributes()) attributes.push_back(std::move(a));
    }
    recorder.finish(attributes);
    // No wall time in the file: two runs of one scene give bit-identical files.
    summary.headline = read_run_headline(options_.output);
    return summary;
  }

 private:
  void write_frame(double time) {
    stepper_.frame_state(frame_);
    recorder_->write_frame(time, frame_);
  }

  void record_collisions() {
    for (const CollisionRow& r : ended_) summary_.max_peak_force = std::max(summary_.max_peak_force, r.peak_force);
    summary_.collision_events += static_cast<std::int64_t>(ended_.size());
    recorder_->write_collisions(ended_);
    ended_.clear();
  }

  // A checkpoint after each full chunk of frames (when the frames are written anyway): the
  // state after step k and the rows written by then. Engines that cannot save their state
  // get none (--resume then runs them again from the start).
  void checkpoint(std::int64_t k) {
    if (!checkpoint_state(k, tally_.checkpoints + 1)) return;
    ++tally_.checkpoints;
    recorder_->write_checkpoint(tally_.checkpoints - 1, k, checkpoint_bytes_.bytes());
  }

 public:
  /// Stopped on request after step k: its state into the stopped run's slot. The regular
  /// checkpoints' count is saved as it is, so a run continued from here writes the regular
  /// checkpoints, in the same slots, that a run never stopped writes. False where the engine
  /// cannot save its state.
  bool checkpoint_on_stop(std::int64_t k) {
    if (!checkpoint_state(k, tally_.checkpoints)) return false;
    recorder_->write_stop_checkpoint(k, checkpoint_bytes_.bytes());
    return true;
  }
  const std::string& partial_path() const { return recorder_->partial_path(); }
  void discard_output() { recorder_->discard(); }

 private:
  /// The state after step k into checkpoint_bytes_, with `count` regular checkpoints written
  /// (what the continued run's tally starts from). False, and no more checkpoints, where the
  /// engine cannot save its state.
  bool checkpoint_state(std::int64_t k, std::int64_t count) {
    if (!checkpoints_) return false;
    StateWriter& out = checkpoint_bytes_;
    out.clear();
    out.tag("floedem checkpoint");
    out.value(kCheckpointFormat);
    out.value(k);
    save_rows(out, recorder_->rows());
    if (!stepper_.save(out)) {
      checkpoints_ = false;
      return false;
    }
    Tally saved = tally_;
    saved.checkpoints = count;
    saved.save(out);
    collisions_.save(out);
    loads_.save(out);
    energy_.save(out);
    return true;
  }

  const Scene& scene_;
  const RunOptions& options_;
  Stepper stepper_;
  RunInfo info_;
  TowMonitor& tow_;
  ContactLoads loads_;
  CollisionTracker collisions_;
  EnergyBalance energy_;
  Tally tally_;
  RunSummary& summary_;
  const std::int64_t steps_;
  const bool track_energy_;
  std::unique_ptr<Recorder> recorder_;
  std::vector<CollisionRow> ended_;
  StateWriter checkpoint_bytes_;
  bool checkpoints_ = true;
  BodyStates frame_;  // the state a frame records (Stepper::frame_state)
};

}  // namespace

RunSummary run_scene(const Scene& scene, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SceneRun run(scene, options);
  const std::int64_t first = run.open();
  const std::int64_t steps = scene.run.steps();
  Progress progress(options.progress, first - 1);
  const std::int64_t kill_at = test_signal_step("FLOEDEM_TEST_KILL_AT_STEP");
  const std::int64_t term_at = test_signal_step("FLOEDEM_TEST_TERM_AT_STEP");
  const std::int64_t int_at = test_signal_step("FLOEDEM_TEST_INT_AT_STEP");
  for (std::int64_t k = first; k <= steps; ++k) {
    try {
      run.step(k);
    } catch (const InputError&) {
      // Bad input that only the first step can find (a forcing grid's fill value or edge under
      // a body's starting place, read where the forcing reads it): refused like any other bad
      // input, with nothing written. Found later, the rows so far stay in the .partial file.
      if (k == 1) run.discard_output();
      throw;
    }
    progress.update(k, steps);
    if (k == kill_at) std::raise(SIGKILL);
    if (k == term_at) std::raise(SIGTERM);
    if (k == int_at) std::raise(SIGINT);
    if (options.stop && k < steps && options.stop->load(std::memory_order_relaxed)) {
      progress.done();
      const bool saved = run.checkpoint_on_stop(k);
      const std::string at = "step " + std::to_string(k) + " (t = " + setting_text(static_cast<double>(k) * scene.run.dt) + " s)";
      throw RunStopped(saved ? "stopped after " + at + "; its checkpoint is in " + run.partial_path() +
                                   ": floedem run --resume " + run.partial_path() + " continues the run from there"
                             : "stopped after " + at + "; the " + options.engine + " engine cannot save its state: " +
                                   run.partial_path() + " holds the rows so far, and floedem run --resume runs it "
                                   "again from t = 0",
                       k, saved);
    }
  }
  progress.done();
  return run.finish(start);
}

void check_scene(const Scene& scene, const std::vector<std::string>& engines) {
  std::unique_ptr<Engine> first;
  for (const std::string& e : engines.empty() ? std::vector<std::string>{"native"} : engines) {
    auto made = make_engine(e, scene);
    if (!first) first = std::move(made);
  }
  Forcing forcing(scene);
  const TowLine line(scene.tow);  // the tug's start and an unparted rope, as a run begins
  forcing.attach_tow(line);
  if (!forcing.empty()) (void)forcing.evaluate(first->state(), 0.0);
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
