// The loader's overlap check (find_overlap) against every pair of parts tested by SAT: the
// broad phase it takes its candidates from may skip no overlapping pair, and the pair it names
// is the first in body order, with the deepest overlap of the two bodies' parts.
#include <catch2/catch.hpp>

#include <algorithm>
#include <optional>
#include <random>

#include "floe_polygon.hpp"
#include "geometry/sat.hpp"
#include "collision/overlap.hpp"

using namespace floedem;

namespace {

/// The same answer by brute force: every pair of parts of distinct bodies whose boxes overlap.
std::optional<BodyOverlap> all_pairs(const Scene& scene) {
  struct Part {
    std::size_t body;
    std::vector<Vec2> vertices, normals;
    Aabb box;
  };
  std::vector<Part> parts;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    for (const auto& local : scene.bodies[i].local_parts) {
      Part p{i, {}, {}, {}};
      for (const Vec2 v : local) p.vertices.push_back(scene.bodies[i].centroid + v);
      for (std::size_t k = 0; k < p.vertices.size(); ++k) {
        const Vec2 a = p.vertices[k], b = p.vertices[(k + 1) % p.vertices.size()];
        p.normals.push_back(normalized(Vec2{b.y - a.y, a.x - b.x}));
      }
      p.box = bounds_of(p.vertices);
      parts.push_back(std::move(p));
    }
  std::optional<BodyOverlap> found;
  for (const Part& p : parts)
    for (const Part& q : parts) {
      if (p.body >= q.body || !p.box.overlaps(q.box)) continue;
      const ConvexView a{p.vertices.data(), p.normals.data(), static_cast<int>(p.vertices.size())};
      const ConvexView b{q.vertices.data(), q.normals.data(), static_cast<int>(q.vertices.size())};
      const double sep = std::max(max_face_separation(a, b).separation, max_face_separation(b, a).separation);
      const double tolerance = 1e-9 * (length(p.box.hi - p.box.lo) + length(q.box.hi - q.box.lo));
      if (!(sep < -tolerance)) continue;
      const BodyOverlap o{p.body, q.body, -sep};
      if (!found || o.a < found->a || (o.a == found->a && (o.b < found->b || (o.b == found->b && o.depth > found->depth))))
        found = o;
    }
  return found;
}

}  // namespace

TEST_CASE("overlap check: the first overlapping pair of bodies, as every pair of parts finds it", "[input]") {
  // Fields of floe-like polygons (some of two parts: an L of two boxes) with a power-law spread
  // of sizes and one body far larger than the rest, scattered more or less densely: from the
  // large body's overlaps alone to many.
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
