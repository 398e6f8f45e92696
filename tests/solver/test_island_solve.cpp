// The direct solve of heavy-light islands (native/solver/island_solve.cpp): a heavy iceberg
// pressing light floes against a wall, where Gauss-Seidel alone cannot hold.
#include <catch2/catch.hpp>

#include "floedem/run/simulation.hpp"
#include "solver/island_solve.hpp"
#include "support.hpp"

using namespace floedem;
using test::BodyText;

namespace {

// A wall (face at x = 0), three 1 m floes of 99 kg in a row touching it and each other, and a
// 10 m iceberg of `mass` kg touching the last floe, at 0.2 m/s towards the wall.
Scene chain(double mass, bool direct_solve, double restitution) {
  std::string text = test::header_toml(1.0, 0.05, restitution, 0.3,
                                       std::string("[engine.native]\ndirect_solve = ") +
                                           (direct_solve ? "true" : "false") + "\n");
  text += test::body_toml({"wall", test::box({-1, 0}, 2, 20), {}, 0.0, true});
  for (int k = 0; k < 3; ++k) text += test::body_toml({"floe-" + std::to_string(k), test::box({0.5 + k, 0}, 1, 1), {}, 0.0, false, {}, 0.11});
  text += "[[body]]\nname = \"iceberg\"\nkind = \"iceberg\"\npolygon = [[3, -5], [13, -5], [13, 5], [3, 5]]\n"
          "draft = 10.0\nsail_height = 2.0\nvelocity = [-0.2, 0.0]\nmass = " +
          std::to_string(mass) + "\n";
  return test::scene_from(text);
}

}  // namespace

TEST_CASE("island solve: an iceberg 1e8 times a floe's mass is stopped by the floes against a wall in one step",
          "[island]") {
  // The exact answer of the first step, frictionless in effect (all normals along x): the floes
  // stay at rest against the wall, the iceberg leaves them at e times its approach speed
  // (Newton's law at its new contact; the floe contacts are at rest, target 0).
  for (const double e : {0.0, 0.1}) {
    INFO("restitution " << e);
    const Scene s = chain(1e10, true, e);
    auto engine = test::native(s);
    const double before = kinetic_energy(s, engine->state());
    engine->step(nullptr);
    const BodyStates& b = engine->state();
    // Normal velocities to the solve's tolerance: 1e-2 of its creep, 1e-3 allowed_penetration
    // / dt = 2e-5 m/s (an overlap growing by 1e-8 m a step). Sideways the floes stay put: the
    // first solve takes the sweeps' friction off (found against their wrong normals, held it
    // threw these floes sideways at up to 4e-4 m/s) and the sweeps rebuild it against the exact
    // normals (measured: under 1e-8 m/s).
    CHECK(b.velocity[4].x == Approx(0.2 * e).margin(2e-7));
    for (int k = 1; k <= 3; ++k) {
      CHECK(std::abs(b.velocity[k].x) < 2e-7);
      CHECK(std::abs(b.velocity[k].y) < 1e-7);
    }
    CHECK(kinetic_energy(s, b) <= before);
    CHECK(engine->info().settings.at("direct_solves") == "1");
  }
}

TEST_CASE("island solve: without it, Gauss-Seidel's 50 sweeps barely slow the same iceberg", "[island]") {
  // What the direct solve is for (and that the test above can fail): the sweeps hand on only
  // m / M of the wall's reaction per sweep.
  const Scene s = chain(1e10, false, 0.0);
  auto engine = test::native(s);
  engine->step(nullptr);
  CHECK(engine->state().velocity[4].x < -0.19);
  CHECK(engine->info().settings.at("direct_solves") == "0");
}

TEST_CASE("island solve: a chain held for 20 s stays within the allowed overlap, and costs nothing below the ratio",
          "[island]") {
  // Pressed for 400 steps (the iceberg keeps its momentum against the floes only through the
  // contacts): overlap within 1 % of the floes' 0.11 m thickness.
  const Scene s = chain(1e8, true, 0.1);
  auto engine = test::native(s);
  for (int k = 0; k < 400; ++k) engine->step(nullptr);
  for (int k = 1; k <= 3; ++k) CHECK(engine->state().position[k].x - (k - 0.5) > -0.011 * 0.1);
  CHECK(engine->state().position[4].x > 8.0 - 0.0011);
  // A floe of 99 kg on floes of 99 kg: no island of a mass ratio of 300, no direct solve.
  const Scene light = chain(99.0, true, 0.1);
  auto light_engine = test::native(light);
  for (int k = 0; k < 40; ++k) light_engine->step(nullptr);
  CHECK(light_engine->info().settings.at("direct_solves") == "0");
}

namespace {

// One contact between a light floe (body 0, 99 kg) and an iceberg (body 1, 1e8 kg), normal
// along x from the floe to the iceberg, its floe approaching the iceberg at `closing` m/s
// beyond its target, overlapping by `overlap` m.
struct OnePoint {
  BodyArrays bodies;
  std::vector<Manifold> manifolds{1};
  OnePoint(double closing, double overlap) {
    bodies.position = {{0.0, 0.0}, {6.0, 0.0}};
    bodies.angle = {0.0, 0.0};
    bodies.velocity = {{closing, 0.0}, {0.0, 0.0}};
    bodies.angular_velocity = {0.0, 0.0};
    bodies.inv_mass = {1.0 / 99.0, 1e-8};
    bodies.inv_inertia = {0.0, 0.0};
    Manifold& m = manifolds[0];
    m.body_a = 0;
    m.body_b = 1;
    m.normal = {1.0, 0.0};
    m.point_count = 1;
    m.points[0].separation = -overlap;
    m.points[0].wnn = 1.0 / 99.0 + 1e-8;
  }
};

}  // namespace

TEST_CASE("island solve: a heavy-light point is solved when it would pass the allowed overlap, not for a creep within it",
          "[island]") {
  // The engine's trigger at dt = 0.05 s and allowed_penetration = 1 mm: closing speed 0.02 m/s,
  // creep 2e-5 m/s (island_stage.cpp).
  const IslandSolver::Trigger trigger{.creep = 2e-5, .closing = 0.02, .dt = 0.05, .allowed_overlap = 1e-3,
                                      .tolerance = 2e-7};
  auto selected = [&](double closing, double overlap) {
    OnePoint p(closing, overlap);
    IslandSolver solver;
    return solver.select(p.manifolds, p.bodies, trigger, 300.0);
  };
  CHECK(selected(0.03, 0.0));        // the step alone adds 1.5 mm
  CHECK_FALSE(selected(0.01, 0.0));  // 0.5 mm, and none yet: the sweeps' answer stands
  CHECK(selected(0.01, 0.6e-3));     // 0.5 mm more on 0.6 mm passes 1 mm
  CHECK(selected(1e-4, 0.999e-3));   // a slow creep at the allowed overlap
  CHECK_FALSE(selected(1e-5, 2e-3)); // below the creep: rounding, whatever the overlap
  CHECK_FALSE(selected(-0.01, 0.0)); // separating
  // Equal masses: never, however fast (the mass ratio).
  OnePoint light(0.5, 0.0);
  light.bodies.inv_mass[1] = 1.0 / 99.0;
  IslandSolver solver;
  CHECK_FALSE(solver.select(light.manifolds, light.bodies, trigger, 300.0));
}
