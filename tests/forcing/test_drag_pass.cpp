// The drag terms' shared pass (forcing/drag_pass.hpp) must give every body the sums and rate
// bounds of the terms added one after the other, to the bit, and take the floes it can.
#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <memory>
#include <random>

#include "forcing/drag_pass.hpp"
#include "geometry/lane_isa.hpp"
#include "floedem/scenario/scenario.hpp"
#include "support.hpp"

using namespace floedem;

namespace {

bool same(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

}  // namespace

TEST_CASE("drag pass: four drag terms in one pass give each body the terms' sums and rate bounds to the bit",
          "[forcing]") {
  // 45 bodies in water form, water skin, air form and air skin drag (Forcing's order). Most
  // are floes the pass takes; it must leave to the terms a body with a zero-length edge, one
  // with a keel of two layers (two water form slabs), one whose keel is scaled, one with more
  // corners than it packs, and one without air drag. Some floes need the Jacobian, some move
  // with the current or the wind without spin (that term adds nothing), and in still water and
  // air some are at rest (most moving: the terms take their lanes directly; most at rest: the
  // moving bodies alone, and the pass the groups with a moving floe). Two steps each, started
  // from another term's sums and rate bounds.
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr std::size_t n = 45;
  int compared = 0;
  for (const LaneIsa isa : available_lane_isas()) {
    use_lane_isa(isa);
    for (const bool rotational : {true, false})
      for (const int mode : {0, 1, 2, 3}) {  // current and wind; current, still air; still, most moving; still, most at rest
        INFO("isa " << static_cast<int>(isa) << " rotational " << rotational << " mode " << mode);
        EnvironmentSpec env;
        env.rotational_damping = rotational;
        const Vec2 current = mode <= 1 ? Vec2{0.4 * u(rng), 0.4 * u(rng)} : Vec2{};
        const Vec2 wind = mode == 0 ? Vec2{8.0 * u(rng), 8.0 * u(rng)} : Vec2{};
        using Kind = DistributedDrag::Kind;
        struct Body {
          std::vector<DragSlab> keel, water_skin, air_form, air_skin;  // air: empty where none
        };
        std::vector<std::vector<Vec2>> polys(n);
        std::vector<Body> bodies(n);
        std::size_t expect_shared = 0;
        for (std::size_t i = 0; i < n; ++i) {
          const int corners = i == 17 ? 30 : 3 + static_cast<int>((i * 5) % 9);
          const double size = 2.5 + 14.0 * (1.0 + u(rng));
          polys[i] = test::jittered_polygon(rng, corners, size);
          const bool zero_edge = i == 4, two_layers = i == 9, scaled = i == 22, no_air = i == 31;
          if (zero_edge) polys[i].insert(polys[i].begin() + 1, polys[i][1]);
          const double h = 0.5 + 2.0 * (1.0 + u(rng));
          Body& b = bodies[i];
          b.keel = {{0.5 * 1025.0 * 0.6 * h, scaled ? 0.9 : 1.0, current}};
          if (two_layers) b.keel = {{200.0, 1.0, current}, {150.0, 0.8, 0.5 * current}};
          b.water_skin = {{1025.0 * 0.0055, 1.0, current}};
          if (!no_air) {
            b.air_form = {{0.5 * 1.3 * 0.4 * 0.2 * h, 1.0, wind}};
            b.air_skin = {{1.3 * 0.0025, 1.0, wind}};
          }
          if (!(zero_edge || two_layers || scaled || no_air || i == 17)) ++expect_shared;
        }
        // The same four terms twice: added one by one, and through the pass.
        struct Terms {
          DistributedDrag water_form, water_skin, air_form, air_skin;
          std::vector<DistributedDrag*> all() { return {&water_form, &water_skin, &air_form, &air_skin}; }
        };
        auto make = [&] {
          auto t = std::make_unique<Terms>(Terms{DistributedDrag("water_form", Kind::form, env, DistributedDrag::Medium::water),
                                                 DistributedDrag("water_skin", Kind::skin, env, DistributedDrag::Medium::water),
                                                 DistributedDrag("air_form", Kind::form, env, DistributedDrag::Medium::air),
                                                 DistributedDrag("air_skin", Kind::skin, env, DistributedDrag::Medium::air)});
          for (std::size_t i = 0; i < n; ++i) {
            t->water_form.add_body(i, polys[i], bodies[i].keel);
            t->water_skin.add_body(i, polys[i], bodies[i].water_skin);
            if (!bodies[i].air_form.empty()) {
              t->air_form.add_body(i, polys[i], bodies[i].air_form);
              t->air_skin.add_body(i, polys[i], bodies[i].air_skin);
            }
          }
          return t;
        };
        const auto alone_terms = make(), pass_terms = make();
        const DragPass pass(pass_terms->all(), [&](std::size_t i) -> const std::vector<Vec2>& { return polys[i]; });
        CHECK(pass.floes() == expect_shared);
        for (int step = 0; step < 2; ++step) {
          INFO("step " << step);
          BodyStates s;
          s.resize(n);
          ForceSums sums;
          sums.q.resize(n);
          sums.dq.assign(n, {});
          sums.rotation_rate.assign(n, 0.0);
          sums.rotation.resize(n);
          sums.jacobian.assign(n, 0);
          sums.rate_bound.resize(n);
          for (std::size_t i = 0; i < n; ++i) {
            const auto k = i + static_cast<std::size_t>(step);
            const bool rests = mode >= 2 && (k % 6 == 2) == (mode == 2);
            const bool with_current = mode <= 1 && k % 10 == 3, with_wind = mode == 0 && k % 10 == 6;
            s.velocity[i] = rests ? Vec2{} : with_current ? current : with_wind ? wind : Vec2{0.8 * u(rng), 0.8 * u(rng)};
            s.angular_velocity[i] = rests || with_current || with_wind ? 0.0 : 0.02 * u(rng);
            s.angle[i] = M_PI * u(rng);
            sums.rotation[i] = Rot::from_angle(s.angle[i]);
            sums.jacobian[i] = k % 8 == 5 ? 1 : 0;
            sums.q[i] = {1e3 * u(rng), 1e3 * u(rng), 1e4 * u(rng)};  // another term's sums
            sums.rate_bound[i] = {10.0 * (1.0 + u(rng)), 10.0 * (1.0 + u(rng))};
            if (!rests) sums.stirred.push_back(static_cast<std::int32_t>(i));
          }
          ForceSums alone = sums, shared = sums;
          for (const DistributedDrag* t : alone_terms->all()) REQUIRE(t->add_rate_bound(s, alone));
          for (const DistributedDrag* t : alone_terms->all()) t->add(s, 0.0, alone);
          pass.add_rate_bound(s, shared);
          pass.add(s, 0.0, shared);
          CHECK(shared.any_jacobian == alone.any_jacobian);
          for (std::size_t i = 0; i < n; ++i) {
            INFO("body " << i);
            for (int k = 0; k < 3; ++k) CHECK(same(shared.q[i][k], alone.q[i][k]));
            for (int k = 0; k < 2; ++k) CHECK(same(shared.rate_bound[i][k], alone.rate_bound[i][k]));
            CHECK(shared.dq[i] == alone.dq[i]);
            ++compared;
          }
        }
      }
  }
  use_fastest_lane_isa();
  CHECK(compared > 0);
}

TEST_CASE("drag pass: Forcing gives the loads of the terms one by one, to the bit", "[forcing]") {
  // A drifting field's scene through Forcing, with and without the shared pass.
  const Scene scene = load_scenario(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/drift_in_field.toml");
  Forcing with(scene), without(scene, false);
  std::size_t floes = 0;
  for (const BodySpec& b : scene.bodies) floes += b.kind == BodyKind::floe ? 1 : 0;
  CHECK(with.drag_pass_floes() == floes);  // every floe: the iceberg has two keel layers
  CHECK(without.drag_pass_floes() == 0);
  BodyStates s;
  s.resize(scene.bodies.size());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int step = 0; step < 3; ++step) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      if (scene.bodies[i].fixed) continue;
      s.velocity[i] = {0.5 * u(rng), 0.5 * u(rng)};
      s.angular_velocity[i] = 0.01 * u(rng);
      s.angle[i] = M_PI * u(rng);
    }
    const Loads* a = with.evaluate(s, 0.05 * step);
    const Loads* b = without.evaluate(s, 0.05 * step);
    REQUIRE(a != nullptr);
    REQUIRE(b != nullptr);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      INFO("body " << i << " step " << step);
      CHECK(same(a->force[i].x, b->force[i].x));
      CHECK(same(a->force[i].y, b->force[i].y));
      CHECK(same(a->torque[i], b->torque[i]));
    }
  }
}
