#pragma once
// The driver: Scene -> Engine -> Recorder, one way. Forcing is evaluated from the engine's
// state and handed to the engine each step; the recorder sees each step's contacts and every
// output_every-th state.
#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "floedem/io/run_headline.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

/// The solver produced a non-finite state. Exit code 4.
class SolverFailure : public std::runtime_error {
 public:
  explicit SolverFailure(const std::string& m) : std::runtime_error(m) {}
};

struct RunOptions {
  std::string engine = "native";
  std::string output;          ///< RESULT.h5
  bool progress = false;       ///< progress line on stderr for runs longer than a second
  /// Continue from this checkpoint (read_stored_run) instead of starting: output must be the
  /// run's file, which is cut back to the checkpoint and extended (resume.hpp).
  const std::vector<std::uint8_t>* resume_state = nullptr;
  /// Checked after every step but the last: once true, the run writes a checkpoint of the step
  /// it has just made (where the engine can save its state) and throws RunStopped, leaving
  /// RESULT.h5.partial to continue with --resume. `floedem run` sets it on SIGTERM and SIGINT:
  /// a batch system's notice that the job is about to be killed costs no finished step.
  const std::atomic<bool>* stop = nullptr;
};

/// A run stopped on request (RunOptions::stop). Exit code 128 + the signal's number.
class RunStopped : public std::runtime_error {
 public:
  RunStopped(const std::string& m, std::int64_t last_step, bool saved)
      : std::runtime_error(m), step(last_step), checkpointed(saved) {}
  std::int64_t step;  ///< the last step made
  bool checkpointed;  ///< a checkpoint of that step was written (false: the engine cannot save its state)
};

struct RunSummary {
  std::string engine;
  std::int64_t steps = 0;
  std::int64_t frames = 0;
  std::int64_t collision_impulses = 0;
  std::int64_t resting_impulses = 0;
  std::int64_t contact_rows = 0;
  std::int64_t collision_events = 0;  ///< rows of /contacts/collisions
  double max_peak_force = 0.0;        ///< N, largest estimated collision peak force
  double kinetic_energy_start = 0.0;  ///< J, translational + rotational, moving bodies
  double kinetic_energy_end = 0.0;
  double max_speed = 0.0;             ///< m/s, largest centroid speed at the end
  double max_speed_seen = 0.0;        ///< m/s, largest centroid speed after any step
  double max_penetration = 0.0;       ///< m, deepest overlap at the start of a step, any contact
  double mean_penetration = 0.0;      ///< m, mean overlap over the contact points that overlap
  double max_kinetic_energy = 0.0;    ///< J, largest kinetic energy after any step
  // Energy balance of the moving bodies (run/energy_balance.hpp), J: the work of the
  // non-contact loads, of bodies on a prescribed path through contacts, and the contacts' own
  // (<= 0); the largest relative gain of a step (0 for a sound solver, up to rounding).
  double work_of_loads = 0.0;
  double work_of_paths = 0.0;
  double contact_work = 0.0;
  double max_relative_energy_gain = 0.0;
  double wall_seconds = 0.0;
  RunHeadline headline;  ///< read back from the finished file: tow, loads, largest collision
};

/// Runs the scene and writes its output; throws InputError (bad engine settings, before any
/// file is made), OutputError, SolverFailure.
RunSummary run_scene(const Scene& scene, const RunOptions& options);

/// What a run finds before its first step, found without running it (`floedem check`): the
/// scene built on each engine (InputError for engine settings out of range) and the forcing
/// read at t = 0 on the first engine's starting state with the tow line as a run begins, as the
/// first step reads it (InputError for a grid's fill value or edge under a body's starting
/// place). Writes nothing. `engines` empty: native.
void check_scene(const Scene& scene, const std::vector<std::string>& engines = {});

/// Multi-line human summary.
std::string format_summary(const Scene& scene, const RunSummary& s, const std::string& output);

/// Translational plus rotational kinetic energy of the moving bodies.
double kinetic_energy(const Scene& scene, const struct BodyStates& state);

}  // namespace floedem
