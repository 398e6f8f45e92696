#pragma once
// The kinetic energy balance of a run, step by step (no spurious energy gain).
//
// Every engine is handed the same non-contact loads, constant over the step (force F, torque
// T, and for Coriolis alone an exact turn of the velocity), and moves the bodies on a
// prescribed path itself. So the change of the moving bodies' kinetic energy over a step
// splits into three parts:
//   W_loads = KE(v*) - KE(v_n), v* = turn(v_n) + dt M_e^-1 F: the work of the loads (for a
//             constant force under symplectic Euler, exactly F . (v_n + v*) / 2 dt);
//   W_path  = sum over contact points with a body on a path of p . u_k: the work that body
//             does on what it pushes (p the impulse on the other body, u_k the velocity of the
//             path body's point there);
//   W_contact = KE(v_n+1) - KE(v*) - W_path: what the contacts themselves did.
// Inelastic collisions, friction and resting contacts can only take energy away: W_contact
// <= 0 at every step (for one contact with target -e u_r it is lambda u_r (1 - e) / 2, with
// lambda >= 0 and u_r < 0). A positive W_contact is energy the solver made (position
// correction fed into velocities, unconverged warm starts, restitution in chains), and the
// stress suite reports it. KE uses the masses the engines move (M_e: with added mass when it
// enters contacts).
#include <span>
#include <vector>

#include "floedem/engine/engine.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

class EnergyBalance {
 public:
  explicit EnergyBalance(const Scene& scene);
  /// Before the step: the velocities it starts from (the state the last after_step saw, as
  /// the driver steps: its kinetic energy is then not summed again).
  void before_step(const BodyStates& state);
  /// After it: the loads it was given (nullptr: none), the state and the contacts.
  void after_step(const Loads* loads, const BodyStates& after, std::span<const ContactRecord> contacts);

  double work_of_loads() const { return work_loads_; }      ///< J, sum of W_loads
  double work_of_paths() const { return work_path_; }       ///< J, sum of W_path
  double contact_work() const { return work_contact_; }     ///< J, sum of W_contact (<= 0)
  /// The largest W_contact of a step relative to the energy in play in it, KE(v*) + |W_path|
  /// (infinite for energy out of nothing); 0 when no step gained. Up to rounding (about 1e-12
  /// for sums over 1e5 bodies), 0 for a sound solver.
  double max_relative_gain() const { return max_gain_; }

  void save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  double kinetic_energy(std::span<const Vec2> v, std::span<const double> w) const;

  double dt_;
  std::vector<std::size_t> moving_;     // bodies neither fixed nor on a path
  std::vector<std::size_t> on_path_;    // bodies on a prescribed path
  std::vector<double> mass_, inertia_;  // M_e per body
  std::vector<std::uint8_t> path_body_;
  std::vector<Vec2> v_star_;
  std::vector<double> w_star_;
  std::vector<Vec2> path_position_;     // per body on a path: its centroid at the step's start
  double ke_before_ = 0.0;       // KE(v_n); after a step, that of the state it ended in
  bool ke_before_known_ = false;  // so before_step need not sum it again
  double work_loads_ = 0.0, work_path_ = 0.0, work_contact_ = 0.0, max_gain_ = 0.0;
};

}  // namespace floedem
