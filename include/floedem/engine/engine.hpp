#pragma once
// The one interface that the native solver and every reference engine implement alike.
// Flow: scenario -> Scene -> Engine (built by name from the registry) -> Recorder.
// An engine owns the dynamics of contact; everything that is not contact (applied loads,
// later environmental forcing and towing) is computed by shared code and handed to step()
// as loads, so that engines differ only in how they treat contact.
#include <cstdint>
#include <cstdio>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "floedem/engine/stage_clock.hpp"
#include "floedem/engine/state_io.hpp"
#include "floedem/geometry/vec2.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

/// State of all bodies, in scene order. Position is the centroid; angle is 0 at t = 0.
struct BodyStates {
  std::vector<Vec2> position;          ///< m
  std::vector<double> angle;           ///< rad
  std::vector<Vec2> velocity;          ///< m/s
  std::vector<double> angular_velocity;///< rad/s
  void resize(std::size_t n) {
    position.resize(n);
    angle.resize(n);
    velocity.resize(n);
    angular_velocity.resize(n);
  }
};

/// Read-only view of BodyStates whose arrays may come from different places: the forcing
/// terms see the engine's positions with the velocities a towed body will have over the step,
/// without a copy of the whole state.
struct BodyStatesView {
  std::span<const Vec2> position;
  std::span<const double> angle;
  std::span<const Vec2> velocity;
  std::span<const double> angular_velocity;
  BodyStatesView(const BodyStates& s)  // NOLINT(google-explicit-constructor): a view of it
      : position(s.position), angle(s.angle), velocity(s.velocity), angular_velocity(s.angular_velocity) {}
};

/// A body moved on a prescribed velocity over the step (towing at constant speed): the engine
/// treats it as kinematic (infinite mass in contacts) and moves it by dt times this velocity.
struct PrescribedMotion {
  std::int32_t body = 0;
  Vec2 velocity;
  double angular_velocity = 0.0;
};

/// Non-contact loads on each body, constant over one step (N at the centroid, N m).
struct Loads {
  std::vector<Vec2> force;
  std::vector<double> torque;
  bool any = false;  ///< false: every force entry is zero and the engine may skip them
  /// True where only the bodies of `loaded` (ascending) may have a force or torque that is not
  /// zero, and an engine may look at those alone: a scene in still water and air, whose forcing
  /// works on the moving bodies alone.
  bool listed = false;
  std::vector<std::int32_t> loaded;
  std::vector<PrescribedMotion> prescribed;
  /// Empty, or per body a turn of the centroid velocity at the start of the step, before the
  /// forces: a scene whose only term is Coriolis hands its exact velocity rotation this way
  /// instead of as forces, so that the engine needs no force pass (forcing.cpp).
  std::vector<Rot> velocity_turn;
};

enum class ContactKind : std::uint8_t {
  collision = 0,  ///< approach speed above the collision threshold: Newton restitution
  resting = 1,    ///< bodies moving together: no bounce
};

/// One contact point's impulse over the last step. Normal from body_a to body_b; the
/// impulse normal_impulse * normal + tangent_impulse * perp(normal) acts on body_b, its
/// opposite on body_a.
struct ContactRecord {
  std::int32_t body_a = 0;
  std::int32_t body_b = 0;
  Vec2 point;                      ///< m, world, at the start of the step
  Vec2 normal;                     ///< unit, world
  double normal_impulse = 0.0;     ///< N s, >= 0
  double tangent_impulse = 0.0;    ///< N s, along perp(normal) = (-n.y, n.x)
  double approach_velocity = 0.0;  ///< m/s, normal relative velocity before the step (< 0 approaching)
  double separation = 0.0;         ///< m, signed gap at the start of the step (< 0 overlapping)
  ContactKind kind = ContactKind::resting;
  /// N s, the impulse on body_b (on body_a its opposite).
  Vec2 impulse() const { return normal_impulse * normal + tangent_impulse * perp(normal); }
};

/// A real-valued setting or figure as text for EngineInfo: 15 significant digits, so that
/// 1e-16 stays 1e-16 and 0.2 stays 0.2 (std::to_string would print both with 6 decimals).
inline std::string setting_text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.15g", v);
  return b;
}

/// A count of an engine's work, summed over its steps (`floedem bench` gives it per timed step):
/// what separates a step that does more work from one whose work costs more.
struct WorkCount {
  std::string name;
  double count = 0.0;
};

/// What an engine says about itself; written into the output's attributes.
struct EngineInfo {
  std::string name;
  std::string version;
  std::map<std::string, std::string> settings;  ///< every setting in force, as text
  std::vector<std::string> limitations;         ///< what this engine cannot express
};

class Engine {
 public:
  virtual ~Engine() = default;
  Engine() = default;
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// Advances every body by the scene's dt under the given loads (nullptr: none).
  virtual void step(const Loads* loads) = 0;
  /// State after the last step (or the initial state before any).
  virtual const BodyStates& state() const = 0;
  /// The contact impulses of the last step.
  virtual std::span<const ContactRecord> contacts() const = 0;
  /// Each body's Rot::from_angle(state().angle[i]), where the engine keeps them (the native
  /// engine turns its parts with them), else empty: the forcing then makes its own. Read by
  /// the forcing in place of a sine and cosine per body and step.
  virtual std::span<const Rot> rotations() const { return {}; }
  virtual EngineInfo info() const = 0;

  /// Checkpoint and restart (floedem run --resume): writes everything the engine's next steps
  /// depend on, so that restore_state() on an engine built from the same scene continues to
  /// the bit. Returns false, writing nothing, for an engine that cannot: the reference engines
  /// keep their contact caches inside libraries that neither expose nor accept them.
  virtual bool save_state(StateWriter& /*out*/) const { return false; }
  /// Reads what save_state() wrote (StateError when it does not fit this engine and scene).
  virtual void restore_state(StateReader& /*in*/) { throw StateError("this engine cannot restore a checkpoint"); }
  /// Wall time per stage of step() (`floedem bench`): summed from the call with `on` true.
  /// Off by default; an engine that does not time its stages ignores it and adds none.
  virtual void time_stages(bool /*on*/) {}
  /// Appends each stage's summed wall time, in the order step() makes them.
  virtual void add_stage_times(std::vector<StageTime>& /*out*/) const {}
  /// Appends the engine's counts of its work since it was built (the same names every call, in
  /// the same order). An engine that counts nothing adds none.
  virtual void add_work_counts(std::vector<WorkCount>& /*out*/) const {}
};

}  // namespace floedem
