// The drag terms' shortcuts must not change a result: the packed quadrature the terms evaluate
// gives the point-by-point rule's sums to the bit, the rate bound that lets a body skip its
// Jacobian is a true upper bound of what stiff() reads (forcing.cpp), and Q without the
// Jacobian (two quadrature points at a time for quadratic drag) is Q with it, to the bit.
#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <random>

#include "forcing/drag.hpp"
#include "geometry/lane_isa.hpp"
#include "geometry/polygon.hpp"
#include "support.hpp"

using namespace floedem;

namespace {

ForceSums sums_for(std::size_t n) {
  ForceSums s;
  s.q.assign(n, {});
  s.dq.assign(n, {});
  s.rotation_rate.assign(n, 0.0);
  s.rotation.assign(n, Rot{});
  s.jacobian.assign(n, 1);
  s.rate_bound.assign(n, {});
  for (std::size_t i = 0; i < n; ++i) s.stirred.push_back(static_cast<std::int32_t>(i));  // every body may move
  return s;
}

}  // namespace

TEST_CASE("drag: the packed quadrature is the rule to the bit and the rate bound covers the Jacobian",
          "[forcing]") {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int cases = 0;
  for (const bool rotational : {true, false})
    for (const double reference_speed : {0.0, 0.4})
      for (const auto kind : {DistributedDrag::Kind::form, DistributedDrag::Kind::skin})
        for (int trial = 0; trial < 200; ++trial) {
          EnvironmentSpec env;
          env.rotational_damping = rotational;
          env.drag_reference_speed = reference_speed;
          DistributedDrag drag("test", kind, env, DistributedDrag::Medium::water);
          // A random convex polygon about the origin (4 to 9 corners, 2 to 60 m).
          const int corners = 4 + trial % 6;
          const double size = 2.0 + 29.0 * (1.0 + u(rng));
          std::vector<Vec2> poly;
          for (int k = 0; k < corners; ++k) {
            const double a = 2.0 * M_PI * (k + 0.4 * u(rng)) / corners;
            const double r = size * (0.7 + 0.3 * u(rng));
            poly.push_back({r * std::cos(a), r * std::sin(a)});
          }
          const Vec2 c = area_moments(poly).centroid;
          for (Vec2& p : poly) p = p - c;
          if (trial % 7 == 3) poly.insert(poly.begin() + 2, poly[2]);  // a zero-length edge
          const std::vector<DragSlab> slabs{{500.0 * (1.0 + u(rng)), 0.5 + u(rng) * 0.4, {u(rng), u(rng)}},
                                            {3.0 * (1.0 + u(rng)), 1.0, {10.0 * u(rng), 10.0 * u(rng)}}};
          drag.add_body(0, poly, slabs);
          BodyStates s;
          s.resize(1);
          s.velocity[0] = {2.0 * u(rng), 2.0 * u(rng)};
          s.angular_velocity[0] = 0.05 * u(rng);
          s.angle[0] = M_PI * u(rng);

          ForceSums full = sums_for(1);
          full.rotation[0] = Rot::from_angle(s.angle[0]);
          drag.add(s, 0.0, full);
          // The term's packed quadrature gives the point-by-point rule's sums to the bit.
          BodySum rule{};
          for (const DragSlab& slab : slabs) {
            const DragSettings settings{rotational, reference_speed};
            if (kind == DistributedDrag::Kind::form)
              add_form_drag(rule, edge_points(poly), slab.scale, slab.c, slab.flow, s.velocity[0],
                            s.angular_velocity[0], full.rotation[0], settings, true);
            else
              add_skin_drag(rule, area_points(poly), slab.scale, slab.c, slab.flow, s.velocity[0],
                            s.angular_velocity[0], full.rotation[0], settings, true);
          }
          CHECK(full.q[0] == rule.q);
          CHECK(full.dq[0] == rule.d);
          REQUIRE(drag.add_rate_bound(s, full));
          const auto& d = full.dq[0];
          const double rows = std::max(std::abs(d[0]) + std::abs(d[1]), std::abs(d[3]) + std::abs(d[4]));
          // Up to rounding: the linearised bounds are equalities (|k| U_ref summed either way);
          // forcing.cpp's test carries a margin of 1e-6, far above this.
          CHECK(rows <= full.rate_bound[0][0] * (1.0 + 1e-12));
          CHECK(std::abs(d[8]) <= full.rate_bound[0][1] * (1.0 + 1e-12));

          ForceSums lean = sums_for(1);
          lean.rotation[0] = full.rotation[0];
          lean.jacobian[0] = 0;
          drag.add(s, 0.0, lean);  // quadratic drag: the two-lane quadrature (drag.cpp)
          for (int k = 0; k < 3; ++k)  // to the bit: == would take -0 for +0
            CHECK(std::bit_cast<std::uint64_t>(lean.q[0][k]) == std::bit_cast<std::uint64_t>(full.q[0][k]));
          ++cases;
        }
  CHECK(cases == 1600);
}

