// Checkpoint and restart: a run killed mid-way and continued with `floedem run --resume`
// ends with the file of a run never interrupted, every dataset and attribute to the bit.
#include <catch2/catch.hpp>

#include <hdf5.h>
#include <H5Cpp.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "floedem/engine/registry.hpp"
#include "io/recorder.hpp"
#include "run/stepper.hpp"
#include "floedem/engine/state_io.hpp"
#include "run/file_contents.hpp"
#include "support.hpp"

using namespace floedem;
using test::check_same_contents;
using test::contents;
using test::Contents;
namespace fs = std::filesystem;

namespace {

/// An iceberg on a rope through a generated field of ~300 floes, drifting in wind and current
/// with Coriolis and waves, every output on: the state of every part of a run (rope,
/// collisions under way, contact loads, warm-started manifolds, the broad phase's cache)
/// must come back from a checkpoint. Frames every 2nd step: a checkpoint about every 100 steps.
const std::string kScenario = R"(
[run]
duration = 60.0
dt = 0.05
output_every = 2
seed = 5
[contact]
restitution = 0.2
friction = 0.3
[output]
contacts = "all"
loads = ["iceberg"]
load_every = 7
tow_every = 3
[environment]
current = [0.2, 0.05]
wind = [6.0, -2.0]
latitude = 70.0
[environment.waves]
amplitude = 0.5
period = 8.0
direction = 30.0
[[body]]
name = "iceberg"
kind = "iceberg"
polygon = [[-30, -20], [25, -25], [30, 15], [-5, 28], [-28, 10]]
draft = 40.0
sail_height = 10.0
[tow]
mode = "rope"
body = "iceberg"
tug_velocity = [0.8, 0.1]
stiffness = 2e5
length = 60.0
damping = 1e4
[field]
origin = [-150.0, -120.0]
width = 300.0
height = 240.0
concentration = 0.6
alpha = 2.0
d_min = 6.0
d_max = 30.0
thickness = 1.0
velocity = [0.1, 0.0]
)";

struct Files {
  fs::path dir, scenario;
};

Files write_scenario(const std::string& name, const std::string& text = kScenario) {
  Files f{test::temp_dir("resume-" + name), {}};
  f.scenario = f.dir / "towed.toml";
  std::ofstream(f.scenario) << text;
  return f;
}

std::string run_args(const Files& f, const std::string& out, const std::string& extra = "") {
  return "run " + f.scenario.string() + " -q --out " + (f.dir / out).string() + " " + extra;
}

}  // namespace

