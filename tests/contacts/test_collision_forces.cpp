// Collision forces from impulses (docs/model.md section 4): effective mass, duration, mean and peak
// force of the half-sine pulse, and how events are told apart, against closed forms.
//
// Tolerances: the formulas are evaluated on the solver's impulse, which is exact to the
// solver tolerance (1e-12 with 500 sweeps and tolerance 0): 1e-9 relative leaves room for the
// round-off of the mass properties and of the impulse-weighted contact point, nothing more.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "contacts/collision_forces.hpp"
#include "run/stepper.hpp"
#include "floedem/scene/input_error.hpp"
#include "support.hpp"

using namespace floedem;
using test::BodyText;

namespace {

const std::string kExact = "[engine.native]\nvelocity_iterations = 500\ntolerance = 0.0\n";

/// Runs a scene to its end and returns the collision events it had.
std::vector<CollisionRow> events_of(const Scene& s) {
  Stepper stepper(s, "native");
  CollisionTracker tracker(s);
  std::vector<CollisionRow> rows;
  for (std::int64_t k = 0; k < s.run.steps(); ++k) {
    stepper.step();
    tracker.observe(stepper.time(), stepper.contacts(), stepper.state(), rows);
  }
  tracker.finish(stepper.state(), rows);
  return rows;
}

std::string scene_text(double dt, double e, double c_tau, const std::vector<BodyText>& bodies, double duration = 1.0) {
  std::ostringstream extra;
  extra.precision(17);
  extra << "duration_coefficient = " << c_tau << "\n" << kExact;
  std::string t = test::header_toml(duration, dt, e, 0.0, extra.str());
  for (const BodyText& b : bodies) t += test::body_toml(b);
  return t;
}

void check_pulse(const CollisionRow& r, double c_tau) {
  const double tau = c_tau * std::sqrt(r.effective_mass);
  CHECK(r.duration == Approx(tau).epsilon(1e-12));
  CHECK(r.mean_force == Approx(r.normal_impulse / tau).epsilon(1e-9));
  CHECK(r.peak_force == Approx(std::numbers::pi * r.normal_impulse / (2.0 * tau)).epsilon(1e-9));
  CHECK(r.peak_force / r.mean_force == Approx(std::numbers::pi / 2.0).epsilon(1e-12));
}

}  // namespace

TEST_CASE("collision forces: head-on floe on floe, the reduced mass and the half-sine pulse", "[contacts]") {
  // Two 10 m floes of 90 t and 22.5 t (thickness 4:1), touching, closing at 1.5 m/s.
  for (const double e : {0.0, 0.1, 0.5, 0.9}) {
    const BodyText a{"a", test::box({-5.0, 0.0}, 10.0, 10.0), {1.0, 0.0}, 0.0, false, {}, 1.0};
    const BodyText b{"b", test::box({5.0, 0.0}, 10.0, 10.0), {-0.5, 0.0}, 0.0, false, {}, 0.25};
    const double ma = 90000.0, mb = 22500.0, mr = ma * mb / (ma + mb);
    const auto rows = events_of(test::scene_from(scene_text(0.01, e, 2e-4, {a, b}, 0.5)));
    INFO("e = " << e);
    REQUIRE(rows.size() == 1);
    const CollisionRow& r = rows[0];
    CHECK(r.body_a == 0);
    CHECK(r.body_b == 1);
    CHECK(r.time == Approx(0.01));
    CHECK(r.effective_mass == Approx(mr).epsilon(1e-12));
    CHECK(r.approach_speed == Approx(1.5).epsilon(1e-12));
    CHECK(r.normal_impulse == Approx((1.0 + e) * mr * 1.5).epsilon(1e-9));
    CHECK(r.restitution_achieved == Approx(e).margin(1e-9));
    check_pulse(r, 2e-4);
  }
}

