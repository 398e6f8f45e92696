// The pressure-area collision force (docs/model.md section 4): the pulse of a mass against the
// linear spring capped by ISO 19906's crushing force over the nominal contact area, against
// closed forms and against an independent integration of m delta'' = -F(delta).
//
// Tolerances: the closed forms are exact but for the crossover's bisection (to 1e-15 of the
// overlap) and the 24-point Gauss-Legendre loading time, whose integrand is smooth after the
// substitution: 1e-10 relative. The independent integration (RK4 at 2e5 steps per pulse) is
// accurate to about 1e-8; 1e-6 checks it without testing the integrator's own error.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "contacts/collision_forces.hpp"
#include "run/stepper.hpp"
#include "floedem/scene/input_error.hpp"
#include "support.hpp"

using namespace floedem;
using test::BodyText;

namespace {

CrushingLaw law_of(double c_tau, double c_r, double m_exp, double n_exp) {
  ContactSettings c;
  c.duration_coefficient = c_tau;
  c.force_model = ContactSettings::ForceModel::pressure_area;
  c.crushing_coefficient = c_r;
  c.crushing_width_exponent = m_exp;
  c.crushing_thickness_exponent = n_exp;
  c.has_crushing_thickness_exponent = true;
  return CrushingLaw::of(c);
}

/// The force law written out again, for the independent integration.
double force(double d, const CrushingLaw& law, const ContactWidth& w) {
  const double h = w.thickness, width = w.initial + w.growth * d;
  const double p = law.coefficient * std::pow(h, law.exponent_n(h)) * std::pow(width / h, law.width_exponent);
  return std::min(law.stiffness * d, p * width * h);
}

/// RK4 of m delta'' = -F(delta) from delta = 0, delta' = u until delta' < 0: the loading time
/// (the crossing of rest interpolated) and the deepest overlap.
std::pair<double, double> integrate_loading(double m, double u, const CrushingLaw& law, const ContactWidth& w,
                                            double dt) {
  double d = 0.0, v = u, t = 0.0;
  auto acc = [&](double x) { return -force(x, law, w) / m; };
  for (;;) {
    const double k1x = v, k1v = acc(d);
    const double k2x = v + 0.5 * dt * k1v, k2v = acc(d + 0.5 * dt * k1x);
    const double k3x = v + 0.5 * dt * k2v, k3v = acc(d + 0.5 * dt * k2x);
    const double k4x = v + dt * k3v, k4v = acc(d + dt * k3x);
    const double dn = d + dt / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x), vn = v + dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (vn <= 0.0) {
      const double f = v / (v - vn);  // rest between the two steps, linearly
      return {t + f * dt, d + f * (dn - d)};
    }
    d = dn;
    v = vn;
    t += dt;
  }
}

}  // namespace

TEST_CASE("crushing pulse: where the cap is never reached it is the linear model's half-sine", "[contacts]") {
  const double c_tau = 1.5e-4, m = 8.8e5, J = 2.5e6;
  const CrushingLaw law = law_of(c_tau, 5e7, -0.16, -0.3);
  const ContactWidth wide{1.0, 500.0, 0.0};  // a face 500 m wide: the cap far above the spring's peak
  const CrushingPulse p = crushing_pulse(J, m, law, wide);
  const double tau = collision_duration(c_tau, m);
  CHECK_FALSE(p.crushed);
  CHECK(p.duration == Approx(tau).epsilon(1e-12));
  CHECK(p.peak_force == Approx(collision_peak_force(J, tau)).epsilon(1e-12));
}

TEST_CASE("crushing pulse: a face that does not widen, a constant cap after the spring", "[contacts]") {
  // g = 0: F = min(k delta, F0), F0 = C_R h^n (w0 / h)^m w0 h. Spring to delta* = F0 / k, then
  // constant deceleration F0 / m from v* = sqrt(u^2 - k delta*^2 / m): t = sqrt(m / k)
  // asin(delta* sqrt(k / m) / u) + m v* / F0, peak F0, deepest delta* + (E - F0 delta* / 2) / F0.
  const double c_tau = 1.5e-4, m = 1e6, J = 6e6, u = J / (2.0 * m);
  for (const double m_exp : {-0.16, -0.5, 0.0}) {
    const CrushingLaw law = law_of(c_tau, 2.5e6, m_exp, -0.3);
    const ContactWidth face{2.0, 1.5, 0.0};
    const double h = 2.0, w = 1.5, F0 = 2.5e6 * std::pow(h, -0.3) * std::pow(w / h, m_exp) * w * h;
    const double k = law.stiffness, ds = F0 / k, vs = std::sqrt(u * u - k * ds * ds / m);
    const CrushingPulse p = crushing_pulse(J, m, law, face);
    INFO("m = " << m_exp);
    CHECK(p.crushed);
    CHECK(p.peak_force == Approx(F0).epsilon(1e-12));
    CHECK(p.width == Approx(w).epsilon(1e-15));
    CHECK(p.overlap == Approx(ds + (0.5 * m * u * u - 0.5 * F0 * ds) / F0).epsilon(1e-10));
    CHECK(p.duration == Approx(2.0 * (std::sqrt(m / k) * std::asin(ds * std::sqrt(k / m) / u) + m * vs / F0))
                            .epsilon(1e-10));
    // Far above the spring's reach the pulse is the rigid-plastic one: duration J / F0.
    CHECK(p.duration > 0.99 * J / F0);
  }
}

