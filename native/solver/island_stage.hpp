#pragma once
// The contact_solve stage: the step's manifolds grouped into islands (contact_islands.hpp),
// each island's impulses by Gauss-Seidel sweeps in pair or colour order (contact_solver.hpp,
// coloured_sweeps.hpp), its energy checked, and heavy-light islands the sweeps cannot hold
// solved directly (island_solve.hpp). It owns the islands, the sweeps' work space and the
// solver's counts.
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "solver/contact_islands.hpp"
#include "solver/island_solve.hpp"
#include "solver/step_context.hpp"

namespace floedem {

class IslandStage {
 public:
  IslandStage(const Scene& scene, const StepContext& ctx);

  /// Islands from `manifolds`, solved. `resolve`, where not empty: per body, whether its island
  /// is solved again (a redetection's); every other island keeps its impulses and velocities.
  void solve(StepContext& ctx, std::span<Manifold> manifolds, std::span<const std::uint8_t> resolve = {});
  const ContactIslands& islands() const { return islands_; }

  // Measured over the run (EngineInfo, work counts, checkpoints).
  std::int64_t total_sweeps() const { return total_sweeps_; }    ///< per step, the most sweeps any island took
  std::int64_t total_islands() const { return total_islands_; }  ///< islands solved
  std::int64_t cold_restarts() const { return cold_restarts_; }
  std::int64_t direct_solves() const { return direct_solves_; }      ///< steps whose islands were solved directly
  std::int64_t direct_reverted() const { return direct_reverted_; }  ///< ... and then given back (they would have made energy)
  /// Checkpoint: the counts, in the engine's order (native_engine.cpp).
  void restore_counts(std::int64_t sweeps, std::int64_t islands, std::int64_t cold, std::int64_t direct,
                      std::int64_t reverted);

 private:
  /// What one block of islands reports back (its scratch lives in the step-wide lists below).
  struct IslandWork {
    int longest = 0;        // most sweeps an island of the block took
    int cold_restarts = 0;  // islands of the block solved again from zero
    bool out_of_sweeps = false;  // an island of the block spent its sweeps (sweep_limits)
  };
  int solve_island(StepContext& ctx, std::span<Manifold> manifolds, std::size_t island, bool checked,
                   IslandWork& work, bool threads);
  // Whether island i is swept colour by colour (NativeSettings::coloured_from; islands_ built).
  bool coloured(const StepContext& ctx, std::size_t i) const {
    return static_cast<std::int64_t>(islands_.manifolds(i).size()) >= ctx.settings.coloured_from;
  }
  void solve_islands_directly(StepContext& ctx, std::span<Manifold> manifolds, double energy_before);
  /// Whether an island of `manifolds` manifolds is large (NativeSettings::large_island_manifolds).
  static bool large_island(const StepContext& ctx, std::size_t manifolds) {
    return static_cast<std::int64_t>(manifolds) >= ctx.settings.large_island_manifolds;
  }
  /// The sweeps' limits for an island of `manifolds` manifolds: a large one's own count, and for
  /// every island extra sweeps while a point would close by more than the allowed overlap
  /// within the step.
  static SweepLimits sweep_limits(const StepContext& ctx, std::size_t manifolds) {
    const NativeSettings& s = ctx.settings;
    const bool large = large_island(ctx, manifolds);
    return {large ? std::min(s.velocity_iterations, s.large_island_iterations) : s.velocity_iterations, s.tolerance,
            s.extra_iterations, s.allowed_penetration / ctx.dt};
  }

  static constexpr std::size_t kIslandGrain = 8;  // islands per block
  static constexpr int kFrictionRounds = 8;       // cut friction, solve the normals again (below)

  bool heavy_light_ = false;  // direct solve on, and two moving bodies differ by its mass ratio
  ContactIslands islands_;
  std::vector<IslandWork> island_work_;  // per block of islands
  // The islands' bodies' velocities before their solves (a cold restart puts them back), each
  // island in its slice (its bodies' place in islands_): one list for all, grown with headroom,
  // so a pile that keeps growing (the towing case) does not allocate per block of islands.
  std::vector<Vec2> island_velocity_;
  std::vector<double> island_angular_velocity_;
  SweepWork sweep_work_;  // the islands' sweeps, each in its slice (its manifolds' place in islands_)
  std::vector<std::size_t> island_bundles_;  // coloured sweeps: each island's first bundle in sweep_work_
  // The direct solve's: what it gives back when it would make energy, and its islands' manifolds.
  std::vector<Vec2> saved_velocity_;
  std::vector<double> saved_angular_velocity_;
  std::vector<double> saved_impulses_;
  std::vector<std::int32_t> island_index_;
  std::vector<Manifold> island_manifolds_;
  IslandSolver island_solver_;
  std::int64_t total_sweeps_ = 0, total_islands_ = 0, cold_restarts_ = 0;
  std::int64_t direct_solves_ = 0, direct_reverted_ = 0;
};

}  // namespace floedem
