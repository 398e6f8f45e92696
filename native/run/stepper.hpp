#pragma once
// One step of a scene on an engine, in the one order every caller needs: towing bookkeeping,
// forcing at the start of the step, the engine's step, the towing force of the step. The
// driver (simulation.cpp) records around it; tests and benchmarks step with it directly.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/engine/step_stages.hpp"
#include "forcing/forcing.hpp"
#include "floedem/scene/scene.hpp"
#include "towing/tow.hpp"

namespace floedem {

class Stepper {
 public:
  /// Builds the named engine (InputError for bad settings) and the scene's forcing.
  Stepper(const Scene& scene, const std::string& engine);

  /// Advances by one dt.
  void step();

  std::int64_t steps_done() const { return steps_; }
  /// Model time after the steps done: k dt, not a running sum (no drift over long runs).
  double time() const { return static_cast<double>(steps_) * dt_; }
  const Engine& engine() const { return *engine_; }
  const BodyStates& state() const { return engine_->state(); }
  /// The state as a frame records it: the engine's positions and angles after the steps done,
  /// with the velocities at that instant (Forcing::velocities_at_step_end; at t = 0 the
  /// scene's own). One copy of the state.
  void frame_state(BodyStates& out) const;
  std::span<const ContactRecord> contacts() const { return engine_->contacts(); }
  const Forcing& forcing() const { return forcing_; }
  /// The loads of the last step (nullptr: none), valid until the next step.
  const Loads* last_loads() const { return loads_; }
  TowMonitor& tow() { return tow_; }
  const TowMonitor& tow() const { return tow_; }

  /// Wall time per stage of the steps from here on (`floedem bench`): the forcing, the
  /// engine's own stages (where it times them), the towing bookkeeping. Off by default.
  void time_stages(bool on);
  /// Each stage's summed wall time since time_stages(true), in the order a step makes them.
  std::vector<StageTime> stage_times() const;

  /// Checkpoint: the step count, the engine's state, the tow's, which bodies touched in the
  /// last step and the forcing's memory of it. False, writing nothing, when the engine cannot
  /// save its state.
  bool save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  const Scene& scene_;
  double dt_;
  std::unique_ptr<Engine> engine_;
  Forcing forcing_;
  TowMonitor tow_;
  std::int64_t steps_ = 0;
  const Loads* loads_ = nullptr;
  std::vector<std::uint8_t> touching_;  ///< per body: a contact in the last step (Forcing::evaluate)
  // The two stages of floedem/engine/step_stages.hpp that the stepper makes around the engine's own.
  enum Stage : std::size_t { kForcing, kTowing, kStages };
  StageClock<kStages> stages_{{kStepStages[step_stage("forcing")].name, kStepStages[step_stage("towing")].name}};
};

}  // namespace floedem
