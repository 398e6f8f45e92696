#pragma once
// Towing (docs/model.md 6, docs/towing.md): the rope's state, the tug that pulls it, and the
// towing force and outcome of each step.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/engine/state_io.hpp"
#include "floedem/io/run_headline.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

/// What moves in a tow besides the bodies: the tug of mode tug (its position and its speed
/// through the water along its heading), and whether the rope has parted (modes rope and
/// tug). Mode rope's tug follows its path and is found from the time alone.
struct TowLine {
  Vec2 tug;             ///< m, world, mode tug
  double speed = 0.0;   ///< m/s, mode tug: through the water, along the heading
  bool parted = false;
  double parted_at = 0.0;  ///< s, the start of the step in which the rope parted
  explicit TowLine(const TowSpec& tow) : tug(tow.tug_start) {}
  /// The tug's position and velocity over the ground at time t (modes rope and tug).
  Vec2 tug_position(const TowSpec& tow, double t) const;
  Vec2 tug_velocity(const TowSpec& tow, const EnvironmentSpec* environment, double t) const;
};

struct RopeState {
  Vec2 tug;          ///< m, world
  Vec2 arm;          ///< m, world offset of the attachment point from the body's centroid
  Vec2 direction;    ///< unit, from the attachment point towards the tug
  double length = 0; ///< m
  double tension = 0;///< N (0 when slack or parted)
};

/// The rope at time t for the body state s (tow.has_rope()), the tug where `line` has it.
/// `environment`: the water that carries a tug of mode tug (null: still water).
RopeState rope_state(const TowSpec& tow, const TowLine& line, const EnvironmentSpec* environment,
                     const BodyStatesView& s, double t);

/// The pull a tug of mode tug has at speed V (m/s) through the water along its heading at time
/// t: P(V) = r(t) P_B (1 - V / V_f) for V >= 0, r(t) P_B for V < 0, with r(t) = min(1, t / pull_ramp)
/// (docs/towing.md); and dP/dV.
std::array<double, 2> tug_pull(const TowSpec& tow, double speed, double t = 1e300);

/// What the recorder writes per frame: the step's towing force, and the means over the frame's
/// steps of the towing force and of its ice part.
struct TowFrame {
  Vec2 force;           ///< N, of the frame's last step
  Vec2 force_mean;      ///< N, mean over the frame's steps
  Vec2 ice_force_mean;  ///< N, mean over the frame's steps of minus the contact force on the body
  Vec2 tug_position;    ///< m
  double tension_max = 0.0;  ///< N, the rope's largest tension over the frame's steps (rope, tug)
  Vec2 tug_velocity;         ///< m/s, over the ground at the frame's end (tug)
};

/// Tensions counted in logarithmic bins (kBinsPerDecade a decade from 1 N), for the 99th
/// percentile of a run's tension without keeping every step's: the percentile comes back as
/// its bin's geometric centre, within half a bin (0.6 %) of the exact one. Slack steps count
/// in a bin of their own.
class TensionHistogram {
 public:
  static constexpr int kBinsPerDecade = 200;
  static constexpr int kDecades = 10;  ///< 1 N to 1e10 N; outside, the end bins
  void add(double tension);
  double quantile(double q) const;  ///< 0 with no step counted
  void save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  std::int64_t slack_ = 0, total_ = 0;
  std::vector<std::int64_t> bins_ = std::vector<std::int64_t>(kBinsPerDecade * kDecades, 0);
};

/// The towing force, step by step, the tug of mode tug and the rope's parting.
///  - velocity: the force that keeps the body on its path, F = m_I a - F_env - F_contact
///    (the constraint force: m_I with added mass, F_env all forcing terms at the start of the
///    step, F_contact the step's contact impulses on the body over dt);
///  - rope, tug: the rope's tension along the rope at the start of the step.
/// Its ice part, in every mode, is minus the contact force on the body, -F_contact: in velocity
/// mode the towing force less its inertial and open-water (drag) parts; what the ice resists with.
class TowMonitor {
 public:
  explicit TowMonitor(const Scene& scene);
  bool active() const { return tow_.mode != TowSpec::Mode::none; }
  /// The rope's state at the start of the step; the rope parts here when its tension exceeds
  /// the breaking load (that step and every later one pull no more).
  void before_step(const BodyStates& state, double time);
  /// The step's forces, and the tug moved over the step (mode tug).
  void after_step(const BodyStates& state, std::span<const ContactRecord> contacts,
                  const std::array<double, 3>& environment_force);
  Vec2 force() const { return force_; }        ///< N, of the last step
  Vec2 ice_force() const { return ice_; }      ///< N, -F_contact of the last step
  Vec2 tug_position(double time) const;        ///< m (rope, tug: the tug; velocity: the body's path)
  /// The tow's line (the tug and the rope's parting), which the rope's force term reads.
  const TowLine& line() const { return line_; }
  /// The frame at `time`: means over the steps since the last call (frames every k-th step).
  TowFrame take_frame(double time);
  /// The frame at t = 0, before any step: no forces yet (NaN), the tug where and as it starts.
  TowFrame start_frame() const;
  /// The outcome at the end of a run of `time` seconds, the body where `state` has it.
  TowOutcome outcome(const BodyStates& state, double time) const;
  /// Checkpoint: the last step's forces, the sums of the frame under way, the line and the
  /// outcome's tallies.
  void save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  const Scene& scene_;
  /// The water the tug moves through: the scene's environment, or none.
  const EnvironmentSpec* water() const { return scene_.has_environment ? &scene_.environment : nullptr; }

  const TowSpec& tow_;
  Vec2 direction_;  ///< the tow's direction, along which the outcome and stalling are measured
  double time_ = 0.0;
  Vec2 force_, ice_;
  Vec2 sum_, ice_sum_;
  long count_ = 0;
  RopeState rope_;
  TowLine line_;
  double frame_tension_max_ = 0.0;
  double tension_max_ = 0.0;
  double stalled_time_ = 0.0;
  TensionHistogram tensions_;
};

}  // namespace floedem