TEST_CASE("collision forces: floe into a fixed structure, off-centre, rotation in the effective mass",
          "[contacts]") {
  // A square floe turned by 30 degrees hits a fixed wall (x >= 0) with one corner: the lever
  // arm r of the corner gives m_eff = 1 / (1/m + (r x n)^2 / I) with n = (1, 0).
  const double side = 10.0, q = std::numbers::pi / 6.0, m = 900.0 * side * side, inertia = m * side * side / 6.0;
  std::vector<Vec2> floe = test::box({0.0, 0.0}, side, side, q);
  double xmax = -1e9;
  Vec2 corner;
  for (const Vec2 v : floe)
    if (v.x > xmax) {
      xmax = v.x;
      corner = v;
    }
  const BodyText wall{"wall", {{xmax, -50.0}, {xmax + 5.0, -50.0}, {xmax + 5.0, 50.0}, {xmax, 50.0}}, {}, 0.0, true};
  const BodyText f{"floe", floe, {0.8, 0.0}};
  const auto rows = events_of(test::scene_from(scene_text(0.01, 0.2, 1.5e-4, {f, wall}, 0.3)));
  REQUIRE(rows.size() == 1);
  const CollisionRow& r = rows[0];
  const double rxn = cross(corner, Vec2{1.0, 0.0});
  const double m_eff = 1.0 / (1.0 / m + rxn * rxn / inertia);
  CHECK(std::abs(rxn) > 1.0);  // a real lever arm
  CHECK(r.effective_mass == Approx(m_eff).epsilon(1e-9));
  CHECK(r.effective_mass < m);
  // Newton's law at the point: J = (1 + e) m_eff u.
  CHECK(r.normal_impulse == Approx(1.2 * m_eff * 0.8).epsilon(1e-9));
  CHECK(r.restitution_achieved == Approx(0.2).margin(1e-9));
  check_pulse(r, 1.5e-4);
}

TEST_CASE("collision forces: one event per impact, and resting contact after it adds nothing", "[contacts]") {
  // A floe driven into a wall by a constant force: it hits (a collision), then stays pressed
  // (resting contacts every step until the end): one event, J the impact's impulse alone.
  const BodyText wall{"wall", test::box({10.0, 0.0}, 10.0, 40.0), {}, 0.0, true};
  const BodyText f{"floe", test::box({0.0, 0.0}, 10.0, 10.0), {0.5, 0.0}, 0.0, false, {2.0e4, 0.0}};
  const Scene s = test::scene_from(scene_text(0.01, 0.0, 1.5e-4, {f, wall}, 2.0));
  const auto rows = events_of(s);
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].normal_impulse == Approx(90000.0 * (0.5 + 0.01 * 2.0e4 / 90000.0)).epsilon(1e-6));
  CHECK(rows[0].effective_mass == Approx(90000.0).epsilon(1e-12));
}

TEST_CASE("collision forces: tau against m_eff over 8 decades has exponent 0.5", "[contacts]") {
  // Head-on floe into a structure, thickness 1e-4 to 1e4 m: m_eff = m from 9 kg to 9e8 kg.
  std::vector<double> log_m, log_tau;
  for (int k = -4; k <= 4; ++k) {
    const double h = std::pow(10.0, k);
    const BodyText wall{"wall", test::box({10.0, 0.0}, 10.0, 40.0), {}, 0.0, true};
    const BodyText f{"floe", test::box({0.0, 0.0}, 10.0, 10.0), {0.3, 0.0}, 0.0, false, {}, h};
    const auto rows = events_of(test::scene_from(scene_text(0.01, 0.1, 1.5e-4, {f, wall}, 0.2)));
    REQUIRE(rows.size() == 1);
    log_m.push_back(std::log(rows[0].effective_mass));
    log_tau.push_back(std::log(rows[0].duration));
  }
  const double slope = (log_tau.back() - log_tau.front()) / (log_m.back() - log_m.front());
  CHECK(slope == Approx(0.5).epsilon(1e-12));
  CHECK(std::exp(log_m.back() - log_m.front()) == Approx(1e8).epsilon(1e-9));
}

TEST_CASE("collision forces: [contact] takes duration_coefficient or stiffness, not both", "[contacts][input]") {
  const std::string run = "[run]\nduration = 1\ndt = 0.1\n";
  const std::string body = test::body_toml({"a", test::box({0, 0}, 1, 1)});
  CHECK(test::scene_from(run + body).contact.duration_coefficient == 1.5e-4);
  const Scene k = test::scene_from(run + "[contact]\nstiffness = 4e8\n" + body);
  CHECK(k.contact.duration_coefficient == Approx(std::numbers::pi / std::sqrt(4e8)).epsilon(1e-15));
  for (const std::string& bad : {std::string("stiffness = 4e8\nduration_coefficient = 1e-4\n"),
                                  std::string("stiffness = -1\n"), std::string("duration_coefficient = 0\n")}) {
    INFO(bad);
    CHECK_THROWS_AS(test::scene_from(run + "[contact]\n" + bad + body), InputError);
  }
}