TEST_CASE("resume: a run killed mid-way and continued gives the uninterrupted run's file", "[resume]") {
  const Files f = write_scenario("killed");
  REQUIRE(test::run_cli(run_args(f, "whole.h5")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");
  REQUIRE(whole.count("/checkpoint/slot_a"));
  REQUIRE(whole.count("/checkpoint/slot_b"));
  REQUIRE(whole.count("/tow/force"));
  REQUIRE(whole.count("/loads/force"));

  // Killed (SIGKILL, no destructor runs) after step 777 of 1200, between two checkpoints.
  const auto killed = test::run_cli(run_args(f, "cut.h5"), "FLOEDEM_TEST_KILL_AT_STEP=777 ");
  CHECK(killed.code != 0);
  CHECK_FALSE(fs::exists(f.dir / "cut.h5"));
  REQUIRE(fs::exists(f.dir / "cut.h5.partial"));
  const StoredRun stored = read_stored_run((f.dir / "cut.h5.partial").string());
  CHECK(stored.status == "running");
  REQUIRE(stored.checkpoint);
  CHECK(stored.checkpoint->step < 777);
  CHECK(stored.checkpoint->step > 500);

  // Continued: by its final name (the .partial is found) or by the .partial's own name.
  const std::string target = GENERATE(std::string("cut.h5"), std::string("cut.h5.partial"));
  INFO("--resume " << target);
  const auto resumed = test::run_cli("run --resume " + (f.dir / target).string());
  INFO(resumed.output);
  REQUIRE(resumed.code == 0);
  CHECK(resumed.output.find("continued from the checkpoint at t = ") != std::string::npos);
  CHECK_FALSE(fs::exists(f.dir / "cut.h5.partial"));
  REQUIRE(fs::exists(f.dir / "cut.h5"));
  check_same_contents(whole, f.dir / "cut.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: a tug's tow whose rope parted, killed and continued gives the uninterrupted run's file",
          "[resume][tug]") {
  // The tow line's own state (the tug's place and speed, the parting, the outcome's tallies)
  // must come back from a checkpoint: the rope parts near t = 5 s, the kill comes at step 777.
  std::string text = kScenario;
  const std::string rope = "mode = \"rope\"\nbody = \"iceberg\"\ntug_velocity = [0.8, 0.1]\n";
  REQUIRE(text.find(rope) != std::string::npos);
  text.replace(text.find(rope), rope.size(),
               "mode = \"tug\"\nbody = \"iceberg\"\ndirection = [1.0, 0.1]\nbollard_pull = 4e5\n"
               "free_running_speed = 5.0\nbreaking_load = 6e5\n");
  const Files f = write_scenario("tug", text);
  REQUIRE(test::run_cli(run_args(f, "whole.h5")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");
  REQUIRE(whole.count("/tow/tug_velocity"));
  REQUIRE(whole.count("/@summary_tow_parted_at"));
  REQUIRE(test::run_cli(run_args(f, "cut.h5"), "FLOEDEM_TEST_KILL_AT_STEP=777 ").code != 0);
  const auto resumed = test::run_cli("run --resume " + (f.dir / "cut.h5").string());
  INFO(resumed.output);
  REQUIRE(resumed.code == 0);
  CHECK(resumed.output.find("parted at t = ") != std::string::npos);
  check_same_contents(whole, f.dir / "cut.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: a geographic run killed and continued gives the uninterrupted run's file", "[resume][geo]") {
  // The same scene on the earth (docs/geography.md): each body's Coriolis parameter comes from
  // tiles of a lattice built as the bodies reach them, and /bodies/lonlat is written per frame.
  std::string text = kScenario;
  const std::string latitude = "latitude = 70.0\n";
  REQUIRE(text.find(latitude) != std::string::npos);
  text.replace(text.find(latitude), latitude.size(), "");
  const Files f = write_scenario("geo", text + "[geo]\norigin = [20.0, 70.0]\n");
  REQUIRE(test::run_cli(run_args(f, "whole.h5")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");
  REQUIRE(whole.count("/bodies/lonlat"));
  REQUIRE(test::run_cli(run_args(f, "cut.h5"), "FLOEDEM_TEST_KILL_AT_STEP=777 ").code != 0);
  const auto resumed = test::run_cli("run --resume " + (f.dir / "cut.h5").string());
  INFO(resumed.output);
  REQUIRE(resumed.code == 0);
  check_same_contents(whole, f.dir / "cut.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: a run on the pressure-area force model killed and continued is the same file", "[resume]") {
  // Its open collision events carry their contact width's law through the checkpoint.
  std::string text = kScenario;
  const std::string friction = "friction = 0.3\n";
  REQUIRE(text.find(friction) != std::string::npos);
  text.insert(text.find(friction) + friction.size(), "force_model = \"pressure_area\"\n");
  const Files f = write_scenario("crushing", text);
  REQUIRE(test::run_cli(run_args(f, "whole.h5")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");
  REQUIRE(whole.count("/contacts/collisions/contact_width"));
  REQUIRE(test::run_cli(run_args(f, "cut.h5"), "FLOEDEM_TEST_KILL_AT_STEP=777 ").code != 0);
  const auto resumed = test::run_cli("run --resume " + (f.dir / "cut.h5").string());
  INFO(resumed.output);
  REQUIRE(resumed.code == 0);
  check_same_contents(whole, f.dir / "cut.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: a forcing file changed since the run read it is refused, an unchanged one continued", "[resume]") {
  std::string text = kScenario;
  const std::string wind = "wind = [6.0, -2.0]\n";
  REQUIRE(text.find(wind) != std::string::npos);
  text.erase(text.find(wind), wind.size());
  const Files f = write_scenario("inputs", text + "[environment.wind_file]\nfile = \"wind.csv\"\n");
  const std::string record = "time,u,v\n0,6,-2\n30,5,-1\n60,6,-2\n";
  std::ofstream(f.dir / "wind.csv") << record;
  REQUIRE(test::run_cli(run_args(f, "whole.h5")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");
  // The record: FNV-1a of the file's bytes, its size and path.
  const std::uint64_t digest =
      state_checksum(reinterpret_cast<const std::uint8_t*>(record.data()), record.size());
  char expected[64];
  std::snprintf(expected, sizeof expected, "fnv1a64 %016llx, %zu bytes, ", static_cast<unsigned long long>(digest),
                record.size());
  REQUIRE(whole.count("/inputs@environment.wind_file.file"));
  CHECK(whole.at("/inputs@environment.wind_file.file").find(expected) != std::string::npos);
  for (const bool change : {true, false}) {
    INFO("file changed: " << change);
    fs::remove(f.dir / "cut.h5");
    std::ofstream(f.dir / "wind.csv") << record;
    REQUIRE(test::run_cli(run_args(f, "cut.h5"), "FLOEDEM_TEST_KILL_AT_STEP=777 ").code != 0);
    std::ofstream(f.dir / "wind.csv") << (change ? "time,u,v\n0,6,-2\n30,5,-1.5\n60,6,-2\n" : record);
    const auto resumed = test::run_cli("run --resume " + (f.dir / "cut.h5").string());
    INFO(resumed.output);
    if (change) {
      CHECK(resumed.code == 2);
      CHECK(resumed.output.find("environment.wind_file.file") != std::string::npos);
      CHECK(resumed.output.find("has changed since the run read it") != std::string::npos);
      CHECK(fs::exists(f.dir / "cut.h5.partial"));  // left as it was, for a continuation once restored
      fs::remove(f.dir / "cut.h5.partial");
    } else {
      REQUIRE(resumed.code == 0);
      check_same_contents(whole, f.dir / "cut.h5");
    }
  }
  fs::remove_all(f.dir);
}

TEST_CASE("resume: killed twice, and a damaged checkpoint falls back to the other slot", "[resume]") {
  const Files f = write_scenario("twice");
  REQUIRE(test::run_cli(run_args(f, "whole.h5")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");

  REQUIRE(test::run_cli(run_args(f, "cut.h5"), "FLOEDEM_TEST_KILL_AT_STEP=450 ").code != 0);
  // The continuation is killed too, further on.
  REQUIRE(test::run_cli("run --resume " + (f.dir / "cut.h5").string() + " -q", "FLOEDEM_TEST_KILL_AT_STEP=900 ").code != 0);
  const fs::path partial = f.dir / "cut.h5.partial";
  const StoredRun before = read_stored_run(partial.string());
  REQUIRE(before.checkpoint);
  CHECK(before.checkpoint->step > 700);
  CHECK(before.damaged_slots == 0);
  {
    // A kill while a checkpoint was written: one byte of the newest slot changed.
    H5::H5File file(partial.string(), H5F_ACC_RDWR);
    for (const char* name : {"/checkpoint/slot_a", "/checkpoint/slot_b"}) {
      H5::DataSet slot = file.openDataSet(name);
      std::int64_t step = 0;
      slot.openAttribute("step").read(H5::PredType::NATIVE_INT64, &step);
      if (step != before.checkpoint->step) continue;
      std::vector<std::uint8_t> bytes(static_cast<std::size_t>(slot.getSpace().getSimpleExtentNpoints()));
      slot.read(bytes.data(), H5::PredType::NATIVE_UINT8);
      bytes[bytes.size() / 2] ^= 0x10;
      slot.write(bytes.data(), H5::PredType::NATIVE_UINT8);
    }
  }
  const StoredRun damaged = read_stored_run(partial.string());
  CHECK(damaged.damaged_slots == 1);
  REQUIRE(damaged.checkpoint);
  CHECK(damaged.checkpoint->step < before.checkpoint->step);

  REQUIRE(test::run_cli("run --resume " + (f.dir / "cut.h5").string() + " -q").code == 0);
  check_same_contents(whole, f.dir / "cut.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: a finished run lengthened with run.duration is the longer run", "[resume]") {
  const Files f = write_scenario("longer");
  // The longer run made at once, and the same made as a 30 s run continued to 60 s.
  REQUIRE(test::run_cli(run_args(f, "whole.h5", "--set run.duration=60")).code == 0);
  REQUIRE(test::run_cli(run_args(f, "short.h5", "--set run.duration=30.05")).code == 0);
  const auto same = test::run_cli("run --resume " + (f.dir / "short.h5").string());
  CHECK(same.code == 0);
  CHECK(same.output.find("the run is complete") != std::string::npos);
  const auto longer = test::run_cli("run --resume " + (f.dir / "short.h5").string() + " -q --set run.duration=60");
  INFO(longer.output);
  REQUIRE(longer.code == 0);
  check_same_contents(contents(f.dir / "whole.h5"), f.dir / "short.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: SIGTERM checkpoints the step the run stopped after, continued it is the uninterrupted file",
          "[resume][signal]") {
  const Files f = write_scenario("term");
  REQUIRE(test::run_cli(run_args(f, "whole.h5")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");
  CHECK_FALSE(whole.count("/checkpoint/stopped"));

  // SIGTERM after step 777 of 1200 (a batch system's notice): the run ends that step, writes
  // its checkpoint and exits 128 + 15, the file left as .partial.
  const auto stopped = test::run_cli(run_args(f, "cut.h5"), "FLOEDEM_TEST_TERM_AT_STEP=777 ");
  INFO(stopped.output);
  CHECK(stopped.code == 143);
  CHECK(stopped.output.find("SIGTERM: stopped after step 777 (t = 38.85 s)") != std::string::npos);
  CHECK(stopped.output.find("floedem run --resume") != std::string::npos);
  CHECK_FALSE(fs::exists(f.dir / "cut.h5"));
  REQUIRE(fs::exists(f.dir / "cut.h5.partial"));
  StoredRun stored = read_stored_run((f.dir / "cut.h5.partial").string());
  CHECK(stored.status == "running");
  REQUIRE(stored.checkpoint);
  CHECK(stored.checkpoint->step == 777);

  // Continued and stopped again, then continued to the end.
  const auto again = test::run_cli("run --resume " + (f.dir / "cut.h5").string() + " -q", "FLOEDEM_TEST_TERM_AT_STEP=1001 ");
  INFO(again.output);
  CHECK(again.code == 143);
  stored = read_stored_run((f.dir / "cut.h5.partial").string());
  REQUIRE(stored.checkpoint);
  CHECK(stored.checkpoint->step == 1001);
  const auto resumed = test::run_cli("run --resume " + (f.dir / "cut.h5").string());
  INFO(resumed.output);
  REQUIRE(resumed.code == 0);
  CHECK(resumed.output.find("continued from the checkpoint at t = 50.05 s") != std::string::npos);
  check_same_contents(whole, f.dir / "cut.h5");

  // A stop asked for at the last step changes nothing: the run ends whole.
  const auto last = test::run_cli(run_args(f, "last.h5"), "FLOEDEM_TEST_TERM_AT_STEP=1200 ");
  CHECK(last.code == 0);
  check_same_contents(whole, f.dir / "last.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: floes at rest (sleeping, manifolds carried over) stopped and killed, the same file",
          "[resume][signal]") {
  // The iceberg towed into a field at rest: the floes ahead of it sleep and their parts and
  // manifolds are kept from step to step, caches that a continued run starts without. What
  // they save is the process's (floedem bench's work counts), not the file's, so a run
  // stopped or killed anywhere and continued still ends as the uninterrupted one.
  std::string text = kScenario;
  for (const std::string line : {"current = [0.2, 0.05]\n", "wind = [6.0, -2.0]\n", "velocity = [0.1, 0.0]\n"}) {
    REQUIRE(text.find(line) != std::string::npos);
    text.replace(text.find(line), line.size(), "");
  }
  const std::string waves = "[environment.waves]\namplitude = 0.5\nperiod = 8.0\ndirection = 30.0\n";
  REQUIRE(text.find(waves) != std::string::npos);
  text.replace(text.find(waves), waves.size(), "");
  const Files f = write_scenario("rest", text);
  REQUIRE(test::run_cli(run_args(f, "whole.h5", "--set run.duration=90")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");
  for (const std::string hook : {"FLOEDEM_TEST_TERM_AT_STEP=1333 ", "FLOEDEM_TEST_KILL_AT_STEP=1333 "}) {
    INFO(hook);
    fs::remove(f.dir / "cut.h5");
    REQUIRE(test::run_cli(run_args(f, "cut.h5", "--set run.duration=90"), hook).code != 0);
    const auto resumed = test::run_cli("run --resume " + (f.dir / "cut.h5").string() + " -q");
    INFO(resumed.output);
    REQUIRE(resumed.code == 0);
    check_same_contents(whole, f.dir / "cut.h5");
  }
  fs::remove_all(f.dir);
}

TEST_CASE("resume: an engine without checkpoints stopped by SIGTERM says so and runs again from the start",
          "[resume][signal]") {
  if (!test::have_engine("box2d")) return;
  const Files f = write_scenario("term-box2d");
  REQUIRE(test::run_cli(run_args(f, "whole.h5", "-e box2d --set run.duration=10")).code == 0);
  const auto stopped = test::run_cli(run_args(f, "cut.h5", "-e box2d --set run.duration=10"), "FLOEDEM_TEST_TERM_AT_STEP=150 ");
  INFO(stopped.output);
  CHECK(stopped.code == 143);
  CHECK(stopped.output.find("the box2d engine cannot save its state") != std::string::npos);
  REQUIRE(fs::exists(f.dir / "cut.h5.partial"));
  REQUIRE(test::run_cli("run --resume " + (f.dir / "cut.h5").string() + " -q").code == 0);
  check_same_contents(contents(f.dir / "whole.h5"), f.dir / "cut.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: an engine without checkpoints runs again from the start, to the same file", "[resume]") {
  if (!test::have_engine("box2d")) return;
  const Files f = write_scenario("box2d");
  REQUIRE(test::run_cli(run_args(f, "whole.h5", "-e box2d --set run.duration=10")).code == 0);
  const Contents whole = contents(f.dir / "whole.h5");
  CHECK_FALSE(whole.count("/checkpoint"));
  REQUIRE(test::run_cli(run_args(f, "cut.h5", "-e box2d --set run.duration=10"), "FLOEDEM_TEST_KILL_AT_STEP=150 ").code != 0);
  const auto resumed = test::run_cli("run --resume " + (f.dir / "cut.h5").string());
  INFO(resumed.output);
  REQUIRE(resumed.code == 0);
  CHECK(resumed.output.find("the box2d engine cannot save its state") != std::string::npos);
  check_same_contents(whole, f.dir / "cut.h5");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: bad input is refused with the file and the reason, exit 2, nothing changed", "[resume][bad-input]") {
  const Files f = write_scenario("bad");
  REQUIRE(test::run_cli(run_args(f, "r.h5", "--set run.duration=20")).code == 0);
  const fs::path r = f.dir / "r.h5";
  const auto missing = test::run_cli("run --resume " + (f.dir / "none.h5").string());
  CHECK(missing.code == 2);
  CHECK(missing.output.find("none.h5: no such run output") != std::string::npos);
  const auto not_hdf5 = test::run_cli("run --resume " + f.scenario.string());
  CHECK(not_hdf5.code == 2);
  CHECK(not_hdf5.output.find("not an HDF5 file") != std::string::npos);
  const auto other_key = test::run_cli("run --resume " + r.string() + " --set run.dt=0.1");
  CHECK(other_key.code == 2);
  CHECK(other_key.output.find("only run.duration may be set") != std::string::npos);
  const auto shorter = test::run_cli("run --resume " + r.string() + " --set run.duration=1");
  CHECK(shorter.code == 2);
  CHECK(shorter.output.find("before the checkpoint") != std::string::npos);
  CHECK(test::run_cli("run --resume " + r.string() + " -e box2d").code == 2);
  CHECK(test::run_cli("run " + f.scenario.string() + " --resume " + r.string()).code == 2);
  // Refused requests leave the run's file as it was.
  CHECK(fs::exists(r));
  CHECK_FALSE(fs::exists(r.string() + ".partial"));
  CHECK(read_stored_run(r.string()).status == "complete");
  fs::remove_all(f.dir);
}

TEST_CASE("resume: the native engine restored from its state steps on to the bit", "[resume]") {
  // A jam: many resting contacts carried over by warm start, the broad phase's cache in use.
  std::string text = test::header_toml(1.0, 0.05, 0.1, 0.3, "[environment]\ncurrent = [-0.6, 0.1]\n");
  text += test::body_toml({"wall", test::box({-2, 50}, 4, 120), {}, 0.0, true});
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 10; ++j)
      text += test::body_toml({"f" + std::to_string(i) + "_" + std::to_string(j),
                               test::box({6.0 + 11.5 * i, 5.0 + 11.5 * j}, 9.0, 9.5, 0.02 * (i - j)), {-0.3, 0.0}});
  const Scene s = test::scene_from(text);
  Stepper a(s, "native");
  for (int k = 0; k < 1200; ++k) a.step();
  REQUIRE(a.contacts().size() > 50);
  StateWriter saved;
  REQUIRE(a.save(saved));
  Stepper b(s, "native");
  StateReader in(saved.bytes().data(), saved.bytes().size());
  b.restore(in);
  CHECK(in.left() == 0);
  CHECK(b.steps_done() == 1200);
  for (int k = 0; k < 200; ++k) {
    a.step();
    b.step();
  }
  const BodyStates& x = a.state();
  const BodyStates& y = b.state();
  bool identical = true;
  for (std::size_t i = 0; i < x.position.size(); ++i)
    identical = identical && x.position[i].x == y.position[i].x && x.position[i].y == y.position[i].y &&
                x.angle[i] == y.angle[i] && x.velocity[i].x == y.velocity[i].x &&
                x.angular_velocity[i] == y.angular_velocity[i];
  CHECK(identical);
  CHECK(a.engine().info().settings == b.engine().info().settings);  // sweeps, restarts, broad-phase counts
  // Another scene's state is refused, not read as garbage.
  const Scene other = test::scene_from(test::header_toml(1.0, 0.05, 0.1, 0.3) + test::body_toml({"a", test::box({0, 0}, 5, 5)}));
  Stepper c(other, "native");
  StateReader wrong(saved.bytes().data(), saved.bytes().size());
  CHECK_THROWS_AS(c.restore(wrong), StateError);
  // A reference engine has no state to save.
  if (test::have_engine("box2d")) {
    Stepper d(s, "box2d");
    StateWriter none;
    CHECK_FALSE(d.save(none));
    CHECK(none.bytes().empty());
  }
}
