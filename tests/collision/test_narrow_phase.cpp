#include <catch2/catch.hpp>

#include <bit>
#include <limits>
#include <random>

#include "floedem/engine/state_io.hpp"
#include "geometry/lane_isa.hpp"
#include "run/stepper.hpp"
#include "collision/narrow_phase.hpp"
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
  ConvexView view() const { return {world.data(), world_n.data(), static_cast<int>(world.size())}; }
};

/// Two random boxes (sides 0.2 to 10.2 m, aspect up to 1:50, any turn), the second's centre at
/// `reach` times the sum of their half-diagonals from the first's, in any direction.
std::pair<Poly, Poly> random_box_pair(std::mt19937_64& rng, double reach_low, double reach_high) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double wa = 0.2 + 10.0 * u(rng), ha = wa / (1.0 + 49.0 * u(rng));
  const double wb = 0.2 + 10.0 * u(rng), hb = wb / (1.0 + 49.0 * u(rng));
  const Poly a(test::box({0, 0}, wa, ha), {0, 0}, 2.0 * M_PI * u(rng));
  const double d = 0.5 * (std::hypot(wa, ha) + std::hypot(wb, hb)) * (reach_low + (reach_high - reach_low) * u(rng));
  const double phi = 2.0 * M_PI * u(rng);
  const Poly b(test::box({0, 0}, wb, hb), {d * std::cos(phi), d * std::sin(phi)}, 2.0 * M_PI * u(rng));
  return {a, b};
}

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

TEST_CASE("corner beside corner, apart: one point on the closest pair, along the line joining them", "[narrow]") {
  // b's left edge lies wholly above the end of a's right face (x = 5, y <= 5): clipping to the
  // face's side planes leaves nothing. The closest points are a's corner (5, 5) and b's corner
  // (5.02, 5.005); the contact is there, its normal along the line joining them.
  const Poly a(square(10), {0, 0}, 0.0);
  const Poly b(square(10), {10.02, 10.005}, 0.0);
  Manifold m;
  collide(a.geometry(), b.geometry(), 0.01, 1e-4, m);
  CHECK(m.point_count == 0);  // beyond the margin
  collide(a.geometry(), b.geometry(), 0.1, 1e-4, m);
  REQUIRE(m.point_count == 1);
  const double d = std::hypot(0.02, 0.005);
  CHECK(m.points[0].separation == Approx(d).epsilon(1e-12));
  CHECK(m.normal.x == Approx(0.02 / d).epsilon(1e-12));
  CHECK(m.normal.y == Approx(0.005 / d).epsilon(1e-12));
  CHECK(m.points[0].point.x == Approx(5.01).epsilon(1e-12));
  CHECK(m.points[0].point.y == Approx(5.0025).epsilon(1e-12));
  // The position solve's plane and point, carried by the bodies, give the same gap.
  const Vec2 face = (m.reference_is_b ? b.x : a.x).apply(m.local_face_point);
  const Vec2 q = (m.reference_is_b ? a.x : b.x).apply(m.points[0].local_incident);
  const Vec2 n_ref = (m.reference_is_b ? b.x : a.x).q.apply(m.local_normal);
  CHECK(dot(q - face, n_ref) == Approx(d).epsilon(1e-12));
  // The same pair with the roles swapped: the normal still points from a to b.
  Manifold swapped;
  collide(b.geometry(), a.geometry(), 0.1, 1e-4, swapped);
  REQUIRE(swapped.point_count == 1);
  CHECK(swapped.normal.x == Approx(-0.02 / d).epsilon(1e-12));
  CHECK(swapped.points[0].separation == Approx(d).epsilon(1e-12));
}

