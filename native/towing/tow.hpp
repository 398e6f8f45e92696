#pragma once
// Towing (MODEL.md 6): the rope's state, and the towing force of each step.
#include <array>
#include <span>

#include "engine/engine.hpp"
#include "scene/scene.hpp"

namespace floedem {

struct RopeState {
  Vec2 tug;          ///< m, world
  Vec2 arm;          ///< m, world offset of the attachment point from the body's centroid
  Vec2 direction;    ///< unit, from the attachment point towards the tug
  double length = 0; ///< m
  double tension = 0;///< N (0 when slack)
};

/// The rope at time t for the body state s (tow.mode must be rope).
RopeState rope_state(const TowSpec& tow, const BodyStates& s, double t);

/// The towing force, step by step.
///  - velocity: the force that keeps the body on its path, F = m_I a - F_env - F_contact
///    (the constraint force: m_I with added mass, F_env all forcing terms at the start of the
///    step, F_contact the step's contact impulses on the body over dt);
///  - rope: the rope's tension along the rope at the start of the step.
class TowMonitor {
 public:
  explicit TowMonitor(const Scene& scene);
  bool active() const { return tow_.mode != TowSpec::Mode::none; }
  void before_step(const BodyStates& state, double time);
  void after_step(std::span<const ContactRecord> contacts, const std::array<double, 3>& environment_force);
  Vec2 force() const { return force_; }        ///< N, of the last step
  Vec2 tug_position(double time) const;        ///< m (rope: the tug; velocity: the body's path)
  /// Mean force over the steps since the last call (for frames every k-th step).
  Vec2 take_mean();

 private:
  const Scene& scene_;
  const TowSpec& tow_;
  double time_ = 0.0;
  Vec2 force_;
  Vec2 sum_;
  long count_ = 0;
  RopeState rope_;
};

}  // namespace floedem
