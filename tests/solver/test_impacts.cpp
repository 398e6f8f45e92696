// Single impacts against closed forms. Every scene starts with the bodies touching, so that the
// impact happens in the first step at the exact geometry the closed form assumes.
#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include "geometry/sat.hpp"
#include "run/stepper.hpp"
#include "support.hpp"

using namespace floedem;
using test::BodyText;

namespace {

constexpr double kSide = 10.0;
constexpr double kMass = 900.0 * kSide * kSide * 1.0;              // 90 000 kg
constexpr double kInertia = kMass * (kSide * kSide * 2.0) / 12.0;  // 1.5e6 kg m^2

struct Impact {
  BodyText a, b;
  double e = 0.3, mu = 0.0;
};

struct After {
  BodyStates state;
  std::vector<ContactRecord> contacts;
};

// `coloured`: the native engine's coloured sweeps (coloured_sweeps.hpp), whose local solve is
// the same law in other arithmetic (reciprocals), held to the same closed forms.
After run_one_step(const Impact& c, bool coloured = false,
                   const std::string& sweeps = "velocity_iterations = 500\ntolerance = 0.0\n") {
  const std::string native = "[engine.native]\n" + sweeps + (coloured ? "coloured_sweeps = true\n" : "");
  const Scene s = test::scene_from(test::header_toml(0.01, 0.01, c.e, c.mu, native) + test::body_toml(c.a) +
                                   test::body_toml(c.b));
  auto engine = test::native(s);
  engine->step(nullptr);
  return {engine->state(), {engine->contacts().begin(), engine->contacts().end()}};
}

// ---- independent closed form: generalised velocities V = (v_a, w_a, v_b, w_b), M = diag,
// contact Jacobians as rows; the impulse P solves the Newton-Coulomb conditions exactly.
using Vec6 = Eigen::Matrix<double, 6, 1>;

struct Closed {
  Vec6 v_after;
  std::vector<double> pn, pt;
};

Eigen::Matrix<double, 1, 6> jacobian(Vec2 dir, Vec2 p, Vec2 xa, Vec2 xb) {
  Eigen::Matrix<double, 1, 6> j;
  const Vec2 ra = p - xa, rb = p - xb;
  j << -dir.x, -dir.y, -cross(ra, dir), dir.x, dir.y, cross(rb, dir);
  return j;
}

/// Frictionless impact at several points (Newton's law at each): the LCP solved by
/// enumerating the active sets.
Closed frictionless(const Vec6& v, const Vec6& minv, const std::vector<Vec2>& pts, Vec2 n, Vec2 xa, Vec2 xb, double e) {
  const int k = static_cast<int>(pts.size());
  Eigen::MatrixXd j(k, 6);
  for (int i = 0; i < k; ++i) j.row(i) = jacobian(n, pts[i], xa, xb);
  const Eigen::VectorXd un = j * v;
  const Eigen::MatrixXd w = j * minv.asDiagonal() * j.transpose();
  for (int mask = (1 << k) - 1; mask > 0; --mask) {
    std::vector<int> act;
    for (int i = 0; i < k; ++i)
      if (mask & (1 << i)) act.push_back(i);
    Eigen::MatrixXd ws(act.size(), act.size());
    Eigen::VectorXd rhs(act.size());
    for (std::size_t r = 0; r < act.size(); ++r) {
      rhs(r) = -(1.0 + e) * un(act[r]);
      for (std::size_t c = 0; c < act.size(); ++c) ws(r, c) = w(act[r], act[c]);
    }
    const Eigen::VectorXd p = ws.fullPivLu().solve(rhs);
    Eigen::VectorXd full = Eigen::VectorXd::Zero(k);
    for (std::size_t r = 0; r < act.size(); ++r) full(act[r]) = p(r);
    const Eigen::VectorXd after = un + w * full;
    bool ok = (full.array() >= -1e-9 * full.cwiseAbs().maxCoeff()).all();
    for (int i = 0; i < k; ++i) ok = ok && after(i) >= -e * un(i) - 1e-12;
    if (ok) {
      Closed c;
      c.v_after = v + minv.asDiagonal() * (j.transpose() * full);
      for (int i = 0; i < k; ++i) {
        c.pn.push_back(full(i));
        c.pt.push_back(0.0);
      }
      return c;
    }
  }
  FAIL("no active set solves the frictionless impact");
  return {};
}

/// One point, Newton restitution with Coulomb friction: stick if the needed tangential impulse
/// is inside the cone, else slide against the final slip.
Closed single_point(const Vec6& v, const Vec6& minv, Vec2 p, Vec2 n, Vec2 xa, Vec2 xb, double e, double mu) {
  Eigen::Matrix<double, 2, 6> j;
  j.row(0) = jacobian(n, p, xa, xb);
  j.row(1) = jacobian(perp(n), p, xa, xb);
  const Eigen::Vector2d u = j * v;
  const Eigen::Matrix2d w = j * minv.asDiagonal() * j.transpose();
  Eigen::Vector2d imp = w.inverse() * Eigen::Vector2d(-(1.0 + e) * u(0), -u(1));  // stick
  if (!(imp(0) >= 0.0 && std::abs(imp(1)) <= mu * imp(0))) {
    bool found = false;
    for (const double s : {1.0, -1.0}) {  // s: sign of the final slip
      const double pn = -(1.0 + e) * u(0) / (w(0, 0) - s * mu * w(0, 1));
      const Eigen::Vector2d cand(pn, -s * mu * pn);
      const double ut = u(1) + (w * cand)(1);
      if (pn >= 0.0 && s * ut >= 0.0) {
        imp = cand;
        found = true;
        break;
      }
    }
    REQUIRE(found);
  }
  Closed c;
  c.v_after = v + minv.asDiagonal() * (j.transpose() * imp);
  c.pn = {imp(0)};
  c.pt = {imp(1)};
  return c;
}

Vec6 generalised(const BodyText& a, const BodyText& b) {
  Vec6 v;
  v << a.velocity.x, a.velocity.y, a.angular_velocity, b.velocity.x, b.velocity.y, b.angular_velocity;
  return v;
}

Vec6 generalised(const BodyStates& s) {
  Vec6 v;
  v << s.velocity[0].x, s.velocity[0].y, s.angular_velocity[0], s.velocity[1].x, s.velocity[1].y, s.angular_velocity[1];
  return v;
}

Vec6 inverse_masses() {
  Vec6 m;
  m << 1 / kMass, 1 / kMass, 1 / kInertia, 1 / kMass, 1 / kMass, 1 / kInertia;
  return m;
}

/// Velocities compared in the units of the impact: speeds against the approach speed,
/// spins times the half side (the speed they give at a corner).
void check_velocities(const Vec6& got, const Vec6& want, double speed, double rel) {
  for (int i = 0; i < 6; ++i) {
    const double scale = (i == 2 || i == 5) ? kSide / 2 : 1.0;
    INFO("component " << i << ": got " << got(i) << ", want " << want(i));
    CHECK(std::abs(got(i) - want(i)) * scale <= rel * speed);
  }
}

void check_momentum(const Vec6& before, const Vec6& after, Vec2 xa, Vec2 xb) {
  // Linear momentum and angular momentum about the origin (positions at the impact; the step
  // moves both bodies, but momentum is read from velocities only).
  const double px0 = kMass * (before(0) + before(3)), py0 = kMass * (before(1) + before(4));
  const double px1 = kMass * (after(0) + after(3)), py1 = kMass * (after(1) + after(4));
  const double scale = kMass * (std::abs(before(0)) + std::abs(before(1)) + std::abs(before(3)) + std::abs(before(4)));
  CHECK(std::abs(px1 - px0) <= 1e-12 * scale);
  CHECK(std::abs(py1 - py0) <= 1e-12 * scale);
  auto l = [&](const Vec6& v) {
    return kInertia * (v(2) + v(5)) + kMass * (cross(xa, Vec2{v(0), v(1)}) + cross(xb, Vec2{v(3), v(4)}));
  };
  CHECK(std::abs(l(after) - l(before)) <= 1e-12 * (scale * (length(xa) + length(xb)) + kInertia * 1e-3));
}

}  // namespace

