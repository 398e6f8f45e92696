// Sleeping islands (engine.native.sleep; docs/model.md, sleeping): what falls asleep, what it
// carries while asleep, what wakes it, and that a checkpoint holds it.
#include <catch2/catch.hpp>

#include <cstring>
#include <string>

#include "support.hpp"

using namespace floedem;
using test::BodyText;

namespace {

// Engine settings for these scenes: a short sleep time, so that a test sees several.
std::string sleep_settings(bool on, double time = 2.0) {
  return "[engine.native]\nsleep = " + std::string(on ? "true" : "false") + "\nsleep_time = " + std::to_string(time) + "\n";
}

double asleep(const Engine& e) { return std::stod(e.info().settings.at("mean_bodies_asleep")); }
long woken(const Engine& e) { return std::stol(e.info().settings.at("sleeping_groups_woken")); }

Loads loads_on(std::size_t n, std::size_t body, Vec2 force) {
  Loads l;
  l.force.assign(n, Vec2{});
  l.torque.assign(n, 0.0);
  l.force[body] = force;
  l.any = true;
  return l;
}

bool same_state(const BodyStates& a, const BodyStates& b) {
  auto same = [](const auto& x, const auto& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
  };
  return same(a.position, b.position) && same(a.angle, b.angle) && same(a.velocity, b.velocity) &&
         same(a.angular_velocity, b.angular_velocity);
}

std::string pushed_floe(bool sleep) {
  return test::header_toml(60.0, 0.01, 0.3, 0.3, sleep_settings(sleep)) + test::floe_and_wall();
}

}  // namespace

TEST_CASE("sleep: a floe pushed on a wall sleeps carrying the push, and wakes when the push turns", "[sleep]") {
  const Scene s = test::scene_from(pushed_floe(true));
  auto e = test::native(s);
  const Loads push = loads_on(2, 0, {test::kWallPush, 0.0});
  for (int k = 0; k < 1000; ++k) e->step(&push);  // 10 s: at rest within a step, asleep after 2 s more
  REQUIRE(asleep(*e) > 0.5);
  // Asleep: not moved, and the wall still carries the push (the held contact's impulses).
  const Vec2 at = e->state().position[0];
  for (int k = 0; k < 100; ++k) {
    e->step(&push);
    REQUIRE(e->state().position[0].x == at.x);
    REQUIRE(e->state().velocity[0].x == 0.0);
    // 0.1 %: the resting contact's tolerance (test_resting.cpp); held, it is the same impulse.
    REQUIRE(std::abs(-test::contact_force_x(*e, 0, 0.01) - test::kWallPush) <= 1e-3 * test::kWallPush);
  }
  // The push turned: the floe wakes in the same step and leaves the wall at F dt / m.
  const Loads pull = loads_on(2, 0, {-test::kWallPush, 0.0});
  e->step(&pull);
  CHECK(woken(*e) == 1);
  const double mass = 900.0 * 100.0;
  CHECK(e->state().velocity[0].x == Approx(-test::kWallPush * 0.01 / mass).epsilon(1e-12));
  CHECK(e->state().position[0].x < at.x);
}

TEST_CASE("sleep: a floe struck by a moving one wakes, and the impact is the same to the bit", "[sleep]") {
  // The struck floe is at rest with no load: asleep it is exactly where it was, so waking it
  // when the other comes within reach must give the run without sleeping, to the bit.
  auto scene = [](bool sleep) {
    return test::scene_from(test::header_toml(20.0, 0.01, 0.3, 0.3, sleep_settings(sleep, 1.0)) +
                            test::body_toml({"struck", test::box({0, 0}, 10, 10)}) +
                            test::body_toml({"striker", test::box({13, 1}, 10, 10, 0.1), {-0.5, 0.0}, 0.02}));
  };
  const Scene on = scene(true), off = scene(false);
  auto a = test::native(on);
  auto b = test::native(off);
  bool struck = false;
  for (int k = 0; k < 2000; ++k) {
    a->step(nullptr);
    b->step(nullptr);
    REQUIRE(same_state(a->state(), b->state()));
    struck = struck || !a->contacts().empty();
  }
  CHECK(struck);
  CHECK(woken(*a) == 1);
  CHECK(asleep(*a) > 0.0);
  CHECK(a->state().velocity[0].x < 0.0);
}