TEST_CASE("drag: in still water only the moving bodies are visited, with the sums of the full quadrature",
          "[forcing]") {
  // Five floes in still water and air: at rest, moving, spinning in place, at rest, moving.
  // Forcing lists the moving ones (ForceSums::stirred); each term then visits those alone, and
  // must give them the quadrature's force to the bit and the ones at rest exactly nothing.
  const std::vector<Vec2> poly{{-5.0, -3.0}, {6.0, -4.0}, {4.0, 5.0}, {-6.0, 2.0}};
  const std::vector<Vec2> velocity{{0.0, 0.0}, {0.3, -0.1}, {0.0, 0.0}, {0.0, -0.0}, {-0.2, 0.05}};
  const std::vector<double> spin{0.0, 0.01, -0.02, 0.0, 0.0};
  for (const auto kind : {DistributedDrag::Kind::form, DistributedDrag::Kind::skin}) {
    EnvironmentSpec env;
    DistributedDrag drag("still", kind, env, DistributedDrag::Medium::water);
    BodyStates s;
    s.resize(5);
    ForceSums sums = sums_for(5);
    sums.stirred.clear();
    for (std::size_t i = 0; i < 5; ++i) {
      drag.add_body(i, poly, {{400.0, 1.0, {0.0, 0.0}}});
      s.velocity[i] = velocity[i];
      s.angular_velocity[i] = spin[i];
      s.angle[i] = 0.3 * static_cast<double>(i);
      sums.rotation[i] = Rot::from_angle(s.angle[i]);
      if (velocity[i].x != 0.0 || velocity[i].y != 0.0 || spin[i] != 0.0) sums.stirred.push_back(static_cast<std::int32_t>(i));
    }
    REQUIRE(sums.stirred == std::vector<std::int32_t>{1, 2, 4});
    drag.add(s, 0.0, sums);
    const std::vector<EdgePoint> edges = edge_points(poly);
    const std::vector<AreaPoint> points = area_points(poly);
    const DragSettings settings{env.rotational_damping, env.drag_reference_speed};
    for (std::size_t i = 0; i < 5; ++i) {
      INFO("floe " << i);
      BodySum expected{};
      if (kind == DistributedDrag::Kind::form)
        add_form_drag(expected, edges, 1.0, 400.0, {}, velocity[i], spin[i], sums.rotation[i], settings, true);
      else
        add_skin_drag(expected, points, 1.0, 400.0, {}, velocity[i], spin[i], sums.rotation[i], settings, true);
      CHECK(sums.q[i] == expected.q);
      CHECK(sums.dq[i] == expected.d);
      if (i == 0 || i == 3) CHECK(sums.q[i] == std::array<double, 3>{});
    }
  }
}