TEST_CASE("corner contacts: only for polygons apart, on a plane pair that separates them", "[narrow]") {
  // Random boxes (aspect up to 1:50, any angle) placed about each other's corners: wherever the
  // narrow phase makes a corner contact, the separating axes must say the polygons are apart,
  // its gap must be at least theirs (it is the true distance, they a lower bound), and the
  // planes through its two points, normal to it, must have each polygon on its own side.
  std::mt19937_64 rng(5);
  int corner_contacts = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const auto [a, b] = random_box_pair(rng, 0.9, 1.1);
    Manifold m;
    collide(a.geometry(), b.geometry(), 1.0, 1e-4, m);
    if (m.point_count != 1 || !(m.points[0].id & 0x40000000u)) continue;
    ++corner_contacts;
    const ConvexView va = a.view(), vb = b.view();
    const double sat = std::max(max_face_separation(va, vb).separation, max_face_separation(vb, va).separation);
    REQUIRE(sat > 0.0);
    const ManifoldPoint& p = m.points[0];
    CHECK(p.separation >= sat - 1e-12);
    CHECK(length(m.normal) == Approx(1.0).epsilon(1e-12));
    // m.normal points from a to b; the contact point is midway between the closest points.
    const Vec2 on_a = p.point - 0.5 * p.separation * m.normal, on_b = p.point + 0.5 * p.separation * m.normal;
    for (const Vec2 v : a.world) CHECK(dot(v - on_a, m.normal) <= 1e-9);
    for (const Vec2 v : b.world) CHECK(dot(v - on_b, m.normal) >= -1e-9);
  }
  CHECK(corner_contacts > 100);  // the property was put to the test
}

TEST_CASE("narrow phase: the separating axes' shortcuts give the full search's edge and separation", "[narrow]") {
  // max_face_separation leaves an edge at its first vertex no further than the best edge, and
  // stops at an edge separating by more than `enough`: exact shortcuts, so the same edge and
  // separation, to the bit, as the plain double loop, and the same verdict against `enough`.
  auto brute = [](const ConvexView& a, const ConvexView& b) {
    FaceSeparation best;
    for (int i = 0; i < a.count; ++i) {
      double s = std::numeric_limits<double>::infinity();
      for (int j = 0; j < b.count; ++j) s = std::min(s, dot(a.normals[i], b.vertices[j] - a.vertices[i]));
      if (s > best.separation) best = {i, s};
    }
    return best;
  };
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int apart = 0, overlapping = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const auto [a, b] = random_box_pair(rng, 0.3, 1.3);
    const ConvexView va = a.view(), vb = b.view();
    const FaceSeparation full = brute(va, vb), fast = max_face_separation(va, vb);
    REQUIRE(fast.edge == full.edge);
    REQUIRE(fast.separation == full.separation);
    // The lanes' search (no shortcut, four edges to a vector, eight to a pass): the same, to the bit.
    const FaceSeparation lanes = max_face_separation_lanes(va, vb);
    REQUIRE(lanes.edge == full.edge);
    REQUIRE(std::bit_cast<std::uint64_t>(lanes.separation) == std::bit_cast<std::uint64_t>(full.separation));
    const double enough = 0.5 * u(rng);
    const FaceSeparation cut = max_face_separation(va, vb, enough);
    REQUIRE((cut.separation > enough) == (full.separation > enough));
    if (full.separation <= enough) REQUIRE((cut.edge == full.edge && cut.separation == full.separation));
    (full.separation > 0.0 ? apart : overlapping) += 1;
  }
  CHECK(apart > 1000);
  CHECK(overlapping > 1000);
}