TEST_CASE("collision forces: events from hand-made records, in any order of the list", "[contacts]") {
  // Three floes apart (their states only give the effective masses). Records made by hand, step
  // by step: pair (0, 1) collides at step 1, is pressed at step 2 (its event goes on) and
  // touches without force at step 3 (it has separated: its event ends there); pair (1, 2) rests
  // at step 1 (no event), collides at step 2 and is still open when the run ends; pair (0, 2)
  // collides at step 3 with its two points apart in the list.
  const BodyText a{"a", test::box({0.0, 0.0}, 10.0, 10.0), {}, 0.0};
  const BodyText b{"b", test::box({20.0, 0.0}, 10.0, 10.0), {}, 0.0};
  const BodyText c{"c", test::box({40.0, 0.0}, 10.0, 10.0), {}, 0.0};
  const Scene s = test::scene_from(scene_text(0.01, 0.0, 1.5e-4, {a, b, c}));
  const Stepper stepper(s, "native");
  const BodyStates& at = stepper.state();
  auto record = [](std::int32_t i, std::int32_t j, double impulse, ContactKind kind, Vec2 point) {
    ContactRecord r;
    r.body_a = i;
    r.body_b = j;
    r.point = point;
    r.normal = {1.0, 0.0};
    r.normal_impulse = impulse;
    r.approach_velocity = kind == ContactKind::collision ? -0.5 : 0.0;
    r.kind = kind;
    return r;
  };
  const auto hit = ContactKind::collision, rest = ContactKind::resting;
  const std::vector<std::vector<ContactRecord>> steps = {
      {record(0, 1, 100.0, hit, {10.0, 1.0}), record(0, 1, 0.1, hit, {10.0, -1.0}), record(1, 2, 5.0, rest, {30.0, 0.0})},
      {record(0, 1, 7.0, rest, {10.0, 0.0}), record(1, 2, 30.0, hit, {30.0, 2.0})},
      {record(0, 2, 0.3, hit, {20.0, 1.0}), record(0, 1, 0.0, rest, {10.0, 0.0}), record(0, 2, 1e-17, hit, {20.0, -1.0}),
       record(1, 2, 2.0, rest, {30.0, 0.0})},
  };
  auto run = [&](bool reversed) {
    CollisionTracker tracker(s);
    std::vector<CollisionRow> rows;
    std::vector<std::size_t> ended_at;
    for (std::size_t k = 0; k < steps.size(); ++k) {
      std::vector<ContactRecord> list = steps[k];
      if (reversed) std::reverse(list.begin(), list.end());
      tracker.observe(0.01 * static_cast<double>(k + 1), list, at, rows);
      ended_at.push_back(rows.size());
    }
    tracker.finish(at, rows);
    return std::pair{rows, ended_at};
  };
  const auto [rows, ended_at] = run(false);
  CHECK(ended_at == std::vector<std::size_t>{0, 0, 1});  // (0, 1) ends at step 3, the rest at the end
  REQUIRE(rows.size() == 3);
  CHECK((rows[0].body_a == 0 && rows[0].body_b == 1));
  CHECK(rows[0].time == 0.01);
  CHECK(rows[0].normal_impulse == 100.0 + 0.1);  // collision impulses only: the pressing at step 2 adds nothing
  CHECK(rows[0].approach_speed == Approx(0.5).epsilon(1e-15));  // impulse-weighted over its two points
  // The finished ones in pair order: (0, 2) before (1, 2).
  CHECK((rows[1].body_a == 0 && rows[1].body_b == 2));
  CHECK(rows[1].time == 0.03);
  CHECK(rows[1].normal_impulse == 0.3 + 1e-17);
  CHECK((rows[2].body_a == 1 && rows[2].body_b == 2));
  CHECK(rows[2].time == 0.02);
  CHECK(rows[2].normal_impulse == 30.0);
  // The list in reverse: a pair's records are no longer adjacent and the pairs are out of order;
  // the sums take each pair's records in list order, so only (0, 1)'s two points at step 1 and
  // (0, 2)'s at step 3 are added the other way round (exact here), and the events are the same.
  const auto [back_rows, back_ended_at] = run(true);
  CHECK(back_ended_at == ended_at);
  REQUIRE(back_rows.size() == rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    CHECK(back_rows[k].body_a == rows[k].body_a);
    CHECK(back_rows[k].body_b == rows[k].body_b);
    CHECK(back_rows[k].normal_impulse == rows[k].normal_impulse);
    CHECK(back_rows[k].effective_mass == rows[k].effective_mass);
  }
}
