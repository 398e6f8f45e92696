#pragma once
// A pressed pack of box floes and its contact manifolds, built directly (no narrow phase): the
// contact solver's tests (test_coloured_sweeps.cpp) solve it.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "solver/contact_solver.hpp"

namespace floedem::test {

// A pressed pack: columns x rows of unit-density boxes of side 8 to 12 m on a grid, each
// touching its right and upper neighbour at two points, the left column against a fixed wall
// (body 0). Random velocities (a few pressed together, most drifting), so that the sweeps have
// collisions, resting contacts, sticking and sliding friction to solve.
struct Pack {
  BodyArrays bodies;
  std::vector<Manifold> manifolds;
};

inline Pack pack(int columns, int rows, std::uint32_t seed, bool shuffled) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Pack p;
  const std::size_t n = static_cast<std::size_t>(columns * rows) + 1;
  p.bodies.resize(n);
  p.bodies.rotation.assign(n, Rot::from_angle(0.0));
  p.bodies.inv_mass.assign(n, 0.0);
  p.bodies.inv_inertia.assign(n, 0.0);
  auto id = [&](int c, int r) { return 1 + r * columns + c; };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) {
      const auto b = static_cast<std::size_t>(id(c, r));
      const double side = 8.0 + 4.0 * u(rng), mass = 900.0 * side * side;
      p.bodies.position[b] = {10.0 * c + 5.0, 10.0 * r + 5.0};
      p.bodies.velocity[b] = {-0.5 * u(rng), 0.2 * (u(rng) - 0.5)};
      p.bodies.angular_velocity[b] = 0.01 * (u(rng) - 0.5);
      p.bodies.inv_mass[b] = 1.0 / mass;
      p.bodies.inv_inertia[b] = 12.0 / (mass * 2.0 * side * side);
    }
  auto join = [&](std::int32_t a, std::int32_t b, Vec2 normal, Vec2 at) {
    Manifold m;
    m.body_a = a;
    m.body_b = b;
    m.part_a = a;
    m.part_b = b;
    m.normal = normal;
    m.friction = 0.3;
    m.restitution = 0.1;
    m.point_count = 2;
    const Vec2 along = perp(normal);
    for (int k = 0; k < 2; ++k) {
      m.points[k].point = at + (k == 0 ? 3.0 : -3.0) * along;
      m.points[k].separation = -0.01 * u(rng);
      m.points[k].id = static_cast<std::uint32_t>(k);
    }
    prepare_contact(m, p.bodies, 0.05, 0.01);
    for (ManifoldPoint& q : m.points) q.normal_impulse = u(rng) < 0.5 ? 1e3 * u(rng) : 0.0;  // a warm start
    p.manifolds.push_back(m);
  };
  for (int r = 0; r < rows; ++r) {
    join(0, id(0, r), {1.0, 0.0}, {0.0, 10.0 * r + 5.0});
    for (int c = 0; c < columns; ++c) {
      if (c + 1 < columns) join(id(c, r), id(c + 1, r), {1.0, 0.0}, {10.0 * c + 10.0, 10.0 * r + 5.0});
      if (r + 1 < rows) join(id(c, r), id(c, r + 1), {0.0, 1.0}, {10.0 * c + 5.0, 10.0 * r + 10.0});
    }
  }
  // The engine's order is by pair (the field generator numbers floes about in space); shuffled,
  // each part's rows wait on the other's all through the sweep.
  if (shuffled) std::shuffle(p.manifolds.begin(), p.manifolds.end(), rng);
  return p;
}

inline bool same_bits(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec2)) == 0;
}
inline bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}
inline bool same_impulses(const std::vector<Manifold>& a, const std::vector<Manifold>& b) {
  for (std::size_t k = 0; k < a.size(); ++k)
    for (int j = 0; j < a[k].point_count; ++j)
      if (!floedem::same_bits(a[k].points[j].normal_impulse, b[k].points[j].normal_impulse) ||
          !floedem::same_bits(a[k].points[j].tangent_impulse, b[k].points[j].tangent_impulse))
        return false;
  return true;
}

/// The same velocities and impulses to the bit (a pack solved two ways).
inline void check_same_solve(const Pack& a, const Pack& b) {
  CHECK(same_bits(a.bodies.velocity, b.bodies.velocity));
  CHECK(same_bits(a.bodies.angular_velocity, b.bodies.angular_velocity));
  CHECK(same_impulses(a.manifolds, b.manifolds));
}

/// Every body's pose and velocity the same to the bit (an engine run two ways).
inline void check_same_state(const BodyStates& a, const BodyStates& b) {
  CHECK(same_bits(a.velocity, b.velocity));
  CHECK(same_bits(a.angular_velocity, b.angular_velocity));
  CHECK(same_bits(a.position, b.position));
  CHECK(same_bits(a.angle, b.angle));
}

}  // namespace floedem::test