TEST_CASE("head-on impact of equal squares: restitution, momentum and energy exact", "[impact]") {
  const bool coloured = GENERATE(false, true);
  for (const double e : {0.0, 0.1, 0.3, 0.5, 0.9, 1.0}) {
    INFO("e = " << e << (coloured ? ", coloured sweeps" : ""));
    Impact c;
    c.e = e;
    c.a = {"a", test::box({5, 5}, kSide, kSide), {1.0, 0.0}};
    c.b = {"b", test::box({15, 5}, kSide, kSide)};
    const After r = run_one_step(c, coloured);
    const double va = r.state.velocity[0].x, vb = r.state.velocity[1].x;
    // Achieved restitution: separation speed over approach speed; the tolerance 1e-9 is the
    // requirement, far above round-off (1e-16) and far below any physical meaning.
    CHECK(std::abs((vb - va) / 1.0 - e) <= 1e-9);
    // Momentum m (va + vb) = m * 1: to 1e-12 relative.
    CHECK(std::abs(va + vb - 1.0) <= 1e-12);
    // Energy lost: 1/2 mu_r v^2 (1 - e^2) with the reduced mass mu_r = m / 2.
    const double lost = 0.5 * kMass * 1.0 - 0.5 * kMass * (va * va + vb * vb);
    const double expected = 0.5 * (kMass / 2) * 1.0 * (1.0 - e * e);
    CHECK(std::abs(lost - expected) <= 1e-9 * 0.5 * kMass);
    // Pure translation, no spin, no sideways motion.
    CHECK(std::abs(r.state.angular_velocity[0]) * kSide < 1e-12);
    CHECK(std::abs(r.state.velocity[0].y) < 1e-12);
    // Impulse (1 + e) m / 2, all of it classified a collision.
    double j = 0.0;
    for (const auto& k : r.contacts) {
      CHECK(k.kind == ContactKind::collision);
      j += k.normal_impulse;
    }
    CHECK(j == Approx((1.0 + e) * kMass / 2).epsilon(1e-10));
  }
}

