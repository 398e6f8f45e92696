// The position projection (solve_positions, native/solver/contact_solver.cpp): a manifold whose
// bodies kept their poses since its gaps were last measured is not measured again. Checked
// against sweeps that measure every manifold (one sweep per call: a call's first sweep measures
// all): the same poses and the same deepest overlap to the bit, with fewer measurements.
#include <catch2/catch.hpp>

#include <cmath>

#include "solver/contact_solver.hpp"

using namespace floedem;

namespace {

// Two chains of unit squares of 1 kg (I = 1/6 kg m^2), each square touching the next across
// its right face at two points: the first, of 4 squares slightly turned (so that the
// corrections turn them too), against a fixed wall (body 0) with 2 cm overlaps (many sweeps to
// bring under the 1 mm allowed); the second, of 10 squares apart from it, with 0.5 mm overlaps
// (within the allowed: nothing to correct, so measured once); and a lone square 2 cm into a
// second wall (a manifold that alone moves its bodies: measured again in every sweep).
struct Chains {
  BodyArrays bodies;
  std::vector<Manifold> manifolds;
  static constexpr int kDeep = 5, kShallow = 9;  // manifolds of each chain
};

Chains chains() {
  Chains c;
  BodyArrays& b = c.bodies;
  auto add = [&](Vec2 p, double angle, double inv_mass, double inv_inertia) {
    b.position.push_back(p);
    b.angle.push_back(angle);
    b.rotation.push_back(Rot::from_angle(angle));
    b.velocity.push_back({});
    b.angular_velocity.push_back(0.0);
    b.inv_mass.push_back(inv_mass);
    b.inv_inertia.push_back(inv_inertia);
  };
  auto touch = [&](int a, int bb, Vec2 face_point) {
    Manifold m;
    m.part_a = m.body_a = a;
    m.part_b = m.body_b = bb;
    m.normal = {1.0, 0.0};
    m.local_normal = {1.0, 0.0};
    m.local_face_point = face_point;
    m.point_count = 2;
    m.points[0].local_incident = {-0.5, 0.5};
    m.points[1].local_incident = {-0.5, -0.5};
    c.manifolds.push_back(m);
  };
  add({-1.0, 0.0}, 0.0, 0.0, 0.0);  // the wall, 2 m wide: its right face at x = 0
  for (int k = 0; k < 4; ++k) add({0.5 + 0.98 * k, 0.0}, 0.002 * ((k % 3) - 1), 1.0, 6.0);
  for (int k = 0; k < 10; ++k) add({0.5 + 0.9995 * k, 10.0}, 0.0, 1.0, 6.0);
  touch(0, 1, {1.0, 0.5});
  for (int k = 1; k < 4; ++k) touch(k, k + 1, {0.5, 0.5});
  for (int k = 5; k < 14; ++k) touch(k, k + 1, {0.5, 0.5});
  add({-1.0, -10.0}, 0.0, 0.0, 0.0);  // bodies 15 and 16
  add({0.48, -10.0}, 0.001, 1.0, 6.0);
  touch(15, 16, {1.0, 0.5});
  return c;
}

}  // namespace

TEST_CASE("position projection: skipping unmoved manifolds changes no bit, and skips the shallow chain",
          "[solver][projection]") {
  NativeSettings settings;
  settings.position_iterations = 1000;
  Chains skipping = chains();
  ProjectionWork work;
  const double deepest = solve_positions(skipping.manifolds, skipping.bodies, settings, work);

  // The same sweeps one per call, stopping where solve_positions stops.
  NativeSettings one = settings;
  one.position_iterations = 1;
  Chains every = chains();
  ProjectionWork fresh;
  double every_deepest = 0.0;
  int sweeps = 0;
  while (sweeps < settings.position_iterations) {
    every_deepest = solve_positions(every.manifolds, every.bodies, one, fresh);
    ++sweeps;
    if (every_deepest <= 1.5 * settings.allowed_penetration) break;
  }
  INFO("sweeps " << sweeps);
  REQUIRE(sweeps > 5);  // the deep chain needs many (measured: 273): the skipping is exercised
  REQUIRE(sweeps < settings.position_iterations);
  CHECK(same_bits(deepest, every_deepest));
  for (std::size_t k = 0; k < every.bodies.position.size(); ++k) {
    INFO("body " << k);
    CHECK(same_bits(skipping.bodies.position[k].x, every.bodies.position[k].x));
    CHECK(same_bits(skipping.bodies.position[k].y, every.bodies.position[k].y));
    CHECK(same_bits(skipping.bodies.angle[k], every.bodies.angle[k]));
    CHECK(same_bits(skipping.bodies.rotation[k].c, every.bodies.rotation[k].c));
  }
  // The shallow chain measured in the first sweep only; the deep one at most once a sweep.
  CHECK(work.clock <= static_cast<std::uint64_t>(Chains::kDeep * sweeps + Chains::kShallow));
  CHECK(fresh.clock == static_cast<std::uint64_t>((Chains::kDeep + Chains::kShallow) * sweeps));
  // The shallow chain did not move; the deep one was spread out from the wall.
  CHECK(skipping.bodies.position[5].x == 0.5);
  CHECK(skipping.bodies.position[4].x > 0.5 + 0.98 * 3 + 0.05);
  CHECK(skipping.bodies.position[16].x > 0.495);
  CHECK(deepest <= 1.5 * settings.allowed_penetration);
}
