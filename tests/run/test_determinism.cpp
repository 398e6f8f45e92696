// The same scenario twice gives bit-identical output, on every engine.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>

#include "floedem/engine/registry.hpp"
#include "parallel/thread_pool.hpp"
#include "parallel/threads.hpp"
#include "floedem/run/simulation.hpp"
#include "run/stepper.hpp"
#include "floedem/scenario/scenario.hpp"
#include "support.hpp"

using namespace floedem;
namespace fs = std::filesystem;

namespace {

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST_CASE("determinism: two runs of one scenario give identical files", "[determinism]") {
  // Every engine: a reference that reads memory it should not (Box2D's second impulse of a
  // manifold it solved as one point) gives different records from run to run.
  std::vector<std::string> names;
  for (const EngineEntry& e : engines()) names.push_back(e.name);
  const std::string engine = GENERATE_COPY(from_range(names));
  INFO("engine " << engine);
  // A jostling cluster: many collisions and resting contacts, friction, rotation.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::string text = test::header_toml(30.0, 0.02, 0.3, 0.4);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const Vec2 c{12.0 * i, 12.0 * j};
      text += test::body_toml({"f" + std::to_string(i) + "_" + std::to_string(j), test::box(c, 8 + u(rng), 8 + u(rng), 0.3 * u(rng)),
                               {-0.5 * c.x / 30.0 + 0.3 * u(rng), -0.5 * c.y / 30.0 + 0.3 * u(rng)}, 0.05 * u(rng)});
    }
  const Scene s = test::scene_from(text);
  const fs::path dir = fs::temp_directory_path() / ("floedem-det-" + engine + std::to_string(::getpid()));
  fs::create_directories(dir);
  RunOptions o;
  o.engine = engine;
  o.output = (dir / "one.h5").string();
  const RunSummary first = run_scene(s, o);
  o.output = (dir / "two.h5").string();
  const RunSummary second = run_scene(s, o);
  CHECK(first.collision_impulses > 10);
  CHECK(first.resting_impulses > 10);
  CHECK(first.collision_impulses == second.collision_impulses);
  CHECK(first.kinetic_energy_end == second.kinetic_energy_end);
  // Bit-identical files: no timestamps are stored, and the solver's order is fixed.
  const std::string a = read_bytes(dir / "one.h5"), b = read_bytes(dir / "two.h5");
  CHECK(a.size() == b.size());
  CHECK(a == b);
  fs::remove_all(dir);
}

TEST_CASE("determinism: the same file on 1 and on 4 threads", "[determinism]") {
  // Some 4 000 floes driven by the current onto a wall, with Coriolis added: every loop the
  // pool splits (drag, forcing, placing, narrow phase, integration) has many blocks here.
  const Scene s = load_scenario(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/bench/field_wall_4k.toml",
                                {"run.duration=15", "run.output_every=50", "environment.latitude=70"});
  REQUIRE(s.bodies.size() > 2000);
  const fs::path dir = fs::temp_directory_path() / ("floedem-threads-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  RunOptions o;
  std::string files[2];
  const unsigned counts[2] = {1, 4};
  for (int k = 0; k < 2; ++k) {
    set_thread_pool_size(counts[k]);
    REQUIRE(thread_pool().size() == counts[k]);
    o.output = (dir / ("t" + std::to_string(counts[k]) + ".h5")).string();
    const RunSummary r = run_scene(s, o);
    CHECK(r.resting_impulses + r.collision_impulses > 0);
    files[k] = read_bytes(o.output);
  }
  set_thread_pool_size(worker_threads());
  CHECK(files[0].size() == files[1].size());
  CHECK(files[0] == files[1]);
  fs::remove_all(dir);
}

TEST_CASE("determinism: timing the stages changes nothing, and the stages add up", "[determinism][stages]") {
  // `floedem bench` times each stage of a step (Stepper::time_stages): the same steps with the
  // clocks on must give the same state to the bit, and the stages' sums must account for the
  // steps' wall time without exceeding it. Native times its own stages; Box2D's come from its
  // b2Profile, the adapter's from its own clocks.
  const std::string engine = GENERATE(as<std::string>{}, "native", "box2d");
  if (!test::have_engine(engine)) return;
  INFO("engine " << engine);
  const std::map<std::string, std::vector<std::string>> expected = {
      {"native", {"forcing", "broad_phase", "narrow_phase", "contact_list", "loads", "contact_solve", "redetect",
                  "integrate", "position_projection", "record", "sleep", "towing"}},
      {"box2d", {"forcing", "loads", "narrow_phase", "contact_solve", "islands_integrate", "broad_phase", "toi",
                 "step_other", "publish", "towing"}}};
  const Scene s = load_scenario(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/bench/field_wall_1k.toml",
                                {"run.duration=20"});
  Stepper plain(s, engine), timed(s, engine);
  timed.time_stages(true);
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < 200; ++k) timed.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (int k = 0; k < 200; ++k) plain.step();
  const BodyStates& a = plain.state();
  const BodyStates& b = timed.state();
  REQUIRE(a.position.size() == b.position.size());
  for (std::size_t i = 0; i < a.position.size(); ++i) {
    INFO("body " << i);
    REQUIRE(same_bits(a.position[i].x, b.position[i].x));
    REQUIRE(same_bits(a.position[i].y, b.position[i].y));
    REQUIRE(same_bits(a.angle[i], b.angle[i]));
    REQUIRE(same_bits(a.velocity[i].x, b.velocity[i].x));
    REQUIRE(same_bits(a.velocity[i].y, b.velocity[i].y));
    REQUIRE(same_bits(a.angular_velocity[i], b.angular_velocity[i]));
  }

  std::vector<std::string> names;
  std::map<std::string, double> seconds;
  double sum = 0.0;
  for (const StageTime& t : timed.stage_times()) {
    names.push_back(t.name);
    seconds[t.name] = t.seconds;
    CHECK(t.seconds >= 0.0);
    sum += t.seconds;
  }
  CHECK(names == expected.at(engine));
  // A drifting field in contact: drag, pairs, contacts and impulses every step; no tow.
  CHECK(seconds["forcing"] > 0.0);
  CHECK(seconds["narrow_phase"] > 0.0);
  CHECK(seconds["contact_solve"] > 0.0);
  CHECK(seconds["towing"] == 0.0);
  CHECK(sum <= 1.001 * wall);  // Box2D's own timers are in float milliseconds
  CHECK(sum > 0.5 * wall);     // the stages are the step: what lies between them is a few calls

  // Off (the default): nothing is summed.
  double untimed = 0.0;
  for (const StageTime& t : plain.stage_times()) untimed += t.seconds;
  CHECK(untimed == 0.0);
}