TEST_CASE("an impact among a few bodies is swept to convergence, a large island's few sweeps are not", "[impact]") {
  // Two squares face to face: two points, which Gauss-Seidel couples through the bodies'
  // rotation, so five sweeps leave the restitution 2.5e-4 off. An island this small keeps
  // velocity_iterations (converged to the tolerance); taken for a large island (of at least
  // one manifold), it gets large_island_iterations and misses the 1e-9 of the test above.
  Impact c;
  c.e = 0.1;
  c.a = {"a", test::box({5, 5}, kSide, kSide), {1.0, 0.0}};
  c.b = {"b", test::box({15, 5}, kSide, kSide)};
  auto restitution_error = [&](const std::string& sweeps) {
    const After r = run_one_step(c, false, sweeps);
    return std::abs(r.state.velocity[1].x - r.state.velocity[0].x - c.e);
  };
  CHECK(restitution_error("large_island_iterations = 5\n") <= 1e-9);
  CHECK(restitution_error("large_island_iterations = 5\nlarge_island_manifolds = 1\n") > 1e-9);
}

TEST_CASE("half-overlapping faces: two-point impact against the closed form", "[impact]") {
  const bool coloured = GENERATE(false, true);
  INFO((coloured ? "coloured sweeps" : "sweeps in pair order"));
  Impact c;
  c.a = {"a", test::box({5, 5}, kSide, kSide), {1.0, 0.0}};
  c.b = {"b", test::box({15, 10}, kSide, kSide)};
  const After r = run_one_step(c, coloured);
  const Vec6 v0 = generalised(c.a, c.b);
  const Closed want = frictionless(v0, inverse_masses(), {{10, 5}, {10, 10}}, {1, 0}, {5, 5}, {15, 10}, 0.3);
  check_velocities(generalised(r.state), want.v_after, 1.0, 1e-6);
  double j = 0.0;
  for (const auto& k : r.contacts) j += k.normal_impulse;
  CHECK(j == Approx(want.pn[0] + want.pn[1]).epsilon(1e-6));
  CHECK(j == Approx(42545.5).margin(0.1));  // the exact 2-D answer in docs/engines.md
  check_momentum(v0, generalised(r.state), {5, 5}, {15, 10});
}