TEST_CASE("narrow phase: a pair's separation hint gives the manifold found without it to the bit", "[narrow]") {
  // The engine starts each pair's separating-axis search at the edges that separated most at
  // its last step (SeparationHint). Whatever the hint (none, right, wrong, one that ties the
  // winner), max_face_separation must give the plain search's edge and separation to the bit,
  // and collide() the same manifold. Pairs: random convex polygons (3 to 9 corners) near each
  // other, and unturned squares on a diagonal, whose edges tie exactly. Every build of collide
  // (geometry/lane_isa.hpp) gives the same manifold.
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto polygon = [&](double size) {
    const int corners = 3 + static_cast<int>(7.0 * u(rng));
    std::vector<Vec2> p;
    for (int k = 0; k < corners; ++k) {
      const double a = 2.0 * M_PI * (k + 0.35 * u(rng)) / corners;
      p.push_back({size * std::cos(a), size * std::sin(a)});
    }
    return p;
  };
  auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
  auto same_vec = [&](Vec2 a, Vec2 b) { return bits(a.x) == bits(b.x) && bits(a.y) == bits(b.y); };
  auto same_manifold = [&](const Manifold& a, const Manifold& b) {
    if (a.point_count != b.point_count) return false;
    if (a.point_count == 0) return true;
    bool same = same_vec(a.normal, b.normal) && a.reference_is_b == b.reference_is_b &&
                same_vec(a.local_normal, b.local_normal) && same_vec(a.local_face_point, b.local_face_point);
    for (int k = 0; k < a.point_count; ++k)
      same = same && same_vec(a.points[k].point, b.points[k].point) && a.points[k].id == b.points[k].id &&
             bits(a.points[k].separation) == bits(b.points[k].separation) &&
             same_vec(a.points[k].local_incident, b.points[k].local_incident);
    return same;
  };
  int ties = 0, contacts = 0, hinted = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const bool diagonal = trial % 5 == 0;
    const double size_a = 1.0 + 9.0 * u(rng), size_b = 1.0 + 9.0 * u(rng);
    const double d = (size_a + size_b) * (0.3 + 0.9 * u(rng));
    const double phi = 2.0 * M_PI * u(rng);
    const Poly a = diagonal ? Poly(square(2.0), {0, 0}, 0.0) : Poly(polygon(size_a), {0, 0}, 2.0 * M_PI * u(rng));
    const Poly b = diagonal ? Poly(square(2.0), {1.0 + 0.5 * (trial % 3), 1.0 + 0.5 * (trial % 3)}, 0.0)
                            : Poly(polygon(size_b), {d * std::cos(phi), d * std::sin(phi)}, 2.0 * M_PI * u(rng));
    const ConvexView va = a.view(), vb = b.view();
    const double margin = 0.5 * u(rng);
    for (const auto& [p, q] : {std::pair{va, vb}, std::pair{vb, va}}) {
      const FaceSeparation plain = max_face_separation(p, q);
      const FaceSeparation cut = max_face_separation(p, q, margin);
      // 3 to 9 corners: one pass of one or two vectors, and a second pass at 9; every count of
      // edges in a vector (the lanes past the last repeat edge 0), ties included.
      const FaceSeparation lanes = max_face_separation_lanes(p, q);
      REQUIRE(lanes.edge == plain.edge);
      REQUIRE(bits(lanes.separation) == bits(plain.separation));
      for (int i = 0; i < p.count; ++i) {
        const double floor = edge_separation(p, q, i);
        if (floor == plain.separation && i != plain.edge) ++ties;
        const FaceSeparation h = max_face_separation(p, q, std::numeric_limits<double>::infinity(), i, floor);
        REQUIRE(h.edge == plain.edge);
        REQUIRE(bits(h.separation) == bits(plain.separation));
        const FaceSeparation hc = max_face_separation(p, q, margin, i, floor);
        REQUIRE((hc.separation > margin) == (cut.separation > margin));
        if (cut.separation <= margin) REQUIRE((hc.edge == cut.edge && bits(hc.separation) == bits(cut.separation)));
      }
    }
    Manifold plain;
    collide(a.geometry(), b.geometry(), margin, 1e-4, plain);
    contacts += plain.point_count > 0;
    for (const LaneIsa isa : available_lane_isas()) {  // every build of collide, the same to the bit
      INFO("build " << static_cast<int>(isa));
      use_lane_isa(isa);
      Manifold built;
      collide(a.geometry(), b.geometry(), margin, 1e-4, built);
      REQUIRE(same_manifold(built, plain));
    }
    use_fastest_lane_isa();
    for (int ha = -1; ha < va.count; ++ha)
      for (int hb = -1; hb < vb.count; ++hb) {
        SeparationHint hint{static_cast<std::int16_t>(ha), static_cast<std::int16_t>(hb)};
        Manifold m;
        collide(a.geometry(), b.geometry(), margin, 1e-4, m, &hint);
        REQUIRE(same_manifold(m, plain));
        ++hinted;
      }
  }
  CHECK(ties > 100);      // hints that tie the winner were tried
  CHECK(contacts > 500);  // and pairs in contact, not only pairs apart
  CHECK(hinted > 50000);
}

