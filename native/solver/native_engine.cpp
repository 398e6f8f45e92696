// The native planar non-smooth DEM: a short sequencer over the stages of one step. It runs the
// stages of floedem/engine/step_stages.hpp from broad_phase to sleep, in that list's order,
// each on the one StepContext (step_context.hpp); docs/architecture.md says what each reads
// and writes, and which file holds it.
#include "solver/native_engine.hpp"

#include <vector>

#include "floedem/engine/step_stages.hpp"
#include "solver/contact_pipeline.hpp"
#include "solver/contact_solver.hpp"
#include "solver/island_stage.hpp"
#include "solver/redetection.hpp"
#include "solver/sleep_sets.hpp"
#include "solver/step_context.hpp"

namespace floedem {

namespace {

class NativeEngine final : public Engine {
 public:
  explicit NativeEngine(const Scene& scene)
      : ctx_(scene), pipeline_(ctx_), islands_(scene, ctx_), redetection_(ctx_), sleep_(ctx_) {}
  void step(const Loads* loads) override;
  const BodyStates& state() const override { return ctx_.bodies; }
  std::span<const Rot> rotations() const override { return ctx_.bodies.rotation; }
  std::span<const ContactRecord> contacts() const override { return pipeline_.records(); }
  EngineInfo info() const override;
  void time_stages(bool on) override { stages_.enable(on); }
  void add_stage_times(std::vector<StageTime>& out) const override { stages_.add_to(out); }
  // sweeps: each step's longest island's velocity sweeps (the step's critical path on any
  // number of threads); islands: the islands solved; redetections: the steps solved again;
  // position_sweeps: the projection's sweeps (counted since the engine was made, so a resumed
  // run's count starts at its checkpoint).
  void add_work_counts(std::vector<WorkCount>& out) const override {
    out.push_back({"sweeps", static_cast<double>(islands_.total_sweeps())});
    out.push_back({"position_sweeps", static_cast<double>(projection_.sweeps)});
    out.push_back({"islands", static_cast<double>(islands_.total_islands())});
    out.push_back({"redetections", static_cast<double>(redetection_.count())});
    // The narrow phase's pairs, and those whose manifold was carried over from the step before
    // (neither body moved). They count what this process's caches saved, as its wall time
    // does, so they are not a run's figures: a run continued from a checkpoint starts with
    // empty caches and would record others. Since the engine was made; `floedem bench`.
    out.push_back({"narrow_pairs", static_cast<double>(pipeline_.narrow_pairs())});
    out.push_back({"narrow_reused", static_cast<double>(pipeline_.narrow_reused())});
  }
  bool save_state(StateWriter& out) const override;
  void restore_state(StateReader& in) override;

 private:
  void apply_loads(const Loads& loads);
  void integrate();

  // Wall time per stage of step(), when asked for (floedem bench): the stages of
  // floedem/engine/step_stages.hpp from broad_phase to sleep, in step()'s order.
  enum Stage : std::size_t {
    kBroad, kNarrow, kContactList, kLoads, kSolve, kRedetect, kIntegrate, kProject, kRecord, kSleep, kStages
  };
  static_assert(step_stage("sleep") - step_stage("broad_phase") + 1 == kStages);
  static constexpr int kMaxWakePasses = 8;  // a woken group's reach meeting the next sleeping group, and so on