TEST_CASE("crushing pulse: a corner widening into a face, against an integration of m delta'' = -F", "[contacts]") {
  const double c_tau = 1.5e-4;
  struct Case {
    double m, J, h, w0, g, m_exp, n_exp;
  };
  // The bergy bit on the ship's stem (48 deg corner), a corner of a hexagonal floe (120 deg)
  // with a starting width, a square corner in thin ice, and the ISO thickness exponent's range.
  for (const Case c : {Case{8.8e5, 2.5e6, 8.3, 0.0, 2.0 * std::tan(std::numbers::pi * 48.0 / 360.0), -0.16, -0.3},
                       Case{4.0e7, 1.2e7, 1.0, 0.3, 2.0 * std::tan(std::numbers::pi / 3.0), -0.16, -0.3},
                       Case{2.0e5, 1.0e5, 0.4, 0.0, 2.0, -0.16, -0.42},
                       Case{3.0e9, 9.0e8, 3.0, 0.0, 2.0, -0.5, -0.3}}) {
    INFO("m_eff = " << c.m << ", J = " << c.J);
    const CrushingLaw law = law_of(c_tau, 2.5e6, c.m_exp, c.n_exp);
    const ContactWidth w{c.h, c.w0, c.g};
    const CrushingPulse p = crushing_pulse(c.J, c.m, law, w);
    CHECK(p.crushed);
    const double u = c.J / (2.0 * c.m);
    const double guess = p.duration / 2.0;
    const auto [t_load, deepest] = integrate_loading(c.m, u, law, w, guess / 2e5);
    CHECK(p.duration == Approx(2.0 * t_load).epsilon(1e-6));
    CHECK(p.overlap == Approx(deepest).epsilon(1e-6));
    CHECK(p.peak_force == Approx(force(p.overlap, law, w)).epsilon(1e-12));
    CHECK(p.width == Approx(c.w0 + c.g * p.overlap).epsilon(1e-12));
    // Capped below the linear model's peak, and longer.
    const double tau = collision_duration(c_tau, c.m);
    CHECK(p.peak_force < collision_peak_force(c.J, tau));
    CHECK(p.duration > tau);
  }
}

TEST_CASE("crushing pulse: ISO 19906's thickness exponent", "[contacts]") {
  ContactSettings c;
  const CrushingLaw iso = CrushingLaw::of(c);
  CHECK(iso.iso_thickness_exponent);
  CHECK(iso.exponent_n(0.5) == Approx(-0.4).epsilon(1e-15));
  CHECK(iso.exponent_n(1.0) == Approx(-0.3).epsilon(1e-15));
  CHECK(iso.exponent_n(4.0) == Approx(-0.3).epsilon(1e-15));
}

TEST_CASE("crushing pulse: the contact width's law from the bodies at the impact point", "[contacts]") {
  BodySpec square, bow;
  square.local_polygon = {{-5, -5}, {5, -5}, {5, 5}, {-5, 5}};
  square.area = 100.0;
  square.thickness = 1.5;
  // A ship's stem: the corner at (20, 0) of interior angle 2 atan(8.9 / 20).
  bow.local_polygon = {{-68, -8.9}, {0, -8.9}, {20, 0}, {0, 8.9}, {-68, 8.9}};
  bow.area = 68 * 17.8 + 20 * 8.9;
  bow.thickness = 8.3;
  SECTION("a square's corner, turned by 45 degrees, on the other's face: g = 2 tan(45 deg)") {
    const Vec2 corner = Rot::from_angle(std::numbers::pi / 4).apply(Vec2{5, 5}) + Vec2{0, 0};
    const ContactWidth w =
        contact_width_law(square, {0, 0}, std::numbers::pi / 4, square, corner + Vec2{5, 0}, 0.0, corner, 0.0);
    CHECK(w.thickness == 1.5);
    CHECK(w.initial == 0.0);
    CHECK(w.growth == Approx(2.0).epsilon(1e-12));
  }
  SECTION("the stem on a face: the stem's corner, at any turn of the ship") {
    for (const double turn : {0.0, 0.7, -2.0}) {
      const Vec2 x{3.0, -4.0}, stem = x + Rot::from_angle(turn).apply(Vec2{20, 0});
      const ContactWidth w = contact_width_law(bow, x, turn, square, stem + Vec2{5, 0}, 0.0, stem, 0.0);
      CHECK(w.growth == Approx(2.0 * 8.9 / 20.0).epsilon(1e-12));
      CHECK(w.thickness == 1.5);
    }
  }
  SECTION("a face on a face: the points' spread, not widening") {
    const ContactWidth w = contact_width_law(square, {0, 0}, 0.0, square, {10, 2}, 0.0, {5, 0}, 8.0);
    CHECK(w.initial == 8.0);
    CHECK(w.growth == 0.0);
  }
  SECTION("an iceberg's contact thickness is its draft and sail") {
    BodySpec berg = square;
    berg.kind = BodyKind::iceberg;
    berg.draft = 10.0;
    berg.freeboard = 2.0;
    CHECK(contact_thickness(berg) == 12.0);
    CHECK(contact_width_law(berg, {0, 0}, 0.0, bow, {30, 0}, 0.0, {5, 0}, 9.0).thickness == 8.3);
  }
}

