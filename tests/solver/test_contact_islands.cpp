// Contact islands (native/solver/contact_islands.cpp) and the velocity solve island by island
// (island_stage.cpp, IslandStage::solve).
#include <catch2/catch.hpp>

#include "run/stepper.hpp"
#include "solver/contact_islands.hpp"
#include "support.hpp"

using namespace floedem;
using test::BodyText;

namespace {

Manifold joining(std::int32_t a, std::int32_t b) {
  Manifold m;
  m.body_a = a;
  m.body_b = b;
  m.point_count = 1;
  return m;
}

std::vector<std::int32_t> list(std::span<const std::int32_t> s) { return {s.begin(), s.end()}; }

// Two floes that meet obliquely with spin (collision, friction, rotation) near the origin and,
// with `pressed_row`, 1 km away a row of ten floes pushed along x onto a fixed wall by a force
// on the last one: a pressed chain that takes every sweep the limits give it.
std::string scene_text(bool pressed_row) {
  std::string text = test::header_toml(10.0, 0.05, 0.3, 0.4);
  text += test::body_toml({"a", test::box({0, 0}, 6, 4, 0.2), {0.6, 0.1}, 0.05});
  text += test::body_toml({"b", test::box({9, 1.5}, 5, 5, -0.3), {-0.4, 0.0}, -0.02});
  if (pressed_row) {
    text += test::body_toml({"wall", test::box({999, 0}, 2, 40), {}, 0.0, true});
    for (int k = 0; k < 10; ++k)
      text += test::body_toml({"row-" + std::to_string(k), test::box({1000.5 + 1.0 * k, 0}, 1, 1), {}, 0.0, false,
                               k == 9 ? Vec2{-2e4, 0.0} : Vec2{}});
  }
  return text;
}

Scene scene(bool pressed_row, const std::vector<std::string>& sets = {}) {
  return test::scene_from(scene_text(pressed_row), sets);
}

}  // namespace

TEST_CASE("contact islands: manifolds join through moving bodies, never through fixed or prescribed ones",
          "[islands]") {
  BodyArrays bodies;
  bodies.resize(7);
  bodies.inv_mass = {0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};  // body 0 fixed
  bodies.inv_inertia = {0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
  // m0 1-2, m1 0-3 (through the fixed body only), m2 4-5, m3 0-1, m4 2-4: 1, 2, 4, 5 are one
  // island (m0, m4, m2); 3 is alone, though the fixed body 0 touches both 1 and 3.
  const std::vector<Manifold> manifolds{joining(1, 2), joining(0, 3), joining(4, 5), joining(0, 1), joining(2, 4)};
  ContactIslands islands;
  islands.build(manifolds, bodies);
  REQUIRE(islands.size() == 2);
  // Numbered by their first manifold, each keeping the manifolds' order (a sweep over an
  // island visits them as a sweep over all would).
  CHECK(list(islands.manifolds(0)) == std::vector<std::int32_t>{0, 2, 3, 4});
  CHECK(list(islands.manifolds(1)) == std::vector<std::int32_t>{1});
  CHECK(list(islands.bodies(0)) == std::vector<std::int32_t>{1, 2, 4, 5});
  CHECK(list(islands.bodies(1)) == std::vector<std::int32_t>{3});
  CHECK(islands.island_of_manifold(3) == 0);

  // The next step's build forgets this one's.
  const std::vector<Manifold> next{joining(3, 6), joining(1, 2)};
  islands.build(next, bodies);
  REQUIRE(islands.size() == 2);
  CHECK(list(islands.bodies(0)) == std::vector<std::int32_t>{3, 6});
  CHECK(list(islands.bodies(1)) == std::vector<std::int32_t>{1, 2});
  islands.build({}, bodies);
  CHECK(islands.size() == 0);

  // Bodies 5 and 6 asleep (held like fixed ones): their manifold with each other and with the
  // fixed body are in no island, and the rest are numbered as if those were absent.
  bodies.inv_mass[5] = bodies.inv_mass[6] = bodies.inv_inertia[5] = bodies.inv_inertia[6] = 0.0;
  const std::vector<Manifold> held{joining(5, 6), joining(1, 2), joining(0, 6), joining(2, 3)};
  islands.build(held, bodies);
  REQUIRE(islands.size() == 1);
  CHECK(list(islands.manifolds(0)) == std::vector<std::int32_t>{1, 3});
  CHECK(list(islands.bodies(0)) == std::vector<std::int32_t>{1, 2, 3});
  CHECK(islands.island_of_manifold(0) == -1);
  CHECK(islands.island_of_manifold(2) == -1);
  CHECK(islands.body_count() == 3);
}

TEST_CASE("contact islands: an island's solve does not depend on the rest of the scene", "[islands]") {
  // The two floes' collision, alone and beside a pressed row that sweeps to its limits every
  // step: solved as one system, the row kept the pair sweeping (and the conjugate-gradient
  // steps mixed the two), so the pair's motion changed with a contact 1 km away. Solved
  // island by island, the pair's 200 steps are the same to the bit.
  const Scene alone = scene(false), beside = scene(true);
  Stepper a(alone, "native"), b(beside, "native");
  bool touched = false;
  for (int step = 0; step < 200; ++step) {
    a.step();
    b.step();
    touched = touched || !a.contacts().empty();
  }
  REQUIRE(touched);
  // The row was hard work: many sweeps a step on the average.
  CHECK(std::stod(b.engine().info().settings.at("mean_sweeps_per_step")) > 20.0);
  for (int i = 0; i < 2; ++i) {
    INFO("floe " << i);
    CHECK(same_bits(a.state().position[i].x, b.state().position[i].x));
    CHECK(same_bits(a.state().position[i].y, b.state().position[i].y));
    CHECK(same_bits(a.state().angle[i], b.state().angle[i]));
    CHECK(same_bits(a.state().velocity[i].x, b.state().velocity[i].x));
    CHECK(same_bits(a.state().angular_velocity[i], b.state().angular_velocity[i]));
  }
}

TEST_CASE("contact islands: a large island gets a few plain sweeps, a smaller one sweeps to converge", "[islands]") {
  // The pressed row of ten floes, an island of ten manifolds at most: taken for a large island
  // (large_island_manifolds = 1), never more than large_island_iterations sweeps a step (the
  // extra sweeps off, so that the count is the limit's); below the threshold, the row's hard
  // work of the test above.
  auto mean_sweeps = [](const std::string& threshold) {
    // The Stepper keeps a reference to its scene: the scene must outlive it.
    const Scene row = scene(true, {"engine.native.large_island_manifolds=" + threshold,
                                   "engine.native.large_island_iterations=2", "engine.native.extra_iterations=0"});
    Stepper s(row, "native");
    for (int step = 0; step < 200; ++step) s.step();
    return std::stod(s.engine().info().settings.at("mean_sweeps_per_step"));
  };
  const double large = mean_sweeps("1"), small = mean_sweeps("11");
  CHECK(large > 0.0);
  CHECK(large <= 2.0);
  CHECK(small > 20.0);
}
