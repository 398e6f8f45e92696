// The local contact law (native/solver/local_law.hpp), the one every sweep makes. Held to: the
// complementarity conditions it states (Signorini on the normal, Coulomb's cone and maximal
// dissipation on the tangent) on random points of every case; the lanes' result the same bits
// as one point's, lane by lane, whichever case each lane falls in.
#include <catch2/catch.hpp>

#include <array>
#include <bit>
#include <cmath>
#include <random>

#include "geometry/lanes4.hpp"
#include "solver/local_law.hpp"

using namespace floedem;

namespace {

struct Point {
  double ufn, uft, target, mu, wnn, wnt, wtt;
};

// A random point: a Delassus block J M^-1 J^T of two bodies of random mass, inertia and lever
// arms (so positive definite, with W_nt of either sign and large against the diagonal where
// the lever arms are long), velocities and target of either sign, friction 0 to 1.
Point random_point(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), positive(0.05, 1.0);
  const double ma = positive(rng), mb = positive(rng) * (unit(rng) > -0.6 ? 1.0 : 0.0);
  const double ia = positive(rng), ib = positive(rng) * (mb > 0.0 ? 1.0 : 0.0);
  const double rna = 3.0 * unit(rng), rta = 3.0 * unit(rng), rnb = 3.0 * unit(rng), rtb = 3.0 * unit(rng);
  Point p;
  p.wnn = ma + mb + ia * rna * rna + ib * rnb * rnb;
  p.wnt = ia * rna * rta + ib * rnb * rtb;
  p.wtt = ma + mb + ia * rta * rta + ib * rtb * rtb;
  p.ufn = unit(rng);
  p.uft = 2.0 * unit(rng);
  p.target = unit(rng) > 0.0 ? 0.0 : 0.5 * unit(rng);
  p.mu = unit(rng) > -0.8 ? 0.5 * (1.0 + unit(rng)) : 0.0;
  return p;
}

std::array<double, 2> solve(const Point& p) {
  double pn = 0.0, pt = 0.0;
  local_law<ScalarOps>(p.ufn, p.uft, p.target, p.mu, p.wnn, p.wnt, p.wtt, pn, pt);
  return {pn, pt};
}

}  // namespace

TEST_CASE("the local law meets Signorini and Coulomb on every case", "[law]") {
  std::mt19937_64 rng(11);
  int apart = 0, stick = 0, slide = 0, frictionless = 0;
  for (int i = 0; i < 20000; ++i) {
    const Point p = random_point(rng);
    const auto [pn, pt] = solve(p);
    const double un = p.ufn + p.wnn * pn + p.wnt * pt, ut = p.uft + p.wnt * pn + p.wtt * pt;
    const double scale = std::abs(p.ufn) + std::abs(p.uft) + std::abs(p.target) + 1.0;
    const double tol = 1e-12 * scale;
    INFO("point " << i << ": P = (" << pn << ", " << pt << "), u+ = (" << un << ", " << ut << ")");
    REQUIRE(pn >= 0.0);
    REQUIRE(un >= p.target - tol);                    // never closing faster than the target
    REQUIRE(pn * (un - p.target) <= tol * (pn + 1));  // an impulse only where the target is met
    REQUIRE(std::abs(pt) <= p.mu * pn * (1 + 1e-12) + 1e-300);
    if (pn == 0.0) {
      ++apart;
    } else if (p.mu == 0.0) {
      ++frictionless;
      REQUIRE(pt == 0.0);
    } else if (std::abs(pt) < p.mu * pn * (1 - 1e-9)) {
      ++stick;
      REQUIRE(std::abs(ut) <= tol);  // inside the cone: no slip
    } else {
      ++slide;
      REQUIRE(ut * pt <= tol * pn);  // on the cone: friction opposes the slip
    }
  }
  // Every case was met often enough for the conditions above to mean something.
  CHECK(apart > 1000);
  CHECK(stick > 1000);
  CHECK(slide > 1000);
  CHECK(frictionless > 1000);
}

TEST_CASE("the local law on four lanes gives each lane one point's bits", "[law]") {
  using namespace lanes4;
  std::mt19937_64 rng(12);
  for (int i = 0; i < 20000; ++i) {
    std::array<Point, 4> q;
    for (Point& p : q) p = random_point(rng);
    auto lane = [&](double Point::*f) { return lanes(q[0].*f, q[1].*f, q[2].*f, q[3].*f); };
    v4d pn, pt;
    local_law<lanes4::Ops>(lane(&Point::ufn), lane(&Point::uft), lane(&Point::target), lane(&Point::mu),
                           lane(&Point::wnn), lane(&Point::wnt), lane(&Point::wtt), pn, pt);
    for (int l = 0; l < 4; ++l) {
      const auto [n, t] = solve(q[static_cast<std::size_t>(l)]);
      INFO("bundle " << i << " lane " << l);
      REQUIRE(std::bit_cast<std::uint64_t>(pn[l]) == std::bit_cast<std::uint64_t>(n));
      REQUIRE(std::bit_cast<std::uint64_t>(pt[l]) == std::bit_cast<std::uint64_t>(t));
    }
  }
}
