#include "solver/sleep_sets.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace floedem {

SleepSets::SleepSets(const StepContext& ctx)
    : own_inv_mass_(ctx.bodies.inv_mass), own_inv_inertia_(ctx.bodies.inv_inertia) {
  const std::size_t n = ctx.bodies.position.size();
  body_radius_.assign(n, 0.0);
  for (std::size_t k = 0; k < ctx.parts.size(); ++k) {
    const auto b = static_cast<std::size_t>(ctx.parts.body()[k]);
    body_radius_[b] = std::max(body_radius_[b], ctx.parts.radius(static_cast<std::int32_t>(k)));
  }
  rest_time_.assign(n, 0.0);
  sleep_group_.assign(n, -1);
  sleep_force_.assign(n, Vec2{});
  sleep_torque_.assign(n, 0.0);
  next_in_group_.assign(n, -1);
  group_first_.reserve(n);
  free_groups_.reserve(n);
  in_island_.assign(n, 0);
  asleep_since_.assign(n, 0);
  settling_.reserve(n);
}

bool SleepSets::out_of_balance(const StepContext& ctx, std::size_t b, Vec2 f, double t) const {
  return length(f) * own_inv_mass_[b] > balance_tolerance(ctx) ||
         std::abs(t) * own_inv_inertia_[b] * body_radius_[b] > balance_tolerance(ctx);
}

void SleepSets::sleep_group(StepContext& ctx, std::span<const std::int32_t> bodies) {
  std::int32_t g = 0;
  if (free_groups_.empty()) {
    g = static_cast<std::int32_t>(group_first_.size());
    group_first_.push_back(-1);
  } else {
    g = free_groups_.back();
    free_groups_.pop_back();
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const std::int32_t b : bodies) {
    next_in_group_[b] = group_first_[static_cast<std::size_t>(g)];
    group_first_[static_cast<std::size_t>(g)] = b;
    sleep_group_[b] = g;
    ctx.bodies.velocity[b] = Vec2{};
    ctx.bodies.angular_velocity[b] = 0.0;
    ctx.bodies.inv_mass[b] = ctx.bodies.inv_inertia[b] = 0.0;
    sleep_force_[b] = Vec2{nan, nan};  // taken at its first step asleep, at rest
    sleep_torque_[b] = nan;
    asleep_since_[b] = ctx.step;
    settling_.push_back(b);
  }
  asleep_count_ += static_cast<std::int64_t>(bodies.size());
  loaded_sleepers_ += static_cast<std::int64_t>(bodies.size());
}

void SleepSets::settle(StepContext& ctx) {
  // A body asleep since the end of step s settles at the start of step s + 3 (ActiveSet says
  // why): its parts are held as placed, and the lists are made again.
  if (settling_.empty()) return;
  std::size_t left = 0;
  for (const std::int32_t b : settling_) {
    if (!asleep(b) || ctx.active.settled(b)) continue;  // woken since (or listed twice, asleep again)
    if (ctx.step < asleep_since_[b] + 3) {
      settling_[left++] = b;
      continue;
    }
    ctx.active.settle(b);
    for (std::int32_t k = ctx.parts.first_part(b); k < ctx.parts.first_part(b + 1); ++k) ctx.parts.hold(k);
  }
  settling_.resize(left);
}

void SleepSets::wake_group(StepContext& ctx, std::int32_t group, bool* reach_grew) {
  std::int64_t count = 0;
  for (std::int32_t b = group_first_[static_cast<std::size_t>(group)]; b >= 0; b = next_in_group_[b], ++count) {
    sleep_group_[b] = -1;
    rest_time_[b] = 0.0;
    loaded_sleepers_ -= loaded_sleeper(b);
    ctx.active.unsettle(b);
    ctx.bodies.inv_mass[b] = own_inv_mass_[b];
    ctx.bodies.inv_inertia[b] = own_inv_inertia_[b];
    // Woken before the loads were applied (in the narrow phase): its loads may give it a reach
    // it did not have asleep, and then the step's pairs are found again (at rest in calm water
    // it keeps none).
    if (!ctx.loads_applied) {
      const bool grew = ctx.set_reach(static_cast<std::size_t>(b));
      if (reach_grew) *reach_grew = grew || *reach_grew;
    }
    // Woken after the loads were applied (by a body the impulses sent into it): its own now.
    if (ctx.loads_applied && ctx.loads) {
      ctx.bodies.velocity[b] += (ctx.dt * ctx.bodies.inv_mass[b]) * ctx.loads->force[b];
      ctx.bodies.angular_velocity[b] += ctx.dt * ctx.bodies.inv_inertia[b] * ctx.loads->torque[b];
    }
  }
  asleep_count_ -= count;
  group_first_[static_cast<std::size_t>(group)] = -1;
  free_groups_.push_back(group);
  ++wakes_;
}