TEST_CASE("drag: in still water a few floes moving among many take their lane groups alone, to the bit",
          "[forcing]") {
  // Forty floes of one outline (so ten lane groups of four, in entry order), a few of them
  // moving: under a quarter moving, the term visits the moving floes alone and adds the groups
  // they fall in, no other (DistributedDrag::add). Each moving floe must get the point-by-point
  // rule's force to the bit, each floe at rest exactly nothing; three steps with other floes
  // moving, so that a group left out after being added (or added twice) shows.
  const std::vector<Vec2> poly{{-5.0, -3.0}, {6.0, -4.0}, {4.0, 5.0}, {-6.0, 2.0}};
  constexpr std::size_t n = 40;
  for (const auto kind : {DistributedDrag::Kind::form, DistributedDrag::Kind::skin}) {
    EnvironmentSpec env;
    DistributedDrag drag("still", kind, env, DistributedDrag::Medium::water);
    BodyStates s;
    s.resize(n);
    for (std::size_t i = 0; i < n; ++i) drag.add_body(i, poly, {{400.0, 1.0, {0.0, 0.0}}});
    const std::vector<EdgePoint> edges = edge_points(poly);
    const std::vector<AreaPoint> points = area_points(poly);
    const DragSettings settings{env.rotational_damping, env.drag_reference_speed};
    for (const std::vector<std::int32_t>& moving :
         {std::vector<std::int32_t>{2, 3, 17, 39}, std::vector<std::int32_t>{17}, std::vector<std::int32_t>{0, 1, 2, 3, 38}}) {
      ForceSums sums = sums_for(n);
      sums.jacobian.assign(n, 0);  // force alone: the lanes' path
      sums.stirred = moving;
      for (std::size_t i = 0; i < n; ++i) {
        s.velocity[i] = {};
        s.angular_velocity[i] = 0.0;
        s.angle[i] = 0.1 * static_cast<double>(i);
        sums.rotation[i] = Rot::from_angle(s.angle[i]);
      }
      for (const std::int32_t m : moving) {
        s.velocity[m] = {0.3 - 0.01 * m, -0.1};
        s.angular_velocity[m] = 0.01 * (m % 3);
      }
      drag.add(s, 0.0, sums);
      for (std::size_t i = 0; i < n; ++i) {
        INFO("floe " << i << " of " << moving.size() << " moving");
        BodySum expected{};
        if (std::find(moving.begin(), moving.end(), static_cast<std::int32_t>(i)) != moving.end()) {
          if (kind == DistributedDrag::Kind::form)
            add_form_drag(expected, edges, 1.0, 400.0, {}, s.velocity[i], s.angular_velocity[i], sums.rotation[i], settings, false);
          else
            add_skin_drag(expected, points, 1.0, 400.0, {}, s.velocity[i], s.angular_velocity[i], sums.rotation[i], settings, false);
          REQUIRE(expected.q != std::array<double, 3>{});
        }
        CHECK(sums.q[i] == expected.q);
      }
    }
  }
}

