// Compliant reference contacts (contact_model = "compliant"): a collision lasts, and its
// measured duration is held against the linear spring-dashpot's closed forms (docs/model.md 4).
//
// For a spring k and dashpot of damping ratio zeta on the effective mass, a contact that
// cannot pull lets go at t_c = (pi - atan(2 zeta sqrt(1 - zeta^2) / (1 - 2 zeta^2))) / omega_d,
// omega_d = sqrt(k / m_eff) sqrt(1 - zeta^2) (Schwager and Poeschel 2007): at e = 0.1
// (zeta = 0.59) that is 0.741 of the undamped half-sine pi sqrt(m_eff / k), the documented gap
// between the compliant references and native's estimate. The measured duration counts whole
// steps from first to last with contact force and ODE's spring-damper is implicit Euler: at
// dt = tau / 40 it exceeds t_c by 4.6 % (0.4 % at tau / 320); Bullet's the same, except that
// on the heavy floes (deep overlap, centimetres) its persistent manifold drops and re-adds
// points during the pulse (4 -> 2 -> 3 points), which tilts the push and delays the release by
// up to 15 % (measured at h = 100 m). Tolerance against t_c: 10 % for ODE, 20 % for Bullet.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "contacts/collision_forces.hpp"
#include "run/stepper.hpp"
#include "reference/compliant_pulse.hpp"
#include "support.hpp"

using namespace floedem;
using test::BodyText;

namespace {

struct Measured {
  CollisionRow row;
  double undamped = 0.0, released = 0.0;  ///< pi sqrt(m/k) and t_c
};

/// A 10 m floe of thickness h head-on into a fixed wall at 0.5 m/s, on `engine` with compliant contacts.
Measured impact(const std::string& engine, double h, double e) {
  const double c_tau = 1.5e-4, m = 900.0 * 100.0 * h;
  const double tau = c_tau * std::sqrt(m), dt = tau / 40.0;
  std::ostringstream extra;
  extra.precision(17);
  extra << "duration_coefficient = " << c_tau << "\n[engine." << engine << "]\ncontact_model = \"compliant\"\n";
  const BodyText floe{"floe", test::box({0.0, 0.0}, 10.0, 10.0), {0.5, 0.0}, 0.0, false, {}, h};
  const BodyText wall{"wall", test::box({10.0, 0.0}, 10.0, 40.0), {}, 0.0, true};
  const Scene s = test::scene_from(test::header_toml(4.0 * tau, dt, e, 0.0, extra.str()) + test::body_toml(floe) +
                                   test::body_toml(wall));
  const std::vector<CollisionRow> rows = test::collisions_of(s, engine);
  REQUIRE(rows.size() == 1);
  const double k = std::pow(std::numbers::pi / c_tau, 2);
  const double released = test::released_pulse(k, m, e).duration;
  return {rows[0], std::numbers::pi * std::sqrt(m / k), released};
}

}  // namespace

TEST_CASE("compliant ODE and Bullet: durations follow the spring-dashpot and scale as sqrt(m_eff) over 8 decades",
          "[reference][compliant]") {
  for (const std::string engine : {"ode", "bullet"}) {
  if (!test::have_engine(engine)) continue;
  INFO(engine);
  std::vector<double> log_m, log_tau;
  for (int p = -4; p <= 4; p += 2) {
    const double h = std::pow(10.0, p);
    const Measured r = impact(engine, h, 0.1);
    INFO("h = " << h << " m: measured " << r.row.duration << " s, t_c " << r.released << " s, pi sqrt(m/k) "
                << r.undamped << " s, restitution " << r.row.restitution_achieved);
    CHECK(r.row.duration == Approx(r.released).epsilon(engine == "ode" ? 0.10 : 0.20));
    CHECK(r.released / r.undamped == Approx(0.741).epsilon(1e-3));  // the gap, as documented
    CHECK(r.row.effective_mass == Approx(90000.0 * h).epsilon(1e-12));
    // The impulse is momentum exchanged: (1 + e_achieved) m u, whatever e came out as.
    CHECK(r.row.normal_impulse == Approx((1.0 + r.row.restitution_achieved) * r.row.effective_mass * 0.5).epsilon(0.02));
    // A no-pull spring-dashpot returns more than exp(-zeta pi / sqrt(1 - zeta^2)) = e: never less.
    CHECK(r.row.restitution_achieved > 0.1);
    CHECK(r.row.restitution_achieved < 0.5);
    log_m.push_back(std::log(r.row.effective_mass));
    log_tau.push_back(std::log(r.row.duration));
  }
  // Least-squares slope of ln tau on ln m_eff.
  const double n = static_cast<double>(log_m.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < log_m.size(); ++i) {
    sx += log_m[i];
    sy += log_tau[i];
    sxx += log_m[i] * log_m[i];
    sxy += log_m[i] * log_tau[i];
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  CHECK(slope == Approx(0.5).margin(0.05));
  }
}