TEST_CASE("face on corner, without friction, sticking and sliding", "[impact]") {
  // B turned 45 degrees; its corner on its own centre line meets A's face 2 m off A's centre.
  const double d = 5.0 * std::sqrt(2.0);
  const Vec2 xa{0, 0}, xb{5.0 + d, 2.0}, p{5.0, 2.0};
  struct Case {
    double mu;
    Vec2 va;
    double wa;
    const char* what;
  };
  const Case cases[] = {
      {0.0, {1.0, 0.0}, 0.0, "frictionless"},
      {0.3, {1.0, 0.0}, 0.0, "sticking (docs/engines.md)"},
      {0.05, {1.0, 0.0}, 0.0, "sliding"},
      {0.1, {1.0, 0.6}, 0.05, "oblique, spinning, sliding"},
      {0.8, {1.0, 0.6}, 0.05, "oblique, spinning, sticking"},
      {0.4, {0.8, -0.5}, -0.03, "oblique the other way"},
  };
  const bool coloured = GENERATE(false, true);
  for (const Case& k : cases) {
    INFO(k.what << ", mu = " << k.mu << (coloured ? ", coloured sweeps" : ""));
    Impact c;
    c.mu = k.mu;
    c.a = {"a", test::box(xa, kSide, kSide), k.va, k.wa};
    c.b = {"b", test::box(xb, kSide, kSide, M_PI / 4)};
    const After r = run_one_step(c, coloured);
    const Vec6 v0 = generalised(c.a, c.b);
    const Closed want = single_point(v0, inverse_masses(), p, {1, 0}, xa, xb, 0.3, k.mu);
    check_velocities(generalised(r.state), want.v_after, length(k.va), 1e-6);
    check_momentum(v0, generalised(r.state), xa, xb);
    REQUIRE(r.contacts.size() == 1);
    const ContactRecord& rec = r.contacts[0];
    CHECK(rec.normal_impulse == Approx(want.pn[0]).epsilon(1e-6));
    CHECK(rec.tangent_impulse == Approx(want.pt[0]).margin(1e-6 * want.pn[0]));
    // Coulomb: inside the cone, and on its edge only when sliding.
    CHECK(std::abs(rec.tangent_impulse) <= k.mu * rec.normal_impulse * (1 + 1e-12));
    if (k.mu == 0.0) CHECK(rec.normal_impulse == Approx(52232.1).margin(0.1));  // docs/engines.md
    if (k.mu == 0.3) {
      // Shared notes: vA = (0.40493, -0.05493), omega_B = -0.02330 (given to 5 digits).
      CHECK(r.state.velocity[0].x == Approx(0.40493).margin(1e-5));
      CHECK(r.state.velocity[0].y == Approx(-0.05493).margin(1e-5));
      CHECK(r.state.angular_velocity[1] == Approx(-0.02330).margin(1e-5));
    }
  }
}

TEST_CASE("redetect: a floe struck across a gap within one step meets the next one, not overlaps it", "[impacts]") {
  // Floes of 10 m in a row, 5 cm apart; the first at 5 m/s, e = 1: the second leaves at 5 m/s
  // and crosses its 5 cm gap in the same 0.02 s step (10 cm of travel), which the pairs found
  // at the step's start (its reach was 0) did not include. With redetect the step's contacts
  // are found again at the widened reach: the overlap stays within the allowed 1 mm; without,
  // the second floe runs several cm into the third before the next step sees it.
  auto overlap_after = [](bool redetect) {
    const std::string text =
        test::header_toml(0.2, 0.02, 1.0, 0.0,
                          std::string("[engine.native]\nredetect = ") + (redetect ? "true" : "false") + "\n") +
        test::body_toml({"a", test::box({-10.05, 0}, 10, 10), {5.0, 0}}) +
        test::body_toml({"b", test::box({0, 0}, 10, 10)}) + test::body_toml({"c", test::box({10.05, 0}, 10, 10)});
    const Scene s = test::scene_from(text);
    auto e = test::native(s);
    double deepest = 0.0;
    for (int k = 0; k < 10; ++k) {
      e->step(nullptr);
      for (const ContactRecord& c : e->contacts()) deepest = std::max(deepest, -c.separation);
      // Gaps from the centroids (the boxes stay axis-aligned: head-on, no friction).
      const BodyStates& b = e->state();
      deepest = std::max({deepest, 10.0 - (b.position[1].x - b.position[0].x), 10.0 - (b.position[2].x - b.position[1].x)});
    }
    return deepest;
  };
  CHECK(overlap_after(true) <= 1e-3 + 1e-9);
  CHECK(overlap_after(false) > 1e-2);
}

