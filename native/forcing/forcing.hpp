#pragma once
// Forcing: the force terms a scene uses (force_term.hpp), evaluated together each step into
// the loads every engine takes (the linearly implicit step per body is forcing.cpp's).
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/engine/state_io.hpp"
#include "floedem/scene/scene.hpp"
#include "forcing/force_term.hpp"

namespace floedem {

class DragPass;

/// The terms a scene uses, evaluated together each step.
class Forcing {
 public:
  /// `share_drag_pass`: the drag terms take their floes in one pass (drag_pass.hpp; the same
  /// loads to the bit); false only to test that.
  explicit Forcing(const Scene& scene, bool share_drag_pass = true);
  ~Forcing();
  Forcing(const Forcing&) = delete;
  Forcing& operator=(const Forcing&) = delete;
  bool empty() const { return terms_.empty() && prescribed_.empty(); }
  std::vector<std::string_view> names() const;
  /// How many floes the drag terms take in one shared pass (drag_pass.hpp; 0: none).
  std::size_t drag_pass_floes() const;
  /// Whether its steps after the first work on the moving bodies alone (see moving_only_).
  bool works_on_moving_bodies_only() const { return moving_only_; }
  /// Loads for the step that starts at `time`, or nullptr when the scene has no forcing.
  /// `rotations`: each body's Rot::from_angle(angle), where the engine has them (Engine::
  /// rotations); empty, the forcing makes them. `touching`: per body, nonzero where it had a
  /// contact in the last step (its step is first order, its load exact: forcing.cpp); empty,
  /// every body is taken to be free (second order).
  const Loads* evaluate(const BodyStates& state, double time, std::span<const Rot> rotations = {},
                        std::span<const std::uint8_t> touching = {});
  /// The velocities at the end of the last evaluated step, at the instant of the positions:
  /// the engines' velocities sit half a step back (forcing.cpp), so each free body's gets the
  /// half step of acceleration the forcing gave it over the step, (dt / 2) a, and in a scene of
  /// Coriolis alone its turn over half a step. `v` and `w` hold the engine's velocities after
  /// the step and are corrected in place. Second order in dt where the forcing's step is (free,
  /// explicit bodies); a body in contact or under stiff drag keeps the engine's velocity.
  void velocities_at_step_end(std::span<Vec2> v, std::span<double> w) const;
  /// Checkpoint: what the next step reads of the last (the accelerations of the free bodies).
  void save(StateWriter& out) const;
  void restore(StateReader& in);
  /// Hands the terms the run's tow line (ForceTerm::attach_tow), before the first step.
  void attach_tow(const TowLine& line);
  /// The generalised force of all terms on prescribed (towed) body i over the last evaluated
  /// step, Coriolis included (-m f k x v at its prescribed velocity). Towing reads it.
  std::array<double, 3> environment_force(std::size_t i) const;

 private:
  /// The largest rate |D| / M of a body's drag Jacobian (1/s, row sums): h times it decides
  /// whether its step is implicit (forcing.cpp).
  static double drag_rate(const std::array<double, 9>& d, double mass, double inertia);
  static constexpr double kExplicitLimit = 0.5;  ///< a step is explicit below this h |D| / M
  /// Whether body i is free this step (no contact in the last).
  bool free_body(std::size_t i) const { return touching_.empty() || touching_[i] == 0; }
  std::span<const std::uint8_t> touching_;  ///< evaluate's `touching`, for the step under way
  /// Per body, the acceleration (dv_x, dv_y, dw) / h the last step's forcing gave it where it
  /// was free and explicit, else zero: the next step takes its terms at q + (dt/2) a.
  std::vector<std::array<double, 3>> ahead_;
  bool any_ahead_ = false;  ///< some entry of ahead_ is not zero
  void note_ahead();        ///< sets any_ahead_ from ahead_

  std::vector<std::unique_ptr<ForceTerm>> terms_;
  /// The drag terms whose flow changes in time (tides, a series): their flows are set for each
  /// step before the terms are asked for anything (DistributedDrag::set_time).
  std::vector<DistributedDrag*> varying_;
  FlowFields fields_;  // the scene's gridded wind and current (none: both null)
  void set_flows(double time);
  void check_fields();  // InputError for a point off a grid or on its fill value
  /// The run of consecutive drag terms terms_[pass_first_, pass_first_ + pass_count_) that
  /// shares one pass over the floes (drag_pass.hpp), or nullptr.
  std::unique_ptr<DragPass> drag_pass_;
  std::size_t pass_first_ = 0, pass_count_ = 0;
  std::vector<std::size_t> prescribed_;
  const Scene& scene_;
  double dt_;
  ForceSums sums_;
  Loads loads_;
  /// The velocities with the prescribed ones (towing scenes only): the terms see these with the
  /// engine's positions and angles.
  std::vector<Vec2> moved_velocity_;
  std::vector<double> moved_angular_velocity_;
  std::vector<double> rotated_angle_;  ///< the angle sums_.rotation[i] was computed for (NaN: none)
  bool rotations_copied_ = false;      ///< the last evaluate copied the engine's rotations
  std::vector<double> cached_rate_, cached_tan_, cached_half_tan_;  ///< Coriolis turn per body
  struct BodyHot {
    bool moves = false;  ///< neither fixed nor prescribed
    double mass = 0.0, mass_with_added = 0.0, inertia_with_added = 0.0;
    double engine_mass = 0.0, engine_inertia = 0.0;
  };
  std::vector<BodyHot> hot_;
  /// Rotation-only scenes (Coriolis alone): the exact turn of each body's velocity, by
  /// -f' dt / 2 on the first step (the trapezoidal start) and -f' dt after, handed to the
  /// engine as Loads::velocity_turn.
  bool rotation_only_ = false;
  bool list_stirred_ = false;  // some term reads ForceSums::stirred
  /// Every term is idle at rest (ForceTerm::idle_at_rest) and the moving bodies are listed:
  /// after a first step over every body, a step zeroes what the last one wrote (the bodies of
  /// loads_.loaded, which it hands on) and works on the moving bodies alone. The towing case:
  /// some 300 of its 5 000 floes.
  bool moving_only_ = false;
  bool have_dirty_ = false;  ///< loads_.loaded holds the bodies the last step may have set
  /// The state the terms see: the prescribed bodies at their velocities over the step, the
  /// free bodies at their mid-step velocities (evaluate's parts, in its order).
  BodyStatesView state_seen(const BodyStates& state);
  /// Each body's rotation into the sums.
  void place_rotations(const BodyStatesView& at, std::span<const Rot> rotations);
  /// The terms' rate bounds, and from them which bodies need the Jacobian D; the sums zeroed.
  void choose_jacobians(const BodyStatesView& at, bool sparse);
  /// Body i's load from the sums (the per-body part of evaluate).
  void load_body(std::size_t i, const BodyStates& state, bool first_step);
  std::vector<Rot> turn_first_, turn_later_;
  const std::vector<Rot>* turn_handed_ = nullptr;
};

}  // namespace floedem