TEST_CASE("sleep: a floe struck across a gap into a sleeping one within a step wakes it, as without sleeping",
          "[sleep][impacts]") {
  // Three floes in a row, 5 cm apart; the middle and the last at rest fall asleep, and the first
  // comes in at 5 m/s, e = 1. It wakes the middle one, which leaves at 5 m/s and crosses its gap
  // to the last within the same 0.02 s step: the step's contacts are found again with its reach
  // widened, and there a woken body meets a sleeping one, so every island is solved again with
  // the last floe awake. The sleepers were at rest with no load, so the run must be the one
  // without sleeping to the bit, whose redetection solves only the islands it can touch.
  auto scene = [](bool sleep) {
    return test::scene_from(test::header_toml(1.0, 0.02, 1.0, 0.0, sleep_settings(sleep, 0.04)) +
                            test::body_toml({"a", test::box({-10.55, 0}, 10, 10), {5.0, 0}}) +
                            test::body_toml({"b", test::box({0, 0}, 10, 10)}) +
                            test::body_toml({"c", test::box({10.05, 0}, 10, 10)}));
  };
  const Scene on = scene(true), off = scene(false);
  auto a = test::native(on);
  auto b = test::native(off);
  double deepest = 0.0;
  for (int k = 0; k < 20; ++k) {
    a->step(nullptr);
    b->step(nullptr);
    REQUIRE(same_state(a->state(), b->state()));
    for (const ContactRecord& c : a->contacts()) deepest = std::max(deepest, -c.separation);
  }
  CHECK(test::work_count(*a, "redetections") >= 1.0);
  CHECK(woken(*a) >= 2);             // the middle floe, then the last
  // The last floe was struck, and momentum kept (equal masses, no drag in this scene).
  const std::vector<Vec2>& v = a->state().velocity;
  CHECK(v[2].x > 1.0);
  CHECK(v[0].x + v[1].x + v[2].x == Approx(5.0).epsilon(1e-12));
  CHECK(deepest <= 1e-3 + 1e-9);
}

TEST_CASE("sleep: a floe woken by a redetection after the loads gets its own load", "[sleep][impacts]") {
  // As above, but the last floe is pushed by its load onto a fixed wall beyond it and sleeps
  // carrying the push. Woken by the redetection, after the step's loads were applied, it gets
  // its load then (wake_group): the wall's reaction in the strike's step and the floes' paths
  // are those of the run without sleeping, to the solve's tolerance. Without it the wall would
  // miss the push's impulse, F dt = 400 N s, in that step.
  auto scene = [](bool sleep) {
    return test::scene_from(test::header_toml(1.0, 0.02, 1.0, 0.0, sleep_settings(sleep, 0.04)) +
                            test::body_toml({"a", test::box({-10.55, 0}, 10, 10), {5.0, 0}}) +
                            test::body_toml({"b", test::box({0, 0}, 10, 10)}) +
                            test::body_toml({"c", test::box({10.05, 0}, 10, 10)}) +
                            test::body_toml({"wall", test::box({16.05, 0}, 2, 40), {}, 0.0, true}));
  };
  const Scene on = scene(true), off = scene(false);
  auto a = test::native(on);
  auto b = test::native(off);
  const Loads push = loads_on(4, 2, {test::kWallPush, 0.0});
  double struck_at = -1.0;
  for (int k = 0; k < 20; ++k) {
    a->step(&push);
    b->step(&push);
    INFO("step " << k);
    // The wall's reaction on the last floe, N s a step, against the run without sleeping: to
    // 1e-9 of itself (about 1e6 N s in the strike's step) and 1 mN s (400 N s, the push alone,
    // in the others), far below the 400 N s a missing load would take off.
    const double wall_a = test::contact_force_x(*a, 3, 1.0), wall_b = test::contact_force_x(*b, 3, 1.0);
    CHECK(std::abs(wall_a - wall_b) <= 1e-3 + 1e-9 * std::abs(wall_b));
    if (struck_at < 0.0 && std::abs(wall_b) > 1e4) struck_at = k;
    for (std::size_t i = 0; i < 3; ++i) {
      CHECK(std::abs(a->state().velocity[i].x - b->state().velocity[i].x) <= 1e-9);
      CHECK(std::abs(a->state().position[i].x - b->state().position[i].x) <= 1e-9);
    }
  }
  REQUIRE(struck_at > 2.0);  // the sleepers were asleep when struck (sleep_time: 2 steps)
  CHECK(woken(*a) >= 2);
}

TEST_CASE("sleep: a free floe under a load too small for the timer does not sleep", "[sleep]") {
  // 1e-8 m/s^2 keeps the floe under sleep_speed (1e-5 m/s) for 1 000 s, far past sleep_time:
  // the balance test (a body without contacts needs no load) keeps it awake.
  const Scene s = test::scene_from(test::header_toml(400.0, 1.0, 0.3, 0.3, sleep_settings(true, 60.0)) +
                                   test::body_toml({"floe", test::box({0, 0}, 10, 10)}));
  auto e = test::native(s);
  const double mass = 900.0 * 100.0;
  const Loads creep = loads_on(1, 0, {1e-8 * mass, 0.0});
  for (int k = 0; k < 400; ++k) e->step(&creep);
  CHECK(asleep(*e) == 0.0);
  CHECK(e->state().velocity[0].x == Approx(400 * 1e-8).epsilon(1e-9));
}