TEST_CASE("narrow phase: pairs of floes at rest reuse their manifolds to the bit of a fresh computation", "[narrow]") {
  // Still water: a block of floes at rest, side by side (touching: paired every step), and one
  // floe driven into its corner. Most pairs' bodies sit still, so their
  // manifolds are carried over from the last step instead of computed. Run B is restored from
  // run A's state at step 150 (a restored engine computes its first narrow phase afresh); both
  // must end the same to the bit, and the reuse must have been in play.
  std::string text = test::header_toml(1.0, 0.05, 0.1, 0.3);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      text += test::body_toml({"f" + std::to_string(i) + "_" + std::to_string(j),
                               test::box({10.0 * i, 10.0 * j}, 10.0, 10.0, 0.0), {}, 0.0});
  text += test::body_toml({"striker", test::box({-12.0, -12.0}, 8.0, 8.0, 0.4), {0.8, 0.7}, 0.02});
  const Scene s = test::scene_from(text);
  Stepper a(s, "native");
  for (int k = 0; k < 150; ++k) a.step();
  StateWriter saved;
  REQUIRE(a.save(saved));
  Stepper b(s, "native");
  StateReader in(saved.bytes().data(), saved.bytes().size());
  b.restore(in);
  for (int k = 0; k < 250; ++k) {
    a.step();
    b.step();
  }
  REQUIRE(a.contacts().size() > 0);
  const double reused = test::work_count(a.engine(), "narrow_reused") / test::work_count(a.engine(), "narrow_pairs");
  INFO("fraction of pairs reused: " << reused);
  CHECK(reused > 0.2);  // measured 0.32: the strike sets much of the block moving
  const BodyStates& x = a.state();
  const BodyStates& y = b.state();
  for (std::size_t i = 0; i < x.position.size(); ++i) {
    INFO("body " << i);
    CHECK(x.position[i].x == y.position[i].x);
    CHECK(x.position[i].y == y.position[i].y);
    CHECK(x.angle[i] == y.angle[i]);
    CHECK(x.velocity[i].x == y.velocity[i].x);
    CHECK(x.angular_velocity[i] == y.angular_velocity[i]);
  }
}

namespace {

// A manifold with every field set from `base` (each point's fields offset by 100 more) and the
// flags to `flag`: two of them with other bases differ in every field.
Manifold filled_manifold(double base, bool flag) {
  const auto id = static_cast<std::int32_t>(base);
  Manifold m;
  m.part_a = id + 1;
  m.part_b = id + 2;
  m.body_a = id + 3;
  m.body_b = id + 4;
  m.normal = {base, base + 1};
  for (ManifoldPoint& p : m.points) {
    p.point = {base + 2, base + 3};
    p.separation = base + 4;
    p.id = static_cast<std::uint32_t>(base) + 5;
    p.local_incident = {base + 6, base + 7};
    p.normal_impulse = base + 8;
    p.tangent_impulse = base + 9;
    p.approach_velocity = base + 10;
    p.target_velocity = base + 11;
    p.kind = flag ? ContactKind::collision : ContactKind::resting;
    p.persistent = flag;
    p.ra = {base + 12, base + 13};
    p.rb = {base + 14, base + 15};
    p.wnn = base + 16;
    p.wnt = base + 17;
    p.wtt = base + 18;
    base += 100;
  }
  m.reference_is_b = flag;
  m.local_normal = {base + 19, base + 20};
  m.local_face_point = {base + 21, base + 22};
  m.friction = base + 23;
  m.restitution = base + 24;
  return m;
}

bool same_vec(Vec2 a, Vec2 b) { return same_bits(a.x, b.x) && same_bits(a.y, b.y); }

bool same_point(const ManifoldPoint& a, const ManifoldPoint& b) {
  return same_vec(a.point, b.point) && same_bits(a.separation, b.separation) && a.id == b.id &&
         same_vec(a.local_incident, b.local_incident) && same_bits(a.normal_impulse, b.normal_impulse) &&
         same_bits(a.tangent_impulse, b.tangent_impulse) && same_bits(a.approach_velocity, b.approach_velocity) &&
         same_bits(a.target_velocity, b.target_velocity) && a.kind == b.kind && a.persistent == b.persistent &&
         same_vec(a.ra, b.ra) && same_vec(a.rb, b.rb) && same_bits(a.wnn, b.wnn) && same_bits(a.wnt, b.wnt) &&
         same_bits(a.wtt, b.wtt);
}

// `to` holds every field of `from` and its points up to from.point_count; a second point past
// the count is `untouched`.
void check_copied(const Manifold& to, const Manifold& from, const ManifoldPoint& untouched) {
  CHECK(to.part_a == from.part_a);
  CHECK(to.part_b == from.part_b);
  CHECK(to.body_a == from.body_a);
  CHECK(to.body_b == from.body_b);
  CHECK(same_vec(to.normal, from.normal));
  CHECK(to.point_count == from.point_count);
  CHECK(same_point(to.points[0], from.points[0]));
  CHECK(same_point(to.points[1], from.point_count == 2 ? from.points[1] : untouched));
  CHECK(to.reference_is_b == from.reference_is_b);
  CHECK(same_vec(to.local_normal, from.local_normal));
  CHECK(same_vec(to.local_face_point, from.local_face_point));
  CHECK(same_bits(to.friction, from.friction));
  CHECK(same_bits(to.restitution, from.restitution));
}

}  // namespace