TEST_CASE("forcing: in still water with Coriolis the moving bodies alone give every body's loads to the bit",
          "[forcing]") {
  // After its first step a Forcing whose terms are all idle at rest (still-water drag,
  // Coriolis) zeroes what its last step wrote and works on the moving bodies alone. Its loads
  // must be those of a fresh Forcing, which works on every body, given the same memory of the
  // last step (the free bodies' accelerations: forcing.cpp), step after step, while floes
  // start, stop (to +0 and to -0), spin in place and move again, and a towed body ramps.
  std::string t = "[run]\nduration = 10.0\ndt = 0.5\n[environment]\nlatitude = 75.0\n";
  for (int i = 0; i < 6; ++i) t += test::body_toml({"f" + std::to_string(i), test::box({40.0 * i, 0.0}, 10.0, 7.0), {}, 0.0});
  t += "[[body]]\nname = \"berg\"\nkind = \"iceberg\"\npolygon = [[300, -20], [340, -20], [340, 20], [300, 20]]\n"
       "draft = 30.0\nsail_height = 5.0\n[tow]\nmode = \"velocity\"\nbody = \"berg\"\npath = [[0.0, 0.0, 0.0], [4.0, 0.5, 0.1]]\n";
  const Scene s = test::scene_from(t);
  Forcing kept(s);
  REQUIRE(kept.works_on_moving_bodies_only());
  BodyStates st;
  st.resize(s.bodies.size());
  for (std::size_t i = 0; i < s.bodies.size(); ++i) st.position[i] = s.bodies[i].centroid;
  // Per step: each floe's velocity and spin.
  const std::vector<std::vector<std::array<double, 3>>> steps{
      {{0, 0, 0}, {0.3, 0, 0}, {0, 0, 0.01}, {0, 0, 0}, {-0.1, 0.2, 0}, {0, 0, 0}},
      {{0, 0, 0}, {0.2, 0.1, 0.002}, {0, 0, 0}, {0.1, 0, 0}, {-0.1, 0.2, 0}, {0, 0, 0}},
      {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {-0.0, -0.0, 0}, {0, 0, -0.003}, {0.4, -0.1, 0}},
      {{0, 0, 0}, {0.05, 0, 0}, {0, 0, 0.02}, {0, 0, 0}, {0, 0, 0}, {0.4, -0.1, 0}},
      {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}},
      {{0, 0, 0}, {0.1, 0.1, 0.1}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
  for (std::size_t k = 0; k < steps.size(); ++k) {
    INFO("step " << k);
    for (std::size_t i = 0; i < 6; ++i) {
      st.velocity[i] = {steps[k][i][0], steps[k][i][1]};
      st.angular_velocity[i] = steps[k][i][2];
      st.angle[i] += 0.01 * static_cast<double>(k * i);
    }
    const double time = 0.5 * static_cast<double>(k);
    Forcing fresh(s);
    StateWriter memory;
    kept.save(memory);
    StateReader read(memory.bytes().data(), memory.size());
    fresh.restore(read);
    const Loads* a = kept.evaluate(st, time);
    const Loads* b = fresh.evaluate(st, time);
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      INFO("body " << i);
      CHECK(std::bit_cast<std::uint64_t>(a->force[i].x) == std::bit_cast<std::uint64_t>(b->force[i].x));
      CHECK(std::bit_cast<std::uint64_t>(a->force[i].y) == std::bit_cast<std::uint64_t>(b->force[i].y));
      CHECK(std::bit_cast<std::uint64_t>(a->torque[i]) == std::bit_cast<std::uint64_t>(b->torque[i]));
      if (s.bodies[i].prescribed) CHECK(kept.environment_force(i) == fresh.environment_force(i));
    }
    const bool any_moves = k != 4;
    if (any_moves) {
      bool loaded = false;
      for (std::size_t i = 0; i < 6; ++i) loaded = loaded || a->force[i].x != 0.0 || a->torque[i] != 0.0;
      CHECK(loaded);  // the case is not empty: drag acts on the moving floes
    }
    // Working on the moving bodies alone, it names them (Loads::listed): every body it does not
    // name has no force and no torque, so an engine may look at the named ones alone.
    CHECK(a->listed == (k > 0));
    if (a->listed) {
      CHECK(std::is_sorted(a->loaded.begin(), a->loaded.end()));
      std::vector<std::uint8_t> named(s.bodies.size(), 0);
      for (const std::int32_t i : a->loaded) named[static_cast<std::size_t>(i)] = 1;
      for (std::size_t i = 0; i < s.bodies.size(); ++i)
        if (!named[i]) CHECK((a->force[i].x == 0.0 && a->force[i].y == 0.0 && a->torque[i] == 0.0));
      if (any_moves) CHECK(!a->loaded.empty());
    }
  }
}

