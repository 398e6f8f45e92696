#pragma once
// The sleeping sets (NativeSettings::sleep; the rule and its tolerances in docs/model.md,
// sleeping): which bodies sleep, in which group, since when, with which load, and the waking
// and falling asleep of the `sleep` stage. A sleeping body is held as a fixed one is: zero
// velocity, zero inverse mass and inertia in the step's bodies (so the islands, the solve, the
// loads and the projection pass it by and its contacts with sleeping or fixed bodies keep
// their impulses), its own kept here.
#include <cstdint>
#include <span>
#include <vector>

#include "collision/broad_phase.hpp"
#include "floedem/engine/state_io.hpp"
#include "solver/contact_islands.hpp"
#include "solver/step_context.hpp"

namespace floedem {

class SleepSets {
 public:
  explicit SleepSets(const StepContext& ctx);

  bool any_asleep() const { return asleep_count_ > 0; }
  bool asleep(std::int32_t b) const { return sleep_group_[static_cast<std::size_t>(b)] >= 0; }
  /// Each sleeping group whose load changed beyond the balance tolerance wakes (before the
  /// reaches: it moves this step). Whether any woke.
  bool wake_on_loads(StepContext& ctx);
  /// A pair with contact points (speculative ones included) between a sleeping body and an
  /// awake one that moves wakes the sleeping body's group; again while any woke. Whether any
  /// did, and whether a woken body's reach changed (reach_grew: its loads give it one it did
  /// not have asleep).
  bool wake_touched(StepContext& ctx, std::span<const PartPair> pairs, std::span<const std::uint8_t> points,
                    bool* reach_grew = nullptr);
  /// Whether wake_touched would wake a group.
  bool touches_sleeper(const StepContext& ctx, std::span<const PartPair> pairs,
                       std::span<const std::uint8_t> points) const;
  /// The sleepers that have been asleep long enough settle: their parts are held as placed.
  void settle(StepContext& ctx);
  /// The end of the step: each moving body's time at rest, and the islands (and lone bodies)
  /// that fall asleep. `solved`: the step had contacts, and `islands` groups them.
  void fall_asleep(StepContext& ctx, const ContactIslands& islands, std::span<const Manifold> manifolds, bool solved);
  void count_step() { asleep_steps_ += asleep_count_; }

  std::int64_t asleep_steps() const { return asleep_steps_; }  ///< sum over steps of the bodies asleep
  std::int64_t wakes() const { return wakes_; }                ///< groups woken over the run

  void save(StateWriter& out) const;
  /// After the bodies are restored; sets their inverse masses from who sleeps.
  void restore(StateReader& in, StepContext& ctx);

 private:
  void wake_group(StepContext& ctx, std::int32_t group, bool* reach_grew);
  void sleep_group(StepContext& ctx, std::span<const std::int32_t> bodies);
  // The balance tolerance, m/s^2: a thousandth of the speed the timer sees over sleep_time.
  double balance_tolerance(const StepContext& ctx) const {
    return 1e-3 * ctx.settings.sleep_speed / ctx.settings.sleep_time;
  }
  // Whether sleeping body b's load at its first step asleep is not zero, or not yet seen (NaN).
  bool loaded_sleeper(std::size_t b) const {
    return !(sleep_force_[b].x == 0.0 && sleep_force_[b].y == 0.0 && sleep_torque_[b] == 0.0);
  }
  // Whether a load (f, t) on body b moves its fastest point beyond the balance tolerance.
  bool out_of_balance(const StepContext& ctx, std::size_t b, Vec2 f, double t) const;

  std::vector<double> own_inv_mass_, own_inv_inertia_;  // 0 for fixed and prescribed bodies
  std::vector<double> body_radius_;        // farthest point of a body from its centroid, m
  std::vector<double> rest_time_;          // s each moving body has been at rest (sleep_speed)
  std::vector<std::int32_t> sleep_group_;  // per body: its sleeping group, -1 awake
  // Each group's bodies as a list through the bodies (no allocation as groups come and go):
  // its first body (-1: a free id), and per body the next of its group (-1: the last).
  std::vector<std::int32_t> group_first_, next_in_group_;
  std::vector<std::int32_t> free_groups_;
  std::vector<Vec2> sleep_force_;          // per sleeping body: its load at its first step asleep (NaN: not yet seen)
  std::vector<double> sleep_torque_;
  std::vector<std::uint8_t> in_island_;    // scratch of fall_asleep
  std::vector<std::int64_t> asleep_since_; // per body: the step at whose end it last fell asleep
  std::vector<std::int32_t> settling_;     // bodies that fell asleep and have not settled yet
  std::int64_t asleep_count_ = 0;          // bodies asleep now
  std::int64_t asleep_steps_ = 0;
  std::int64_t wakes_ = 0;
  std::int64_t loaded_sleepers_ = 0;       // sleeping bodies whose load at sleep is not yet seen, or not zero
};

}  // namespace floedem
