#pragma once
// What every stage of the native engine's step reads: one object, made by the engine and
// handed to each stage (as Box2D v3's b2StepContext), so that no stage keeps its own copy of
// the step, the settings or the bodies. A stage owns only what it alone keeps between steps
// (contact_pipeline.hpp, island_stage.hpp, redetection.hpp, sleep_sets.hpp).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "collision/part_set.hpp"
#include "floedem/engine/engine.hpp"
#include "floedem/scene/scene.hpp"
#include "parallel/thread_pool.hpp"
#include "solver/native_settings.hpp"
#include "solver/solver_types.hpp"

namespace floedem {

/// The bodies and parts that the per-body passes visit: all but the settled sleepers. A body
/// asleep since the end of step s has, from step s + 2 on, zero velocity and reach and the same
/// placement, part boxes and fat boxes every step, until it wakes (its position could still
/// change in step s + 1: a velocity of zero moves -0 to +0). From step s + 3 it is settled
/// (SleepSets::settle): the passes of the broad phase, the loads and the integration go over
/// the lists of the rest (ascending) instead, the same values to the bit without a visit to
/// the towing case's 4 000 floes at rest.
class ActiveSet {
 public:
  ActiveSet(std::size_t bodies, std::size_t parts);
  bool settled(std::int32_t body) const { return settled_[static_cast<std::size_t>(body)] != 0; }
  bool any_settled() const { return settled_count_ > 0; }
  void settle(std::int32_t body);
  void unsettle(std::int32_t body);  ///< a settled body that wakes (others: nothing)
  void unsettle_all();               ///< a restored run: its sleepers settle anew
  /// The lists again, where a body settled or woke since they were made.
  void refresh(const PartSet& parts);
  /// Valid after refresh(): the bodies and parts not settled, ascending.
  std::span<const std::int32_t> bodies() const { return bodies_; }
  std::span<const std::int32_t> parts() const { return parts_; }

 private:
  std::vector<std::uint8_t> settled_;  // per body
  std::int64_t settled_count_ = 0;
  std::vector<std::int32_t> bodies_, parts_;
  bool stale_ = false;
};

struct StepContext {
  explicit StepContext(const Scene& scene);

  NativeSettings settings;
  ContactSettings contact;
  double dt;  ///< s, the scene's step

  // Hot: touched every step.
  BodyArrays bodies;                 ///< the published state, with rotations and inverse masses
  std::vector<std::uint8_t> moves;   ///< per body: 0 for fixed bodies
  bool has_prescribed = false;       ///< a body moves on a prescribed path (towing)
  PartSet parts;                     ///< every body's convex parts, placed each step
  ActiveSet active;
  /// Per body: how far its centroid (dt |v|) and its spin (dt |w|) can take it this step, at
  /// its velocity after the loads: the broad and narrow phases' reach (speculative contact).
  std::vector<double> linear_reach, angular_reach;

  // This step's.
  const Loads* loads = nullptr;  ///< the loads that add velocity (nullptr: none)
  bool loads_applied = false;    ///< the loads stage has run: a body woken later gets its loads then
  std::int64_t step = 0;         ///< steps made before this one

  /// Body i's reach from its velocity after this step's loads; whether it changed.
  bool set_reach(std::size_t i);
  /// f(i) for each body but the settled sleepers, ascending, in blocks of `grain` on the pool's
  /// threads (kSerial: one block, on the calling thread).
  static constexpr std::size_t kSerial = 0;
  template <class F>
  void for_active_bodies(std::size_t grain, F&& f) {
    active.refresh(parts);
    const bool skip = active.any_settled();
    const std::size_t count = skip ? active.bodies().size() : bodies.position.size();
    auto body = [&](std::size_t j) { return skip ? static_cast<std::size_t>(active.bodies()[j]) : j; };
    if (grain == kSerial) {
      for (std::size_t j = 0; j < count; ++j) f(body(j));
      return;
    }
    thread_pool().for_blocks(count, grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t j = begin; j < end; ++j) f(body(j));
    });
  }
};

}  // namespace floedem