TEST_CASE("forcing: the native engine's rotations give the loads of the angles to the bit", "[forcing]") {
  // The forcing copies the engine's Rot::from_angle(angle) per body (Engine::rotations) instead
  // of making its own: the same loads to the bit, step after step, as a forcing that makes them
  // from the angles, and again when it falls back to the angles midway (it must not keep the
  // rotations of a step it did not make them for). Six floes spun by their drag in a current
  // and a wind across it, colliding; rotational drag on.
  std::string t = "[run]\nduration = 20.0\ndt = 0.1\n[environment]\ncurrent = [0.4, 0.1]\nwind = [-3.0, 6.0]\n";
  for (int i = 0; i < 6; ++i)
    t += test::body_toml({"f" + std::to_string(i), test::box({14.0 * i, 3.0 * (i % 2)}, 10.0 + i, 6.0, 0.3 * i),
                          {0.2 * (i % 3), 0.0}, 0.02 * (i - 3)});
  const Scene s = test::scene_from(t);
  auto engine = test::native(s);
  REQUIRE(engine->rotations().size() == s.bodies.size());
  Forcing from_engine(s), from_angles(s);
  double turned = 0.0;
  for (int k = 0; k < 200; ++k) {
    INFO("step " << k);
    const double time = 0.1 * k;
    // Steps 80 to 89: the first forcing makes its own rotations too (and then takes the engine's again).
    const Loads* a = from_engine.evaluate(engine->state(), time, k / 10 == 8 ? std::span<const Rot>{} : engine->rotations());
    const Loads* b = from_angles.evaluate(engine->state(), time);
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      CHECK(std::bit_cast<std::uint64_t>(a->force[i].x) == std::bit_cast<std::uint64_t>(b->force[i].x));
      CHECK(std::bit_cast<std::uint64_t>(a->force[i].y) == std::bit_cast<std::uint64_t>(b->force[i].y));
      CHECK(std::bit_cast<std::uint64_t>(a->torque[i]) == std::bit_cast<std::uint64_t>(b->torque[i]));
    }
    engine->step(a);
  }
  for (std::size_t i = 0; i < s.bodies.size(); ++i) turned += std::abs(engine->state().angle[i]);
  CHECK(turned > 0.5);  // rad, summed: the floes turned, so the rotations were not all the identity
}

