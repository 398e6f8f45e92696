#include <catch2/catch.hpp>

#include "solver/narrow_phase.hpp"
#include "support.hpp"

using namespace floedem;

namespace {

struct Poly {
  std::vector<Vec2> local, local_n, world, world_n;
  Transform x;
  Poly(std::vector<Vec2> pts, Vec2 c, double q) : x{c, Rot::from_angle(q)} {
    const std::size_t n = pts.size();
    for (std::size_t i = 0; i < n; ++i) {
      local.push_back(pts[i]);
      const Vec2 e = pts[(i + 1) % n] - pts[i];
      local_n.push_back(normalized(Vec2{e.y, -e.x}));
    }
    for (std::size_t i = 0; i < n; ++i) {
      world.push_back(x.apply(local[i]));
      world_n.push_back(x.q.apply(local_n[i]));
    }
  }
  PartGeometry geometry() const {
    return {ConvexView{world.data(), world_n.data(), static_cast<int>(world.size())}, local.data(), local_n.data(), x};
  }
};

std::vector<Vec2> square(double s) { return test::box({0, 0}, s, s); }

}  // namespace

TEST_CASE("face-on-face contact gives two points at the ends of the shared face", "[narrow]") {
  const Poly a(square(10), {0, 0}, 0.0);
  const Poly b(square(10), {10.0 - 0.02, 5.0}, 0.0);  // overlapping by 2 cm, shifted half a face
  Manifold m;
  collide(a.geometry(), b.geometry(), 0.0, 1e-4, m);
  REQUIRE(m.point_count == 2);
  CHECK(m.normal.x == Approx(1.0).margin(1e-15));
  for (int k = 0; k < 2; ++k) CHECK(m.points[k].separation == Approx(-0.02).margin(1e-12));
  const double y0 = std::min(m.points[0].point.y, m.points[1].point.y);
  const double y1 = std::max(m.points[0].point.y, m.points[1].point.y);
  CHECK(y0 == Approx(0.0).margin(1e-12));  // clipped to b's bottom edge
  CHECK(y1 == Approx(5.0).margin(1e-12));  // a's top corner
  CHECK(m.points[0].id != m.points[1].id);
}

TEST_CASE("corner on face gives one point at the corner", "[narrow]") {
  const double d = 5.0 * std::sqrt(2.0);
  const Poly a(square(10), {0, 0}, 0.0);
  const Poly b(square(10), {5.0 + d - 0.01, 2.0}, M_PI / 4);  // corner 1 cm into a's right face
  Manifold m;
  collide(a.geometry(), b.geometry(), 0.0, 1e-4, m);
  REQUIRE(m.point_count == 1);
  CHECK(m.normal.x == Approx(1.0).margin(1e-12));
  CHECK(m.points[0].separation == Approx(-0.01).margin(1e-9));
  CHECK(m.points[0].point.x == Approx(4.995).margin(1e-9));  // midway between corner and face
  CHECK(m.points[0].point.y == Approx(2.0).margin(1e-9));
}

TEST_CASE("separated polygons: contact only within the margin", "[narrow]") {
  const Poly a(square(10), {0, 0}, 0.0);
  const Poly b(square(10), {10.8, 0.0}, 0.1);  // nearest corner 0.33 m from a's face
  Manifold m;
  collide(a.geometry(), b.geometry(), 0.01, 1e-4, m);
  CHECK(m.point_count == 0);
  collide(a.geometry(), b.geometry(), 1.0, 1e-4, m);
  CHECK(m.point_count >= 1);
  for (int k = 0; k < m.point_count; ++k) CHECK(m.points[k].separation > 0.0);
}

TEST_CASE("normal points from a to b whichever face is the reference", "[narrow]") {
  // b's face is the better axis here: a is turned so that its corner meets b's face.
  const double d = 5.0 * std::sqrt(2.0);
  const Poly a(square(10), {0, 0}, M_PI / 4);
  const Poly b(square(10), {d + 5.0 - 0.01, 0.0}, 0.0);
  Manifold m;
  collide(a.geometry(), b.geometry(), 0.0, 1e-4, m);
  REQUIRE(m.point_count == 1);
  CHECK(m.reference_is_b);
  CHECK(m.normal.x == Approx(1.0).margin(1e-12));
  CHECK(m.points[0].separation == Approx(-0.01).margin(1e-9));
}
