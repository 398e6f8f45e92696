#pragma once
// Non-contact forcing as small independent units (docs/model.md section 2). Each term adds, per
// body, its generalised force Q = (F_x, F_y, torque) at the start of the step and, where it
// depends on the body's velocity, the Jacobian dQ/dq with q = (v_x, v_y, omega); Coriolis adds
// a rotation rate instead. Forcing (forcing.cpp) then takes one linearly implicit step per body
// and hands the engines the equivalent constant loads. A term a scene does not use is never
// built, so it costs nothing. The same terms drive every engine, so that engines differ only
// in contact. Adding a term: one source file with a builder, and one line in forcing.cpp.
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

/// One body's generalised force Q and Jacobian dQ/dq while a term adds to it point by point:
/// a copy held in registers (the per-point sums would otherwise go through memory, since the
/// compiler cannot rule out aliasing with the quadrature data), added in the same order as
/// point by point into ForceSums, so the result is the same to the bit.
struct BodySum {
  std::array<double, 3> q;
  std::array<double, 9> d;
  /// Adds the force f acting at offset r (world) from the centroid without its Jacobian (a
  /// body whose drag cannot be stiff this step, see ForceTerm::add_rate_bound).
  void add_point_force(Vec2 r, Vec2 f, bool with_torque) {
    q[0] += f.x;
    q[1] += f.y;
    if (with_torque) q[2] += cross(r, f);
  }
  /// Adds the force f acting at offset r (world) from the centroid, with dF/du = a (2x2,
  /// row-major) where u = flow - (v + w k x r): Q += G^T f, dQ/dq -= G^T a G, G = [I, k x r].
  void add_point_force(Vec2 r, Vec2 f, const std::array<double, 4>& a, bool with_torque) {
    // G = [[1, 0, -r_y], [0, 1, r_x]] maps q to the point's velocity.
    const double gx = with_torque ? -r.y : 0.0, gy = with_torque ? r.x : 0.0;
    q[0] += f.x;
    q[1] += f.y;
    if (with_torque) q[2] += cross(r, f);
    // G^T a G, with a = [[a0, a1], [a2, a3]].
    const double a0 = a[0], a1 = a[1], a2 = a[2], a3 = a[3];
    const double c0 = a0 * gx + a1 * gy;  // (a G)_{0,2}
    const double c1 = a2 * gx + a3 * gy;  // (a G)_{1,2}
    d[0] -= a0;
    d[1] -= a1;
    d[2] -= c0;
    d[3] -= a2;
    d[4] -= a3;
    d[5] -= c1;
    d[6] -= gx * a0 + gy * a2;
    d[7] -= gx * a1 + gy * a3;
    d[8] -= gx * c0 + gy * c1;
  }
};

/// Per-body sums the terms add to, in world axes about each body's centroid.
struct ForceSums {
  std::vector<std::array<double, 3>> q;   ///< generalised force (N, N, N m)
  std::vector<std::array<double, 9>> dq;  ///< dQ/dq, row-major 3x3
  std::vector<double> rotation_rate;      ///< f of -m f k x v (1/s); treated exactly, see forcing.cpp
  bool any_jacobian = false;
  bool any_rotation = false;
  /// Each body's rotation at the start of the step, Rot::from_angle(angle): set by Forcing
  /// before the terms add (one sin/cos per body that turned since the last step, not one per
  /// term), for the terms to read.
  std::vector<Rot> rotation;
  /// Per body: whether the terms add dQ/dq (set by Forcing before they add). Zero where the
  /// terms' bound on dt |D| / M shows that the step is explicit whatever D is: D is then never
  /// read, and a term adds Q alone (the same Q to the bit).
  std::vector<std::uint8_t> jacobian;
  /// Per body, filled by ForceTerm::add_rate_bound: upper bounds on the row sums of the
  /// translational block of -D (N s/m) and on |D_ww| (N m s).
  std::vector<std::array<double, 2>> rate_bound;
  /// The bodies that move (a nonzero velocity or spin at the state the terms see), ascending;
  /// set by Forcing before the terms add, when a term reads it (ForceTerm::reads_stirred). A
  /// term in still water and air visits only these (a body at rest listed too costs a look).
  std::vector<std::int32_t> stirred;