bool SleepSets::wake_on_loads(StepContext& ctx) {
  // A sleeping body's load (forcing and applied loads) against the one it had at its first step
  // asleep: a change that would move it faster than the balance tolerance (below) wakes its
  // group. Steady wind and current on a body that does not move give the same load to the bit;
  // a changing wind, a wave or a load switched on does not.
  const Loads* loads = ctx.loads;
  bool woke = false;
  auto check = [&](std::size_t b) {
    const std::int32_t g = sleep_group_[b];
    if (g < 0) return;
    const Vec2 f = loads ? loads->force[b] : Vec2{};
    const double t = loads ? loads->torque[b] : 0.0;
    if (std::isnan(sleep_torque_[b])) {
      sleep_force_[b] = f;
      sleep_torque_[b] = t;
      loaded_sleepers_ -= !loaded_sleeper(b);
      return;
    }
    if (out_of_balance(ctx, b, f - sleep_force_[b], t - sleep_torque_[b])) {
      wake_group(ctx, g, nullptr);
      woke = true;
    }
  };
  // Where every sleeper's load at sleep was zero (the towing case), only a sleeper with a load
  // now can wake: with no loads, none; with the loaded bodies listed (Loads::listed), a listed one.
  if (loaded_sleepers_ == 0 && !loads) return false;
  if (loaded_sleepers_ == 0 && loads->listed) {
    for (const std::int32_t b : loads->loaded) check(static_cast<std::size_t>(b));
    return woke;
  }
  for (std::size_t b = 0; b < sleep_group_.size(); ++b) check(b);
  return woke;
}

bool SleepSets::wake_touched(StepContext& ctx, std::span<const PartPair> pairs, std::span<const std::uint8_t> points,
                             bool* reach_grew) {
  bool woke = false;
  for (bool again = true; again;) {
    again = false;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      if (points[k] == 0) continue;
      const std::int32_t a = ctx.parts.body()[pairs[k].a], b = ctx.parts.body()[pairs[k].b];
      const bool sa = asleep(a), sb = asleep(b);
      if (sa == sb) continue;
      const std::int32_t sleeper = sa ? a : b, other = sa ? b : a;
      if (!ctx.moves[other]) continue;
      wake_group(ctx, sleep_group_[sleeper], reach_grew);
      again = woke = true;
    }
  }
  return woke;
}

bool SleepSets::touches_sleeper(const StepContext& ctx, std::span<const PartPair> pairs,
                                std::span<const std::uint8_t> points) const {
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (points[k] == 0) continue;
    const std::int32_t a = ctx.parts.body()[pairs[k].a], b = ctx.parts.body()[pairs[k].b];
    if (asleep(a) != asleep(b) && ctx.moves[asleep(a) ? b : a]) return true;
  }
  return false;
}

