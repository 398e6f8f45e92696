#pragma once
// What the compliant-contact tests share: a scene's collision events on one engine, and the
// closed forms of the spring-dashpot that cannot pull (Schwager and Poeschel 2007; docs/model.md 4).
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "contacts/collision_forces.hpp"
#include "run/stepper.hpp"

namespace floedem::test {

/// Every collision event of a run of `scene` on `engine`, with its measured or estimated duration.
inline std::vector<CollisionRow> collisions_of(const Scene& scene, const std::string& engine) {
  Stepper stepper(scene, engine);
  CollisionTracker tracker(scene, duration_model_of(stepper.engine().info()));
  std::vector<CollisionRow> rows;
  for (std::int64_t k = 0; k < scene.run.steps(); ++k) {
    stepper.step();
    tracker.observe(stepper.time(), stepper.contacts(), stepper.state(), rows);
  }
  tracker.finish(stepper.state(), rows);
  return rows;
}

/// A spring k and dashpot of damping ratio zeta(e) = -ln e / sqrt(pi^2 + ln^2 e) on m_eff, struck
/// at speed u, let go when their force would pull, at
///   t_c = (pi - atan(2 zeta sqrt(1 - zeta^2) / (1 - 2 zeta^2))) / omega_d,
///   omega_d = sqrt(k / m_eff) sqrt(1 - zeta^2),
/// with the rebound e_c = -v(t_c) / u, v(t) = u exp(-zeta omega t) (cos(omega_d t) - zeta omega /
/// omega_d sin(omega_d t)).
struct ReleasedPulse {
  double duration = 0.0;  ///< t_c
  double rebound = 0.0;   ///< e_c
};
inline ReleasedPulse released_pulse(double stiffness, double effective_mass, double e) {
  const double log_e = std::log(e), zeta = -log_e / std::sqrt(std::numbers::pi * std::numbers::pi + log_e * log_e);
  const double omega = std::sqrt(stiffness / effective_mass), omega_d = omega * std::sqrt(1.0 - zeta * zeta);
  const double t_c =
      (std::numbers::pi - std::atan(2.0 * zeta * std::sqrt(1.0 - zeta * zeta) / (1.0 - 2.0 * zeta * zeta))) / omega_d;
  const double e_c =
      -std::exp(-zeta * omega * t_c) * (std::cos(omega_d * t_c) - zeta * omega / omega_d * std::sin(omega_d * t_c));
  return {t_c, e_c};
}

}  // namespace floedem::test