  void add_force(std::size_t i, Vec2 f, double torque) {
    q[i][0] += f.x;
    q[i][1] += f.y;
    q[i][2] += torque;
  }
  BodySum load(std::size_t i) const { return {q[i], dq[i]}; }
  /// Stores a body's sum back after a term added point forces to it. Safe from several
  /// threads for distinct bodies; the term then sets any_jacobian once if it added any.
  void store(std::size_t i, const BodySum& s) {
    q[i] = s.q;
    dq[i] = s.d;
  }
  /// One point force on body i (BodySum::add_point_force); terms that add many points to a
  /// body use load / store around them instead.
  void add_point_force(std::size_t i, Vec2 r, Vec2 f, const std::array<double, 4>& a, bool with_torque) {
    BodySum s = load(i);
    s.add_point_force(r, f, a, with_torque);
    store(i, s);
    any_jacobian = true;
  }
};

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  virtual std::string_view name() const = 0;
  /// Adds this term at the start of a step at `time`.
  virtual void add(const BodyStatesView& state, double time, ForceSums& sums) const = 0;
  /// Adds to sums.rate_bound, per body, upper bounds of what this term adds to the row sums
  /// max(|D_xx| + |D_xy|, |D_yx| + |D_yy|) and to |D_ww| of the Jacobian at this state, and
  /// returns true; or returns false when it cannot bound them (then every body gets the full
  /// Jacobian). A term that adds no Jacobian returns true and adds nothing.
  virtual bool add_rate_bound(const BodyStatesView&, ForceSums&) const { return false; }
  /// True for a term that only adds a constant rotation rate (Coriolis): a scene whose terms
  /// are all such takes a precomputed per-body path (Forcing::evaluate).
  virtual bool constant_rotation_only() const { return false; }
  /// True for a term that reads ForceSums::stirred (Forcing lists the moving bodies only then).
  virtual bool reads_stirred() const { return false; }
  /// True for a term that neither reads nor adds anything for a body at rest (zero velocity
  /// and spin at the state it sees) but, at most, a rotation rate: drag in still water and
  /// air, Coriolis. When every term is such, Forcing works on the moving bodies alone.
  virtual bool idle_at_rest() const { return false; }
};

/// Builds the term for a scene, or returns nullptr when the scene does not use it.
using ForceTermBuilder = std::unique_ptr<ForceTerm> (*)(const Scene&);

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
  /// Checkpoint: what the next step reads of the last (the accelerations of the free bodies).
  void save(StateWriter& out) const;
  void restore(StateReader& in);
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
  /// Body i's load from the sums (the per-body part of evaluate).
  void load_body(std::size_t i, const BodyStates& state, bool first_step);
  std::vector<Rot> turn_first_, turn_later_;
  const std::vector<Rot>* turn_handed_ = nullptr;
};

// Builders, one per term file.
std::unique_ptr<ForceTerm> build_applied_load(const Scene& scene);
std::unique_ptr<ForceTerm> build_water_form_drag(const Scene& scene);
std::unique_ptr<ForceTerm> build_water_skin_drag(const Scene& scene);
std::unique_ptr<ForceTerm> build_air_form_drag(const Scene& scene);
std::unique_ptr<ForceTerm> build_air_skin_drag(const Scene& scene);
std::unique_ptr<ForceTerm> build_coriolis(const Scene& scene);
std::unique_ptr<ForceTerm> build_sea_surface_tilt(const Scene& scene);
std::unique_ptr<ForceTerm> build_wave_radiation(const Scene& scene);
std::unique_ptr<ForceTerm> build_rope_tow(const Scene& scene);

}  // namespace floedem