TEST_CASE("copy_manifold copies every field a contact holds and leaves an unused point as it was") {
  // The contact list is built with copy_manifold (byte ranges, not the whole struct): a field
  // it missed would reach the solver stale. Every field of the source and of the target set to
  // values that differ between the two (flags included), so a field not copied fails its check.
  for (const int count : {1, 2}) {
    Manifold from = filled_manifold(1000.0, true);
    from.point_count = count;
    Manifold to = filled_manifold(5000.0, false);
    const ManifoldPoint untouched = to.points[1];
    copy_manifold(from, to);
    check_copied(to, from, untouched);
  }
}

TEST_CASE("fill_manifold makes the contact list's manifold from the narrow phase's, every field, solver fields fresh") {
  // The narrow phase keeps NarrowManifold (the fields it finds); the contact list fills a
  // Manifold from it: each field copied, each point's solver fields as a fresh ManifoldPoint has
  // them, a point past the count left as it was. A field missed would reach the solver stale.
  const Manifold source = filled_manifold(1000.0, true);
  NarrowManifold from;
  from.part_a = source.part_a;
  from.part_b = source.part_b;
  from.body_a = source.body_a;
  from.body_b = source.body_b;
  from.normal = source.normal;
  for (int k = 0; k < 2; ++k) {
    from.points[k].point = source.points[k].point;
    from.points[k].separation = source.points[k].separation;
    from.points[k].id = source.points[k].id;
    from.points[k].local_incident = source.points[k].local_incident;
  }
  from.reference_is_b = source.reference_is_b;
  from.local_normal = source.local_normal;
  from.local_face_point = source.local_face_point;
  from.friction = source.friction;
  from.restitution = source.restitution;
  for (const int count : {1, 2}) {
    from.point_count = count;
    Manifold expected = source;  // what collide() writes into a Manifold
    expected.point_count = count;
    for (ManifoldPoint& p : expected.points) {
      const ManifoldPoint found = p;
      p = ManifoldPoint{};
      p.point = found.point;
      p.separation = found.separation;
      p.id = found.id;
      p.local_incident = found.local_incident;
    }
    Manifold to = filled_manifold(5000.0, false);
    const ManifoldPoint untouched = to.points[1];
    fill_manifold(from, to);
    check_copied(to, expected, untouched);
    CHECK(to.points[0].normal_impulse == 0.0);
    CHECK(!to.points[0].persistent);
    CHECK(to.points[0].kind == ContactKind::resting);
  }
}