TEST_CASE("crushing pulse: the force model leaves every impulse and motion as it was", "[contacts]") {
  // A square floe turned by 30 degrees into a fixed wall: one corner. Same impulses, states
  // and effective mass on both models; the pressure-area pulse is lower and longer.
  const double side = 10.0, q = std::numbers::pi / 6.0;
  std::vector<Vec2> floe = test::box({0.0, 0.0}, side, side, q);
  double xmax = -1e9;
  for (const Vec2 v : floe) xmax = std::max(xmax, v.x);
  const BodyText wall{"wall", {{xmax, -50.0}, {xmax + 5.0, -50.0}, {xmax + 5.0, 50.0}, {xmax, 50.0}}, {}, 0.0, true};
  const BodyText f{"floe", floe, {2.0, 0.0}, 0.0, false, {}, 1.0};
  std::vector<CollisionRow> rows[2];
  BodyStates end[2];
  for (int model = 0; model < 2; ++model) {
    std::string t = test::header_toml(0.3, 0.01, 0.1, 0.3,
                                      model ? "force_model = \"pressure_area\"\ncrushing_coefficient = 1e6\n" : "");
    t += test::body_toml(f) + test::body_toml(wall);
    const Scene s = test::scene_from(t);
    Stepper stepper(s, "native");
    CollisionTracker tracker(s);
    for (std::int64_t k = 0; k < s.run.steps(); ++k) {
      stepper.step();
      tracker.observe(stepper.time(), stepper.contacts(), stepper.state(), rows[model]);
    }
    tracker.finish(stepper.state(), rows[model]);
    end[model] = stepper.state();
  }
  REQUIRE(rows[0].size() == 1);
  REQUIRE(rows[1].size() == 1);
  CHECK(rows[0][0].normal_impulse == rows[1][0].normal_impulse);
  CHECK(rows[0][0].effective_mass == rows[1][0].effective_mass);
  CHECK(end[0].position == end[1].position);
  CHECK(end[0].angular_velocity == end[1].angular_velocity);
  CHECK(rows[1][0].crushed == 1);
  CHECK(rows[1][0].peak_force < rows[0][0].peak_force);
  CHECK(rows[1][0].duration > rows[0][0].duration);
  // The floe's corner is a right angle: the width grows from nothing.
  CHECK(rows[1][0].contact_width > 0.0);
}

TEST_CASE("crushing pulse: [contact] keys, their ranges, and a compliant engine refused", "[contacts][input]") {
  const std::string run = "[run]\nduration = 1\ndt = 0.1\n";
  const std::string body = test::body_toml({"a", test::box({0, 0}, 1, 1)});
  const Scene ok = test::scene_from(run + "[contact]\nforce_model = \"pressure_area\"\ncrushing_coefficient = 3e6\n" +
                                    "crushing_width_exponent = -0.2\ncrushing_thickness_exponent = -0.35\n" + body);
  CHECK(ok.contact.force_model == ContactSettings::ForceModel::pressure_area);
  CHECK(ok.contact.crushing_coefficient == 3e6);
  CHECK(ok.contact.crushing_width_exponent == -0.2);
  CHECK(ok.contact.has_crushing_thickness_exponent);
  CHECK(test::scene_from(run + body).contact.force_model == ContactSettings::ForceModel::linear);
  for (const std::string& bad :
       {std::string("crushing_coefficient = 3e6\n"), std::string("force_model = \"crushing\"\n"),
        std::string("force_model = \"pressure_area\"\ncrushing_coefficient = 1e3\n"),
        std::string("force_model = \"pressure_area\"\ncrushing_width_exponent = 0.2\n"),
        std::string("force_model = \"pressure_area\"\ncrushing_thickness_exponent = -1\n")}) {
    INFO(bad);
    CHECK_THROWS_AS(test::scene_from(run + "[contact]\n" + bad + body), InputError);
  }
  CHECK_THROWS_AS(CollisionTracker(ok, DurationModel::measured), InputError);
}
