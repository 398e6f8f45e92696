#pragma once
// Timing a scene on one engine, as `floedem bench` does: the wall time of each step (of the
// whole run, or of a window at its end), with what the steps achieved (contact fraction,
// penetration) and, when the program can count them, their heap allocations. No output file is
// written: the recorder's work is not timed.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/engine/stage_clock.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

struct BenchOptions {
  std::string engine = "native";
  double window = 0.0;   ///< s of model time at the end of the run that are timed; 0: all of it
  bool stages = false;   ///< also time each stage of the timed steps (two clock reads a stage)
  /// Heap allocations of the process so far, when the program counts them (the floedem command
  /// replaces operator new and malloc to do so); empty: allocations are not counted.
  std::function<std::uint64_t()> allocations;
  /// Called every 10 s of wall time with the step reached and the run's steps; empty: silent.
  std::function<void(std::int64_t, std::int64_t)> progress;
};

struct BenchResult {
  std::string engine_version;
  std::int64_t steps = 0, timed_steps = 0;
  std::size_t moving_bodies = 0;
  double median_ms = 0.0, mean_ms = 0.0, p10_ms = 0.0, p90_ms = 0.0;  ///< wall time a timed step
  double setup_seconds = 0.0;   ///< building the engine
  double total_seconds = 0.0;   ///< setup and every step
  double contact_fraction = 0.0;   ///< moving bodies in contact, mean over the timed steps
  double max_penetration = 0.0;    ///< m, deepest overlap at the start of a timed step
  double mean_penetration = 0.0;   ///< m, mean over the overlapping contact points
  double allocations_per_step = 0.0;  ///< NaN when not counted
  std::vector<StageTime> stages;   ///< mean seconds a timed step per stage (BenchOptions::stages)
  std::vector<WorkCount> work;     ///< the engine's work counts, mean a timed step (Engine::add_work_counts)
};

/// Runs the scene without output and times it. InputError for a run shorter than one step or
/// a bad engine, SolverFailure for a non-finite state at the end.
BenchResult bench_scene(const Scene& scene, const BenchOptions& options);

}  // namespace floedem