void SleepSets::fall_asleep(StepContext& ctx, const ContactIslands& islands, std::span<const Manifold> manifolds,
                            bool solved) {
  // The rule (docs/model.md, sleeping): a moving body is at rest in a step when no point of it
  // moves faster than sleep_speed (|v| + |w| r, r its farthest point from the centroid). An
  // island (bodies joined by contacts) whose every body has been at rest for sleep_time falls
  // asleep, unless a towed body touches it or nothing holds it: an island without a contact with
  // a fixed (or sleeping) body must carry a net load below the balance tolerance, as must a body
  // without contacts. A body out of balance by more than sleep_speed / sleep_time leaves the
  // speed within sleep_time, so the tolerance on loads, a thousandth of that, is what the timer
  // cannot see for itself: about 1.7e-10 m/s^2 at the defaults.
  const NativeSettings& settings = ctx.settings;
  BodyArrays& s = ctx.bodies;
  const double rest = settings.sleep_time * (1.0 - 1e-9);  // a sum of steps, to rounding
  bool ready = false;  // any awake body at rest for sleep_time (else nothing more to look at)
  ctx.for_active_bodies(StepContext::kSerial, [&](std::size_t i) {
    if (own_inv_mass_[i] == 0.0 || sleep_group_[i] >= 0) return;
    // |v| + |w| r <= sleep_speed, without the square root: |v|^2 <= (sleep_speed - |w| r)^2.
    const double left = settings.sleep_speed - std::abs(s.angular_velocity[i]) * body_radius_[i];
    const Vec2 v = s.velocity[i];
    rest_time_[i] = left >= 0.0 && v.x * v.x + v.y * v.y <= left * left ? rest_time_[i] + ctx.dt : 0.0;
    ready = ready || rest_time_[i] >= rest;
  });
  if (!ready) return;
  if (ctx.has_prescribed)
    for (const Manifold& m : manifolds) {
      const bool towed_a = ctx.moves[m.body_a] && own_inv_mass_[m.body_a] == 0.0;
      const bool towed_b = ctx.moves[m.body_b] && own_inv_mass_[m.body_b] == 0.0;
      if (towed_a) rest_time_[m.body_b] = 0.0;
      if (towed_b) rest_time_[m.body_a] = 0.0;
    }
  const Loads* loads = ctx.loads;
  auto force = [&](std::int32_t b) { return loads ? loads->force[b] : Vec2{}; };
  for (std::size_t i = 0; solved && i < islands.size(); ++i) {
    const std::span<const std::int32_t> bodies = islands.bodies(i);
    bool rested = true;
    for (const std::int32_t b : bodies) {
      in_island_[b] = 1;
      rested = rested && rest_time_[b] >= rest;
    }
    if (!rested) continue;
    bool held = false;
    for (const std::int32_t k : islands.manifolds(i)) {
      const Manifold& m = manifolds[static_cast<std::size_t>(k)];
      held = held || s.inv_mass[m.body_a] == 0.0 || s.inv_mass[m.body_b] == 0.0;
    }
    if (!held) {
      Vec2 net{};
      double mass = 0.0;
      for (const std::int32_t b : bodies) {
        net += force(b);
        mass += 1.0 / own_inv_mass_[b];
      }
      if (length(net) > balance_tolerance(ctx) * mass) continue;
    }
    sleep_group(ctx, bodies);
  }
  ctx.for_active_bodies(StepContext::kSerial, [&](std::size_t i) {
    if (own_inv_mass_[i] == 0.0 || sleep_group_[i] >= 0 || in_island_[i] || rest_time_[i] < rest) return;
    const auto b = static_cast<std::int32_t>(i);
    if (out_of_balance(ctx, i, force(b), loads ? loads->torque[i] : 0.0)) return;
    sleep_group(ctx, {&b, 1});
  });
  if (solved)
    for (const std::int32_t b : islands.all_bodies()) in_island_[b] = 0;  // for the next step
}

void SleepSets::save(StateWriter& out) const {
  out.tag("sleep");
  out.vector(rest_time_);
  out.vector(sleep_group_);
  out.vector(sleep_force_);
  out.vector(sleep_torque_);
  out.value(asleep_steps_);
  out.value(wakes_);
}

void SleepSets::restore(StateReader& in, StepContext& ctx) {
  const std::size_t n = sleep_group_.size();
  in.tag("sleep");
  in.vector(rest_time_, n, "rest times");
  in.vector(sleep_group_, n, "sleeping groups");
  in.vector(sleep_force_, n, "sleeping loads");
  in.vector(sleep_torque_, n, "sleeping torques");
  in.value(asleep_steps_);
  in.value(wakes_);
  // The groups again from each body's (the ids as saved; which ids are free, and the order of
  // a group's list, change no result).
  group_first_.clear();
  free_groups_.clear();
  asleep_count_ = 0;
  loaded_sleepers_ = 0;
  // A restored run places every part afresh (PartSet keeps no placement across a checkpoint):
  // its sleepers settle as if they had just fallen asleep.
  settling_.clear();
  ctx.active.unsettle_all();
  for (std::size_t b = 0; b < n; ++b) {
    const std::int32_t g = sleep_group_[b];
    next_in_group_[b] = -1;
    ctx.bodies.inv_mass[b] = g >= 0 ? 0.0 : own_inv_mass_[b];
    ctx.bodies.inv_inertia[b] = g >= 0 ? 0.0 : own_inv_inertia_[b];
    if (g < 0) continue;
    if (g >= static_cast<std::int32_t>(n) || own_inv_mass_[b] == 0.0)
      throw StateError("checkpoint: a sleeping body that does not fit this scene");
    if (static_cast<std::size_t>(g) >= group_first_.size()) group_first_.resize(static_cast<std::size_t>(g) + 1, -1);
    next_in_group_[b] = group_first_[static_cast<std::size_t>(g)];
    group_first_[static_cast<std::size_t>(g)] = static_cast<std::int32_t>(b);
    ++asleep_count_;
    loaded_sleepers_ += loaded_sleeper(b);
    asleep_since_[b] = ctx.step;
    settling_.push_back(static_cast<std::int32_t>(b));
  }
  for (std::size_t g = group_first_.size(); g-- > 0;)
    if (group_first_[g] < 0) free_groups_.push_back(static_cast<std::int32_t>(g));
}

}  // namespace floedem
