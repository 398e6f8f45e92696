#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "geometry/convex_partition.hpp"
#include "geometry/polygon.hpp"
#include "support.hpp"

using namespace floedem;
using Catch::Matchers::WithinRel;

TEST_CASE("rectangle moments equal the closed form", "[geometry]") {
  // Rectangle w x h: A = w h, J_c = A (w^2 + h^2) / 12, anywhere in the plane and turned.
  const double w = 7.0, h = 3.0;
  const auto pts = test::box({1234.5, -987.25}, w, h, 0.3);
  const AreaMoments m = area_moments(pts);
  // Far from the origin the coordinates carry ~1e-13 relative round-off: 1e-12 is ample.
  CHECK_THAT(m.area, WithinRel(w * h, 1e-12));
  CHECK_THAT(m.centroid.x, WithinRel(1234.5, 1e-12));
  CHECK_THAT(m.centroid.y, WithinRel(-987.25, 1e-12));
  CHECK_THAT(m.polar_moment, WithinRel(w * h * (w * w + h * h) / 12.0, 1e-10));
}

TEST_CASE("triangle moments equal the closed form", "[geometry]") {
  // Right triangle with legs a, b: A = a b / 2, centroid (a/3, b/3), J_c = A (a^2 + b^2) / 18.
  const double a = 4.0, b = 6.0;
  const std::vector<Vec2> t{{0, 0}, {a, 0}, {0, b}};
  const AreaMoments m = area_moments(t);
  CHECK_THAT(m.area, WithinRel(a * b / 2, 1e-14));
  CHECK_THAT(m.centroid.x, WithinRel(a / 3, 1e-14));
  CHECK_THAT(m.centroid.y, WithinRel(b / 3, 1e-14));
  CHECK_THAT(m.polar_moment, WithinRel(a * b / 2 * (a * a + b * b) / 18.0, 1e-13));
}

TEST_CASE("concave polygon: moments of the whole equal the sum over its convex parts", "[geometry]") {
  // An L of three unit squares.
  const std::vector<Vec2> l{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  CHECK_FALSE(is_strictly_convex(l));
  const AreaMoments whole = area_moments(l);
  CHECK_THAT(whole.area, WithinRel(3.0, 1e-14));
  const auto parts = convex_partition(l);
  REQUIRE(parts.size() == 2);  // an L needs exactly two convex pieces
  double area = 0, polar = 0;
  Vec2 first;
  for (const auto& p : parts) {
    CHECK(is_strictly_convex(p));
    const AreaMoments m = area_moments(p);
    area += m.area;
    first += m.area * m.centroid;
  }
  const Vec2 c = (1.0 / area) * first;
  for (const auto& p : parts) {
    const AreaMoments m = area_moments(p);
    polar += m.polar_moment + m.area * length_squared(m.centroid - c);  // parallel axes
  }
  CHECK_THAT(area, WithinRel(whole.area, 1e-14));
  CHECK_THAT(c.x, WithinRel(whole.centroid.x, 1e-13));
  CHECK_THAT(polar, WithinRel(whole.polar_moment, 1e-13));
}

namespace {

// Crossing number of p against a simple polygon (p not on its boundary).
bool inside_polygon(const std::vector<Vec2>& poly, Vec2 p) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2 a = poly[i], b = poly[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)) in = !in;
  }
  return in;
}

// Strictly left of every edge of a counter-clockwise convex part.
bool inside_convex(const std::vector<Vec2>& part, Vec2 p) {
  for (std::size_t i = 0; i < part.size(); ++i)
    if (cross(part[(i + 1) % part.size()] - part[i], p - part[i]) <= 0.0) return false;
  return true;
}

}  // namespace

