// The loader's overlap check (find_overlap) against every pair of parts tested by SAT: the
// broad phase it takes its candidates from may skip no overlapping pair, and the pair it names
// is the first in body order, with the deepest overlap of the two bodies' parts.
#include <catch2/catch.hpp>

#include <algorithm>
#include <optional>
#include <random>

#include "floe_polygon.hpp"
#include "geometry/sat.hpp"
#include "scene/overlap.hpp"

using namespace floedem;

namespace {

/// The same answer by brute force: every pair of parts of distinct bodies.
std::optional<BodyOverlap> all_pairs(const Scene& scene) {
  auto world = [&](std::size_t i, const std::vector<Vec2>& local) {
    std::vector<Vec2> v;
    for (const Vec2 p : local) v.push_back(scene.bodies[i].centroid + p);
    return v;
  };
  auto normals = [](const std::vector<Vec2>& v) {
    std::vector<Vec2> n;
    for (std::size_t k = 0; k < v.size(); ++k) {
      const Vec2 p = v[k], q = v[(k + 1) % v.size()];
      n.push_back(normalized(Vec2{q.y - p.y, p.x - q.x}));
    }
    return n;
  };
  std::optional<BodyOverlap> found;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    for (std::size_t j = i + 1; j < scene.bodies.size(); ++j)
      for (const auto& pi : scene.bodies[i].local_parts)
        for (const auto& pj : scene.bodies[j].local_parts) {
          const auto vi = world(i, pi), vj = world(j, pj), ni = normals(vi), nj = normals(vj);
          const ConvexView a{vi.data(), ni.data(), static_cast<int>(vi.size())};
          const ConvexView b{vj.data(), nj.data(), static_cast<int>(vj.size())};
          const double sep = std::max(max_face_separation(a, b).separation, max_face_separation(b, a).separation);
          const double tolerance = 1e-9 * (length(bounds_of(vi).hi - bounds_of(vi).lo) +
                                           length(bounds_of(vj).hi - bounds_of(vj).lo));
          if (sep < -tolerance && (!found || (found->a == i && found->b == j && -sep > found->depth)))
            found = BodyOverlap{i, j, -sep};
        }
  return found;
}

}  // namespace

TEST_CASE("overlap check: the first overlapping pair of bodies, as every pair of parts finds it", "[input]") {
  // Fields of floe-like polygons (some of two parts: an L of two boxes) with a power-law spread
  // of sizes and one body far larger than the rest, scattered more or less densely: from none
  // overlapping to many.
  for (const double spacing : {60.0, 25.0, 12.0}) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
      INFO("spacing " << spacing << " seed " << seed);
      std::mt19937_64 rng(seed);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      Scene scene;
      const int n = 400;
      for (int k = 0; k < n; ++k) {
        BodySpec b;
        b.centroid = {spacing * (k % 20) + 3.0 * u(rng), spacing * (k / 20) + 3.0 * u(rng)};
        const double size = k == 7 ? 80.0 : 2.0 * std::pow(10.0, 0.8 * u(rng));
        if (k % 9 == 4) {  // two convex parts
          b.local_parts = {{{0, 0}, {size, 0}, {size, 0.3 * size}, {0, 0.3 * size}},
                           {{0, 0.3 * size}, {0.3 * size, 0.3 * size}, {0.3 * size, size}, {0, size}}};
        } else {
          b.local_parts = {test::jittered_polygon(rng, 5 + k % 4, size)};
        }
        scene.bodies.push_back(b);
      }
      const auto expected = all_pairs(scene);
      const auto got = find_overlap(scene);
      REQUIRE(got.has_value() == expected.has_value());
      if (got) {
        CHECK(got->a == expected->a);
        CHECK(got->b == expected->b);
        CHECK(got->depth == expected->depth);
      }
      if (spacing == 60.0) {  // all apart but the large body (7) and its neighbours
        REQUIRE(got.has_value());
        CHECK(got->b == 7);
      }
    }
  }
}

TEST_CASE("overlap check: touching parts are no overlap, a hair's overlap is", "[input]") {
  Scene scene;
  BodySpec a, b;
  a.centroid = {0, 0};
  a.local_parts = {{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}};
  b.centroid = {2, 0.5};
  b.local_parts = a.local_parts;
  scene.bodies = {a, b};
  CHECK_FALSE(find_overlap(scene).has_value());
  scene.bodies[1].centroid = {2 - 1e-6, 0.5};
  const auto hit = find_overlap(scene);
  REQUIRE(hit.has_value());
  CHECK(hit->a == 0);
  CHECK(hit->b == 1);
  CHECK(hit->depth == Approx(1e-6).epsilon(1e-3));
}