TEST_CASE("redetect: the islands the widened reach cannot touch are not solved again", "[impacts]") {
  // As in the test above, a floe struck across its 5 cm gap within one step, here onto a fixed
  // wall; 1 km along that wall, five floes pushed against it and sliding along it, each its own
  // island (a fixed body joins none), solved in every step.
  // In a step where the struck floe is found again, only its own island is solved again: the
  // far floes' islands are solved once a step, and their paths and contact impulses are the
  // same to the bit with redetect on and off.
  constexpr int kSteps = 10, kFar = 5;
  struct Run {
    std::vector<double> far_path;
    double islands = 0.0, redetections = 0.0;
  };
  auto run = [](bool redetect, bool row, bool far) {
    std::string text =
        test::header_toml(0.2, 0.02, 1.0, 0.3,
                          std::string("[engine.native]\nredetect = ") + (redetect ? "true" : "false") + "\n");
    // Left out, the struck pair is fixed and still (the bodies keep their numbers).
    text += test::body_toml({"a", test::box({-10.05, 0}, 10, 10), {row ? 5.0 : 0.0, 0}, 0.0, !row}) +
            test::body_toml({"b", test::box({0, 0}, 10, 10), {}, 0.0, !row}) +
            test::body_toml({"wall", test::box({6.05, 550}, 2, 1200), {}, 0.0, true});
    for (int i = 0; far && i < kFar; ++i)
      text += test::body_toml({"far" + std::to_string(i), test::box({0.05, 1000.0 + 50.0 * i}, 10, 10),
                               {0, 0.1137 * (i + 1)}, 0.0, false, {2.7e4, 1.9e4 * (i + 1)}});
    const Scene scene = test::scene_from(text);
    Stepper stepper(scene, "native");  // with the pushes (forcing)
    const Engine* e = &stepper.engine();
    Run r;
    for (int k = 0; k < kSteps; ++k) {
      stepper.step();
      const BodyStates& b = e->state();
      for (std::size_t i = 3; far && i < 3 + kFar; ++i)
        r.far_path.insert(r.far_path.end(), {b.position[i].x, b.position[i].y, b.angle[i], b.velocity[i].x,
                                             b.velocity[i].y, b.angular_velocity[i]});
      // ... and their contacts' impulses, which the next step starts from.
      for (const ContactRecord& c : e->contacts())
        if (std::max(c.body_a, c.body_b) >= 3)
          r.far_path.insert(r.far_path.end(), {c.normal_impulse, c.tangent_impulse, static_cast<double>(c.kind)});
    }
    r.islands = test::work_count(*e, "islands");
    r.redetections = test::work_count(*e, "redetections");
    return r;
  };
  const Run with = run(true, true, true), row_alone = run(true, true, false), far_alone = run(true, false, true),
            without = run(false, true, true);
  REQUIRE(with.redetections > 0);
  CHECK(row_alone.redetections == with.redetections);
  CHECK(far_alone.redetections == 0);
  // The far floes' islands are solved as often as without the row: in no redetection.
  REQUIRE(far_alone.islands >= kSteps);
  CHECK(with.islands == row_alone.islands + far_alone.islands);
  REQUIRE(with.far_path.size() == without.far_path.size());
  bool same = true;
  for (std::size_t i = 0; i < with.far_path.size(); ++i) same = same && same_bits(with.far_path[i], without.far_path[i]);
  CHECK(same);
}

