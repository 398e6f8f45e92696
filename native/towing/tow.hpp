#pragma once
// Towing (docs/model.md 6): the rope's state, and the towing force of each step.
#include <array>
#include <span>

#include "floedem/engine/engine.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

struct RopeState {
  Vec2 tug;          ///< m, world
  Vec2 arm;          ///< m, world offset of the attachment point from the body's centroid
  Vec2 direction;    ///< unit, from the attachment point towards the tug
  double length = 0; ///< m
  double tension = 0;///< N (0 when slack)
};

/// The rope at time t for the body state s (tow.mode must be rope).
RopeState rope_state(const TowSpec& tow, const BodyStatesView& s, double t);

/// What the recorder writes per frame: the step's towing force, and the means over the frame's
/// steps of the towing force and of its ice part.
struct TowFrame {
  Vec2 force;           ///< N, of the frame's last step
  Vec2 force_mean;      ///< N, mean over the frame's steps
  Vec2 ice_force_mean;  ///< N, mean over the frame's steps of minus the contact force on the body
  Vec2 tug_position;    ///< m
};

/// The towing force, step by step.
///  - velocity: the force that keeps the body on its path, F = m_I a - F_env - F_contact
///    (the constraint force: m_I with added mass, F_env all forcing terms at the start of the
///    step, F_contact the step's contact impulses on the body over dt);
///  - rope: the rope's tension along the rope at the start of the step.
/// Its ice part, in both modes, is minus the contact force on the body, -F_contact: in velocity
/// mode the towing force less its inertial and open-water (drag) parts; what the ice resists with.
class TowMonitor {
 public:
  explicit TowMonitor(const Scene& scene);
  bool active() const { return tow_.mode != TowSpec::Mode::none; }
  void before_step(const BodyStates& state, double time);
  void after_step(std::span<const ContactRecord> contacts, const std::array<double, 3>& environment_force);
  Vec2 force() const { return force_; }        ///< N, of the last step
  Vec2 ice_force() const { return ice_; }      ///< N, -F_contact of the last step
  Vec2 tug_position(double time) const;        ///< m (rope: the tug; velocity: the body's path)
  /// The frame at `time`: means over the steps since the last call (frames every k-th step).
  TowFrame take_frame(double time);
  /// Checkpoint: the last step's forces and the sums of the frame under way.
  void save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  const Scene& scene_;
  const TowSpec& tow_;
  double time_ = 0.0;
  Vec2 force_, ice_;
  Vec2 sum_, ice_sum_;
  long count_ = 0;
  RopeState rope_;
};

}  // namespace floedem