  StepContext ctx_;
  ContactPipeline pipeline_;
  IslandStage islands_;
  Redetection redetection_;
  SleepSets sleep_;
  ProjectionWork projection_;  // the position projection's stamps (what moved since measured)
  StageClock<kStages> stages_{step_stage_names<kStages>(step_stage("broad_phase"))};
};

EngineInfo NativeEngine::info() const {
  const NativeSettings& s = ctx_.settings;
  const double steps = static_cast<double>(ctx_.step);
  auto per_step = [&](std::int64_t count) { return setting_text(steps > 0 ? static_cast<double>(count) / steps : 0.0); };
  EngineInfo i;
  i.name = "native";
  i.version = "floedem";
  i.settings = {
      {"velocity_iterations", std::to_string(s.velocity_iterations)},
      {"extra_iterations", std::to_string(s.extra_iterations)},
      {"accelerate", s.accelerate ? "true" : "false"},
      {"coloured_from", std::to_string(s.coloured_from)},
      {"large_island_manifolds", std::to_string(s.large_island_manifolds)},
      {"large_island_iterations", std::to_string(s.large_island_iterations)},
      {"tolerance", setting_text(s.tolerance)},
      {"warm_start", s.warm_start ? "true" : "false"},
      {"position_iterations", std::to_string(s.position_iterations)},
      {"position_correction", setting_text(s.position_correction)},
      {"allowed_penetration", setting_text(s.allowed_penetration)},
      {"max_correction", setting_text(s.max_correction)},
      {"redetect", s.redetect ? "true" : "false"},
      {"direct_solve", s.direct_solve ? "true" : "false"},
      {"direct_solve_mass_ratio", setting_text(s.direct_solve_mass_ratio)},
      {"sleep", s.sleep ? "true" : "false"},
      {"sleep_speed", setting_text(s.sleep_speed)},
      {"sleep_time", setting_text(s.sleep_time)},
      {"mean_bodies_asleep", per_step(sleep_.asleep_steps())},
      {"sleeping_groups_woken", std::to_string(sleep_.wakes())},
      {"direct_solves", std::to_string(islands_.direct_solves())},
      {"direct_solves_reverted", std::to_string(islands_.direct_reverted())},
      {"mean_sweeps_per_step", per_step(islands_.total_sweeps())},
      {"mean_islands_per_step", per_step(islands_.total_islands())},
      {"cold_restarts", std::to_string(islands_.cold_restarts())},
      {"redetections", std::to_string(redetection_.count())},
      {"broad_phase_rebuilds", std::to_string(pipeline_.pair_cache().rebuilds())},
      {"broad_phase_refreshed_parts", std::to_string(pipeline_.pair_cache().refreshed_parts())},
  };
  return i;
}

bool NativeEngine::save_state(StateWriter& out) const {
  // What the next steps read: the bodies (the rotation too, so that no sin/cos is redone),
  // last step's contacts (warm start and persistence: pair, feature id, impulses, kind), the
  // broad phase's cache, the counts info() reports and the sleeping sets. Everything else is
  // rebuilt from these (placed parts, boxes, reach) or is scratch.
  const BodyArrays& b = ctx_.bodies;
  out.tag("native");
  out.vector(b.position);
  out.vector(b.angle);
  out.vector(b.rotation);
  out.vector(b.velocity);
  out.vector(b.angular_velocity);
  pipeline_.save_contacts(out);
  out.value(islands_.total_sweeps());
  out.value(ctx_.step);
  out.value(islands_.cold_restarts());
  out.value(redetection_.count());
  out.value(islands_.direct_solves());
  out.value(islands_.direct_reverted());
  out.value(islands_.total_islands());
  // Where the layout held the narrow phase's counts, now the process's own (add_work_counts):
  // zeros, so that checkpoints of earlier builds, which hold them, are read as before.
  out.value(std::int64_t{0});
  out.value(std::int64_t{0});
  sleep_.save(out);
  return true;
}

void NativeEngine::restore_state(StateReader& in) {
  BodyArrays& b = ctx_.bodies;
  const std::size_t n = b.position.size();
  in.tag("native");
  in.vector(b.position, n, "body positions");
  in.vector(b.angle, n, "body angles");
  in.vector(b.rotation, n, "body rotations");
  in.vector(b.velocity, n, "body velocities");
  in.vector(b.angular_velocity, n, "body angular velocities");
  pipeline_.restore_contacts(in, ctx_);
  std::int64_t sweeps = 0, cold = 0, redetections = 0, direct = 0, reverted = 0, islands = 0;
  in.value(sweeps);
  in.value(ctx_.step);
  in.value(cold);
  in.value(redetections);
  in.value(direct);
  in.value(reverted);
  in.value(islands);
  islands_.restore_counts(sweeps, islands, cold, direct, reverted);
  redetection_.restore_count(redetections);
  std::int64_t unused = 0;  // the narrow phase's counts of earlier builds (save_state)
  in.value(unused);
  in.value(unused);
  sleep_.restore(in, ctx_);  // after the step count: a sleeper's time asleep counts from it
}

void NativeEngine::step(const Loads* loads) {
  if (loads) {
    for (const PrescribedMotion& p : loads->prescribed) {
      ctx_.bodies.velocity[p.body] = p.velocity;
      ctx_.bodies.angular_velocity[p.body] = p.angular_velocity;
    }
    if (!loads->any && loads->velocity_turn.empty()) loads = nullptr;  // nothing to add: skip the pass
  }
  ctx_.loads = loads && loads->any ? loads : nullptr;
  ctx_.loads_applied = false;
  // A sleeping group whose loads changed wakes (before the reaches: it moves this step).
  if (sleep_.any_asleep()) stages_.time(kSleep, [&] { sleep_.wake_on_loads(ctx_); });
  // Pairs (a velocity turn keeps the speed).
  stages_.time(kBroad, [&] {
    sleep_.settle(ctx_);
    pipeline_.find_pairs(ctx_);
  });
  // Manifolds, classified on the velocities before the step; a sleeping group that an awake
  // body reaches wakes, and the pairs are found again with its reach.
  stages_.time(kNarrow, [&] {
    pipeline_.collide_pairs(ctx_, /*redetection=*/false);
    bool grew = false;
    for (int pass = 0; sleep_.any_asleep() && pass < kMaxWakePasses &&
                       sleep_.wake_touched(ctx_, pipeline_.pairs(), pipeline_.pair_points(), &grew) && grew;
         ++pass) {
      grew = false;
      pipeline_.pair_up(ctx_);
      pipeline_.collide_pairs(ctx_, /*redetection=*/false);
    }
  });
  stages_.time(kContactList, [&] { pipeline_.build_contact_list(ctx_); });
  if (loads) stages_.time(kLoads, [&] { apply_loads(*loads); });  // non-contact forces
  ctx_.loads_applied = true;
  LineVector<Manifold>& manifolds = pipeline_.manifolds();
  if (!manifolds.empty()) {
    stages_.time(kSolve, [&] { islands_.solve(ctx_, pipeline_.manifolds()); });
    stages_.time(kRedetect, [&] { redetection_.run(ctx_, pipeline_, islands_, sleep_); });
  }
  stages_.time(kIntegrate, [&] { integrate(); });
  if (ctx_.settings.position_iterations > 0 && !manifolds.empty())  // drift correction, positions only
    stages_.time(kProject, [&] { solve_positions(pipeline_.manifolds(), ctx_.bodies, ctx_.settings, projection_); });
  stages_.time(kRecord, [&] { pipeline_.record(); });
  if (ctx_.settings.sleep)
    stages_.time(kSleep, [&] { sleep_.fall_asleep(ctx_, islands_.islands(), pipeline_.manifolds(), !manifolds.empty()); });
  sleep_.count_step();
  ++ctx_.step;
}

void NativeEngine::apply_loads(const Loads& loads) {
  // A settled sleeper is left out: its velocity is zero, turned or pushed through its zero
  // inverse mass it stays zero.
  BodyArrays& s = ctx_.bodies;
  if (!loads.velocity_turn.empty())
    ctx_.for_active_bodies(StepContext::kSerial,
                           [&](std::size_t i) { s.velocity[i] = loads.velocity_turn[i].apply(s.velocity[i]); });
  if (!loads.any) return;
  const double dt = ctx_.dt;
  ctx_.for_active_bodies(8192, [&](std::size_t i) {
    s.velocity[i] += (dt * s.inv_mass[i]) * loads.force[i];
    s.angular_velocity[i] += dt * s.inv_inertia[i] * loads.torque[i];
  });
}

void NativeEngine::integrate() {
  // Symplectic Euler: x += dt v, angle += dt w, with the velocities after the contact impulses.
  BodyArrays& s = ctx_.bodies;
  const double dt = ctx_.dt;
  ctx_.for_active_bodies(4096, [&](std::size_t i) {
    if (!ctx_.moves[i]) return;
    s.position[i] += dt * s.velocity[i];
    if (s.angular_velocity[i] != 0.0) {
      s.angle[i] += dt * s.angular_velocity[i];
      s.rotation[i] = Rot::from_angle(s.angle[i]);
    }
  });
}

}  // namespace

std::unique_ptr<Engine> make_native_engine(const Scene& scene) { return std::make_unique<NativeEngine>(scene); }

}  // namespace floedem