TEST_CASE("sleep: two floes in contact drifting under a small common load do not sleep", "[sleep]") {
  // Joined by a contact but held by nothing: their net load must be below the balance test's.
  const Scene s = test::scene_from(test::header_toml(400.0, 1.0, 0.0, 0.3, sleep_settings(true, 60.0)) +
                                   test::body_toml({"a", test::box({0, 0}, 10, 10)}) +
                                   test::body_toml({"b", test::box({10.0005, 0}, 10, 10)}));
  auto e = test::native(s);
  const double mass = 900.0 * 100.0;
  Loads creep = loads_on(2, 0, {1e-8 * mass, 0.0});
  creep.force[1] = creep.force[0];
  for (int k = 0; k < 400; ++k) e->step(&creep);
  CHECK(asleep(*e) == 0.0);
  CHECK(e->state().velocity[1].x == Approx(400 * 1e-8).epsilon(1e-6));
  // Pressed together by opposite loads, the same pair balances and sleeps.
  Loads press = loads_on(2, 0, {1e-3 * mass, 0.0});
  press.force[1] = -press.force[0];
  auto f = test::native(s);
  for (int k = 0; k < 400; ++k) f->step(&press);
  CHECK(asleep(*f) > 0.5);
}

TEST_CASE("sleep: a load on one of the bodies the loads list wakes its sleeping floe", "[sleep]") {
  // Two floes at rest and apart fall asleep without a load. Then a load comes for the second
  // alone, in loads that list the bodies they load (Loads::listed, as a forcing in still water
  // hands them): the engine, which looks at the listed bodies alone once every sleeper's load
  // at sleep was zero, must wake the second and leave the first asleep.
  const Scene s = test::scene_from(test::header_toml(20.0, 0.01, 0.3, 0.3, sleep_settings(true, 1.0)) +
                                   test::body_toml({"first", test::box({0, 0}, 10, 10)}) +
                                   test::body_toml({"second", test::box({40, 0}, 10, 10)}));
  auto e = test::native(s);
  for (int k = 0; k < 300; ++k) e->step(nullptr);  // asleep after 1 s
  REQUIRE(asleep(*e) > 1.0);
  Loads listed = loads_on(2, 1, {test::kWallPush, 0.0});
  listed.listed = true;
  listed.loaded = {1};
  const Vec2 first_at = e->state().position[0];
  e->step(&listed);
  CHECK(woken(*e) == 1);
  const double mass = 900.0 * 100.0;
  CHECK(e->state().velocity[1].x == Approx(test::kWallPush * 0.01 / mass).epsilon(1e-12));
  CHECK(e->state().velocity[0].x == 0.0);
  CHECK(e->state().position[0].x == first_at.x);
}

TEST_CASE("sleep: a checkpoint with sleeping bodies continues to the bit", "[sleep]") {
  const Scene s = test::scene_from(pushed_floe(true) + test::body_toml({"drifter", test::box({-15, 5}, 8, 8), {0.3, 0.0}}));
  const Loads push = loads_on(3, 0, {test::kWallPush, 0.0});
  auto a = test::native(s);
  for (int k = 0; k < 800; ++k) a->step(&push);  // the floe asleep, the drifter on its way to it
  REQUIRE(asleep(*a) > 0.0);
  StateWriter out;
  REQUIRE(a->save_state(out));
  auto b = test::native(s);
  StateReader in(out.bytes().data(), out.bytes().size());
  b->restore_state(in);
  for (int k = 0; k < 6000; ++k) {  // the drifter strikes the sleeping floe and wakes it
    a->step(&push);
    b->step(&push);
    REQUIRE(same_state(a->state(), b->state()));
  }
  CHECK(woken(*a) >= 1);
  CHECK(a->info().settings.at("sleeping_groups_woken") == b->info().settings.at("sleeping_groups_woken"));
}

TEST_CASE("sleep: a scene switch turns it off", "[sleep]") {
  const Scene s = test::scene_from(pushed_floe(false));
  auto e = test::native(s);
  const Loads push = loads_on(2, 0, {test::kWallPush, 0.0});
  for (int k = 0; k < 1000; ++k) e->step(&push);
  CHECK(asleep(*e) == 0.0);
  CHECK(e->info().settings.at("sleep") == "false");
}