TEST_CASE("redetect: a point the first pass held is classified as it was, not on the velocities after the loads",
          "[impacts]") {
  // As above, a floe struck across its 5 cm gap within one step onto a fixed wall; a third floe,
  // 6 m wide, rests on the middle of the struck one's top face, pushed down onto it by a load of
  // F dt / m = 0.006 m/s a step (above the 1e-3 m/s collision threshold). In the first step its
  // contact is new and it does not approach before the loads: resting. The redetection solves the struck floe's
  // island again from the velocities after the loads, where the pressed floe approaches at
  // 0.006 m/s: classified on those, it would be a collision, and with e = 1 it would leave the
  // struck floe's face at 0.006 m/s in the step the struck floe hit the wall.
  auto first_step = [](bool redetect) {
    const std::string text =
        test::header_toml(0.2, 0.02, 1.0, 0.0,
                          std::string("[engine.native]\nredetect = ") + (redetect ? "true" : "false") + "\n") +
        test::body_toml({"a", test::box({-10.05, 0}, 10, 10), {5.0, 0}}) +
        test::body_toml({"b", test::box({0, 0}, 10, 10)}) +
        test::body_toml({"wall", test::box({6.05, 0}, 2, 40), {}, 0.0, true}) +
        test::body_toml({"pressed", test::box({0, 10}, 6, 10), {}, 0.0, false, {0.0, -1.62e4}});
    const Scene scene = test::scene_from(text);
    Stepper stepper(scene, "native");  // with the load (forcing)
    stepper.step();
    const Engine& e = stepper.engine();
    struct First {
      double leaving = 0.0, redetections = 0.0;  // the pressed floe's normal speed off b's face
      std::vector<ContactRecord> pressed;        // its contacts with b
    } r;
    r.leaving = e.state().velocity[3].y - e.state().velocity[1].y;
    for (const ContactRecord& c : e.contacts())
      if (c.body_a == 1 && c.body_b == 3) r.pressed.push_back(c);
    r.redetections = test::work_count(e, "redetections");
    return r;
  };
  const auto with = first_step(true), without = first_step(false);
  REQUIRE(with.redetections == 1);
  REQUIRE(without.redetections == 0);
  REQUIRE(!with.pressed.empty());
  REQUIRE(with.pressed.size() == without.pressed.size());
  for (std::size_t k = 0; k < with.pressed.size(); ++k) {
    INFO("point " << k);
    CHECK(with.pressed[k].kind == ContactKind::resting);
    CHECK(without.pressed[k].kind == ContactKind::resting);
    // The approach it was classified on: before the loads, the same in both runs.
    CHECK(same_bits(with.pressed[k].approach_velocity, without.pressed[k].approach_velocity));
    CHECK(with.pressed[k].normal_impulse > 0.0);
  }
  // Resting: it stays on the face (to the solve's tolerance), where a bounce would be 0.006 m/s.
  CHECK(std::abs(with.leaving) < 1e-5);
  CHECK(std::abs(without.leaving) < 1e-5);
}

TEST_CASE("a floe sliding corner-first onto another's face is met, not overlapped", "[impacts]") {
  // b's lower-left corner starts 2 cm right of and 5 mm above a's upper-right corner, moving
  // at (-0.5, -0.5) m/s: within the first 0.1 s step it would reach 3 cm into a's right face.
  // At the step's start no point of b's nearest edge lies beside that face (clipping keeps
  // nothing); the contact is the closest pair of points, corner to corner, and the overlap
  // stays within the allowed 1 mm. (drift_in_field had 13.8 mm from such an approach.)
  const std::string text = test::header_toml(1.0, 0.1, 0.0, 0.0) +
                           test::body_toml({"a", test::box({0, 0}, 10, 10)}) +
                           test::body_toml({"b", test::box({10.02, 10.005}, 10, 10), {-0.5, -0.5}});
  const Scene s = test::scene_from(text);
  auto e = test::native(s);
  double deepest = 0.0;
  for (int k = 0; k < 10; ++k) {
    e->step(nullptr);
    const BodyStates& b = e->state();
    std::vector<Vec2> pa = test::box(b.position[0], 10, 10, b.angle[0]), pb = test::box(b.position[1], 10, 10, b.angle[1]);
    std::vector<Vec2> na, nb;
    for (std::size_t i = 0; i < 4; ++i) {
      na.push_back(normalized(perp(pa[(i + 1) % 4] - pa[i])) * -1.0);
      nb.push_back(normalized(perp(pb[(i + 1) % 4] - pb[i])) * -1.0);
    }
    const ConvexView va{pa.data(), na.data(), 4}, vb{pb.data(), nb.data(), 4};
    const double separation = std::max(max_face_separation(va, vb).separation, max_face_separation(vb, va).separation);
    deepest = std::max(deepest, -separation);
  }
  CHECK(deepest <= 1e-3 + 1e-9);
}