TEST_CASE("drag: floes four at a time give each floe the rule's sums to the bit, in every build",
          "[forcing]") {
  // 37 floes (nine groups of four and one lane more), 3 to 9 corners, some with a zero-length
  // edge, in one term: most take the four-floe lanes (one slab, no Jacobian, quadratic drag);
  // some need the Jacobian, some have two slabs, and in still water some are at rest and not
  // visited (most of them moving, which takes the groups directly as a moving flow does, or
  // most at rest, which visits the moving ones entry by entry: DistributedDrag::lanes_direct);
  // in a moving flow some move with it without spin (nothing to add). Each floe's
  // sums, started from another term's, must be the point-by-point rule's to the bit, over two
  // steps (the lanes' marks of the first must not leak into the second).
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr std::size_t n = 37;
  int lean_checked = 0;
  for (const LaneIsa isa : available_lane_isas()) {
    use_lane_isa(isa);
    for (const bool rotational : {true, false})
      for (const int mode : {0, 1, 2})  // a moving flow; still, most floes moving; still, most at rest
        for (const auto kind : {DistributedDrag::Kind::form, DistributedDrag::Kind::skin}) {
          const bool still = mode != 0;
          INFO("isa " << static_cast<int>(isa) << " rotational " << rotational << " mode " << mode << " form "
                      << (kind == DistributedDrag::Kind::form));
          EnvironmentSpec env;
          env.rotational_damping = rotational;
          DistributedDrag drag("lanes", kind, env, DistributedDrag::Medium::water);
          std::vector<std::vector<Vec2>> polys(n);
          std::vector<std::vector<DragSlab>> slabs(n);
          for (std::size_t i = 0; i < n; ++i) {
            const int corners = 3 + static_cast<int>((i * 5) % 7);
            const double size = 2.5 + 14.0 * (1.0 + u(rng));
            polys[i] = test::jittered_polygon(rng, corners, size);
            if (i % 9 == 4) polys[i].insert(polys[i].begin() + 1, polys[i][1]);  // a zero-length edge
            const Vec2 flow = still ? Vec2{} : Vec2{0.5 * u(rng), 0.5 * u(rng)};
            slabs[i].push_back({300.0 * (1.0 + u(rng)), 0.6 + 0.3 * u(rng), flow});
            if (i % 11 == 7) slabs[i].push_back({40.0, 1.0, still ? Vec2{} : Vec2{u(rng), u(rng)}});  // a keel
            drag.add_body(i, polys[i], slabs[i]);
          }
          for (int step = 0; step < 2; ++step) {
            INFO("step " << step);
            BodyStates s;
            s.resize(n);
            ForceSums sums = sums_for(n);
            sums.stirred.clear();
            for (std::size_t i = 0; i < n; ++i) {
              const bool rests = still && ((i + static_cast<std::size_t>(step)) % 6 == 2) == (mode == 1);
              const bool with_flow = !still && (i + static_cast<std::size_t>(step)) % 10 == 3;
              s.velocity[i] = rests ? Vec2{} : with_flow ? slabs[i].front().flow : Vec2{0.8 * u(rng), 0.8 * u(rng)};
              s.angular_velocity[i] = rests || with_flow ? 0.0 : 0.02 * u(rng);
              s.angle[i] = M_PI * u(rng);
              sums.rotation[i] = Rot::from_angle(s.angle[i]);
              sums.jacobian[i] = (i + static_cast<std::size_t>(step)) % 8 == 5 ? 1 : 0;
              sums.q[i] = {1e3 * u(rng), 1e3 * u(rng), 1e4 * u(rng)};  // another term's sums
              if (!rests) sums.stirred.push_back(static_cast<std::int32_t>(i));
            }
            if (mode == 1) REQUIRE(4 * sums.stirred.size() >= n);  // the groups directly
            if (mode == 2) REQUIRE(4 * sums.stirred.size() < n);   // the moving floes, entry by entry
            const ForceSums before = sums;
            if (mode == 2) {
              // The same state with every floe listed as stirred (a floe at rest listed costs a
              // look) takes the direct path: the same sums and rate bounds to the bit.
              ForceSums entry_by_entry = sums, direct = sums;
              direct.stirred.resize(n);
              std::iota(direct.stirred.begin(), direct.stirred.end(), 0);
              for (ForceSums* x : {&entry_by_entry, &direct}) {
                drag.add(s, 0.0, *x);
                std::fill(x->rate_bound.begin(), x->rate_bound.end(), std::array<double, 2>{});
                REQUIRE(drag.add_rate_bound(s, *x));
              }
              for (std::size_t i = 0; i < n; ++i)
                for (int k = 0; k < 3; ++k) {
                  CHECK(std::bit_cast<std::uint64_t>(direct.q[i][k]) == std::bit_cast<std::uint64_t>(entry_by_entry.q[i][k]));
                  if (k < 2)
                    CHECK(std::bit_cast<std::uint64_t>(direct.rate_bound[i][k]) ==
                          std::bit_cast<std::uint64_t>(entry_by_entry.rate_bound[i][k]));
                }
            }
            drag.add(s, 0.0, sums);
            for (std::size_t i = 0; i < n; ++i) {
              INFO("floe " << i);
              BodySum rule{before.q[i], before.dq[i]};
              const bool visited = !still || s.velocity[i].x != 0.0 || s.angular_velocity[i] != 0.0;
              if (visited)
                for (const DragSlab& slab : slabs[i]) {
                  const DragSettings settings{rotational, 0.0};
                  if (kind == DistributedDrag::Kind::form)
                    add_form_drag(rule, edge_points(polys[i]), slab.scale, slab.c, slab.flow, s.velocity[i],
                                  s.angular_velocity[i], sums.rotation[i], settings, true);
                  else
                    add_skin_drag(rule, area_points(polys[i]), slab.scale, slab.c, slab.flow, s.velocity[i],
                                  s.angular_velocity[i], sums.rotation[i], settings, true);
                }
              for (int k = 0; k < 3; ++k)  // to the bit: == would take -0 for +0
                CHECK(std::bit_cast<std::uint64_t>(sums.q[i][k]) == std::bit_cast<std::uint64_t>(rule.q[k]));
              if (sums.jacobian[i] != 0) CHECK(sums.dq[i] == rule.d);
              else CHECK(sums.dq[i] == before.dq[i]);  // Q alone: D left as it was
              if (visited && sums.jacobian[i] == 0 && slabs[i].size() == 1) ++lean_checked;
            }
          }
        }
  }
  use_fastest_lane_isa();
  CHECK(lean_checked >= 8 * 2 * 20);  // the lanes took most floes in every case
}
