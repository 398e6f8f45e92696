#include <catch2/catch.hpp>

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
