// MuJoCo as a reference: its soft contact against the spring-dashpot's closed forms t_c and e_c
// (reference/compliant_pulse.hpp; e_c = 0.253 for the scene's e = 0.1: the dashpot's force at
// first touch), its checkpoint, and its settings' errors.
// Tolerances (measured in docs/engines.md): at 10 substeps a step (400 a pulse) the duration
// within 5 % of t_c (1.3 % measured on the face, 3.6 % on a corner) and the rebound within 0.01
// of e_c (0.016 measured at most on the impact suite's 1 km floes, 0.004 here).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <sstream>

#include "contacts/collision_forces.hpp"
#include "floedem/engine/registry.hpp"
#include "floedem/engine/state_io.hpp"
#include "floedem/scene/input_error.hpp"
#include "run/stepper.hpp"
#include "reference/compliant_pulse.hpp"
#include "support.hpp"

using namespace floedem;
using test::BodyText;

namespace {

constexpr double kCtau = 1.5e-4;

std::string impact_scene(double h, double e, const std::string& settings, const Vec2 velocity = {0.5, 0.0}) {
  const double m = 900.0 * 100.0 * h;
  const double tau = kCtau * std::sqrt(m), dt = tau / 40.0;
  std::ostringstream extra;
  extra.precision(17);
  extra << "duration_coefficient = " << kCtau << "\n[engine.mujoco]\n" << settings << "\n";
  const BodyText floe{"floe", test::box({0.0, 0.0}, 10.0, 10.0), velocity, 0.0, false, {}, h};
  const BodyText wall{"wall", test::box({10.0, 0.0}, 10.0, 40.0), {}, 0.0, true};
  return test::header_toml(4.0 * tau, dt, e, 0.0, extra.str()) + test::body_toml(floe) + test::body_toml(wall);
}

struct Pulse {
  CollisionRow row;
  double released = 0.0, rebound = 0.0;  ///< t_c and e_c
};

Pulse measure(const std::string& text) {
  const Scene s = test::scene_from(text);
  const std::vector<CollisionRow> rows = test::collisions_of(s, "mujoco");
  REQUIRE(rows.size() == 1);
  const test::ReleasedPulse closed = test::released_pulse(std::pow(std::numbers::pi / kCtau, 2), rows[0].effective_mass,
                                                          s.contact.restitution);
  return {rows[0], closed.duration, closed.rebound};
}

}  // namespace

TEST_CASE("mujoco: a face impact lasts t_c and rebounds at e_c", "[mujoco]") {
  if (!test::have_engine("mujoco")) return;
  for (const double h : {0.1, 1.0, 10.0}) {
    INFO("thickness " << h);
    const Pulse p = measure(impact_scene(h, 0.1, "substeps = 10"));
    CHECK(p.row.effective_mass == Approx(900.0 * 100.0 * h).epsilon(1e-3));  // the face: no turn
    CHECK(p.row.duration == Approx(p.released).epsilon(0.05));
    CHECK(p.row.restitution_achieved == Approx(p.rebound).margin(0.01));
  }
}

TEST_CASE("mujoco: the pulse follows the mass as sqrt(m_eff)", "[mujoco]") {
  if (!test::have_engine("mujoco")) return;
  // Exponent of the duration on the floe's mass over two decades: 0.5 for a linear spring.
  const Pulse light = measure(impact_scene(0.1, 0.1, "substeps = 10"));
  const Pulse heavy = measure(impact_scene(10.0, 0.1, "substeps = 10"));
  const double exponent = std::log(heavy.row.duration / light.row.duration) / std::log(100.0);
  CHECK(exponent == Approx(0.5).margin(0.02));
}

TEST_CASE("mujoco: a checkpoint continues to the bit", "[mujoco]") {
  if (!test::have_engine("mujoco")) return;
  const Scene s = test::scene_from(impact_scene(1.0, 0.3, "", {0.5, 0.2}));
  auto whole = make_engine("mujoco", s), first = make_engine("mujoco", s), second = make_engine("mujoco", s);
  const int steps = 60, cut = 23;  // the cut falls inside the pulse
  for (int k = 0; k < steps; ++k) whole->step(nullptr);
  for (int k = 0; k < cut; ++k) first->step(nullptr);
  StateWriter out;
  REQUIRE(first->save_state(out));
  StateReader in(out.bytes().data(), out.size());
  second->restore_state(in);
  for (int k = cut; k < steps; ++k) second->step(nullptr);
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    CHECK(second->state().position[i].x == whole->state().position[i].x);
    CHECK(second->state().position[i].y == whole->state().position[i].y);
    CHECK(second->state().angle[i] == whole->state().angle[i]);
    CHECK(second->state().velocity[i].x == whole->state().velocity[i].x);
    CHECK(second->state().angular_velocity[i] == whole->state().angular_velocity[i]);
  }
}

TEST_CASE("mujoco: bad settings get one line naming the field and the range", "[mujoco]") {
  if (!test::have_engine("mujoco")) return;
  const auto refused = [](const std::string& settings, const std::string& field, const std::string& allowed) {
    INFO(settings);
    const Scene s = test::scene_from(impact_scene(1.0, 0.1, settings));
    try {
      make_engine("mujoco", s);
      FAIL("accepted");
    } catch (const InputError& e) {
      const std::string m = e.what();
      CHECK(m.find(field) != std::string::npos);
      CHECK(m.find(allowed) != std::string::npos);
      CHECK(m.find('\n') == std::string::npos);
    }
  };
  refused("solver = \"lcp\"", "engine.mujoco.solver", "newton");
  refused("cone = \"round\"", "engine.mujoco.cone", "elliptic");
  refused("iterations = 0", "engine.mujoco.iterations", "1");
  refused("substeps = 0", "engine.mujoco.substeps", "1");
  refused("max_contacts = 0", "engine.mujoco.max_contacts", "1");
  refused("solref = [0.02, -1.0]", "engine.mujoco.solref", "timeconst > 0");
  refused("solimp = [0.9, 0.95, 0.001]", "engine.mujoco.solimp", "5 numbers");
  refused("solimp = [0.9, 1.5, 0.001, 0.5, 2]", "engine.mujoco.solimp", "[0.0001, 0.9999]");
  refused("stiffness = 3", "engine.mujoco.stiffness", "");
}

TEST_CASE("mujoco: a towed body keeps its path through the ice", "[mujoco]") {
  if (!test::have_engine("mujoco")) return;
  // The prescribed body pushes a free floe: its own path is exact, the floe is pushed ahead.
  const std::string text = test::header_toml(20.0, 0.01, 0.1, 0.3) +
                           "[tow]\nmode = \"velocity\"\nbody = \"berg\"\npath = [[0.0, 0.5, 0.0]]\n" +
                           test::body_toml({"berg", test::box({0, 0}, 20, 20), {0.5, 0.0}, 0.0, false, {}, 2.0}) +
                           test::body_toml({"floe", test::box({12.01, 0}, 4, 4), {}, 0.0, false, {}, 0.5});
  const Scene s = test::scene_from(text);
  Stepper stepper(s, "mujoco");
  for (std::int64_t k = 0; k < s.run.steps(); ++k) stepper.step();
  CHECK(stepper.state().position[0].x == Approx(10.0).epsilon(1e-9));
  CHECK(stepper.state().position[0].y == Approx(0.0).margin(1e-9));
  CHECK(stepper.state().position[1].x > 12.0 + 10.0 - 1.0);  // ahead of the berg's face
}