TEST_CASE("polygons with three vertices on a line get convex parts that tile them", "[geometry]") {
  // CGAL's optimal partition fails on these in a release build: the first (found by the fuzzer,
  // four vertices on one horizontal line) made it read freed memory; the rectilinear one came
  // back as a single non-convex part; the cup's parts overlapped. Each must come back as convex
  // parts, built from the polygon's own vertices, covering each interior point exactly once.
  const std::vector<std::vector<Vec2>> polygons{
      {{-78.43, 75.35}, {-78.43, -37.21}, {-19.52, -37.33}, {-14.44, -98.76}, {-16.99, -39.79}, {3.48, -37.32},
       {-16.55, -37.32}, {-13.99, -34.32}, {-6.99, -34.32}, {13.49, -37.32}, {157.09, -37.32}},
      {{1.4, -4.2}, {1.4, -3.4}, {-0.2, -3.4}, {-0.2, 7.8}, {3, 7.8}, {3, 5.4}, {2.2, 5.4}, {2.2, 3}, {3.8, 3}, {3.8, -4.2}},
      {{4, 4}, {6, 6}, {0, 6}, {2, 4}, {2, 2}, {0, 0}, {6, 0}, {4, 2}},
      {{0, 0}, {5, 0}, {5, 2}, {4, 2}, {4, 1}, {3, 1}, {3, 2}, {2, 2}, {2, 1}, {1, 1}, {1, 2}, {0, 2}},
  };
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    INFO("polygon " << k);
    std::vector<Vec2> poly = polygons[k];
    if (signed_area(poly) < 0.0) std::reverse(poly.begin(), poly.end());
    REQUIRE_FALSE(find_self_intersection(poly).has_value());
    const auto parts = convex_partition(poly);
    REQUIRE_FALSE(parts.empty());
    double area = 0.0;
    for (const auto& part : parts) {
      CHECK(is_strictly_convex(part));
      CHECK(signed_area(part) > 0.0);
      for (const Vec2 v : part)
        CHECK(std::any_of(poly.begin(), poly.end(), [&](Vec2 q) { return q.x == v.x && q.y == v.y; }));
      area += area_moments(part).area;
    }
    CHECK_THAT(area, WithinRel(area_moments(poly).area, 1e-12));
    // A grid offset by unequal irrational fractions of its spacing misses every edge (the
    // cup's lie on y = x and x + y = 6).
    const Aabb box = bounds_of(poly);
    const int n = 97;
    int mismatches = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const Vec2 p{box.lo.x + (i + 0.5 * M_SQRT1_2) * (box.hi.x - box.lo.x) / n,
                     box.lo.y + (j + M_1_PI) * (box.hi.y - box.lo.y) / n};
        const auto covering = std::count_if(parts.begin(), parts.end(), [&](const auto& part) { return inside_convex(part, p); });
        if (covering != (inside_polygon(poly, p) ? 1 : 0)) ++mismatches;
      }
    CHECK(mismatches == 0);
  }
}

TEST_CASE("self-intersection and convexity checks", "[geometry]") {
  const std::vector<Vec2> bowtie{{0, 0}, {1, 1}, {1, 0}, {0, 1}};
  CHECK(find_self_intersection(bowtie).has_value());
  const std::vector<Vec2> repeated{{0, 0}, {1, 0}, {1, 1}, {1, 0}};
  CHECK(find_self_intersection(repeated).has_value());
  const std::vector<Vec2> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  CHECK_FALSE(find_self_intersection(square).has_value());
  CHECK(is_strictly_convex(square));
  // A pentagram turns left at every vertex but winds twice: not convex.
  std::vector<Vec2> star;
  for (int k = 0; k < 5; ++k) star.push_back({std::cos(k * 4 * M_PI / 5), std::sin(k * 4 * M_PI / 5)});
  CHECK_FALSE(is_strictly_convex(star));
  CHECK(find_self_intersection(star).has_value());
  // Collinear vertices are dropped.
  const std::vector<Vec2> with_mid{{0, 0}, {1, 0}, {2, 0}, {2, 1}, {0, 1}};
  CHECK(remove_collinear(with_mid).size() == 4);
}
