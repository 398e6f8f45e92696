// The HDF5 layout of a run, the temporary name, and a killed run's readability.
#include <catch2/catch.hpp>

#include <H5Cpp.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "floedem/version.hpp"
#include "io/recorder.hpp"
#include "run/stepper.hpp"
#include "floedem/io/output.hpp"
#include "floedem/run/resume.hpp"
#include "floedem/run/simulation.hpp"
#include "floedem/scene/input_error.hpp"
#include "support.hpp"

using namespace floedem;
namespace fs = std::filesystem;

namespace {

std::vector<hsize_t> shape(const H5::DataSet& d) {
  const H5::DataSpace s = d.getSpace();
  std::vector<hsize_t> dims(static_cast<std::size_t>(s.getSimpleExtentNdims()));
  s.getSimpleExtentDims(dims.data());
  return dims;
}

std::string string_attribute(const H5::H5Object& o, const std::string& name) {
  const H5::Attribute a = o.openAttribute(name);
  std::string v;
  a.read(a.getStrType(), v);
  return v;
}

const std::string kScene = test::header_toml(1.0, 0.01, 0.3, 0.3, "[engine.native]\nvelocity_iterations = 20\n") +
                           test::body_toml({"a", test::box({5, 5}, 10, 10), {1.0, 0.0}}) +
                           test::body_toml({"b", {{10.5, 0}, {20.5, 0}, {10.5, 12}}, {}, 0.1});

/// kScene run into a new temporary directory named after `tag`; the output's path.
std::string run_small_scene(const std::string& tag) {
  const std::string out = (test::temp_dir(tag) / "r.h5").string();
  RunOptions o;
  o.output = out;
  run_scene(test::scene_from(kScene), o);
  return out;
}

std::int64_t format_of(const H5::H5File& f) {
  std::int64_t format = 0;
  f.openAttribute("format_version").read(H5::PredType::NATIVE_INT64, &format);
  return format;
}

/// A 10 m square floe, 1 m thick, and a fixed wall at x = 0, a 0.5 m/s current towards the
/// wall, 60 s at dt 0.1 s; the wall's load recorded every 10 steps.
std::string wall_and_floe(const std::string& floe_polygon, const std::string& floe_velocity) {
  return "[run]\nduration = 60.0\ndt = 0.1\noutput_every = 600\n[output]\ncontacts = \"none\"\nloads = [\"wall\"]\n"
         "load_every = 10\n[environment]\ncurrent = [-0.5, 0.0]\n"
         "[[body]]\nname = \"wall\"\npolygon = [[-5,-20],[0,-20],[0,20],[-5,20]]\nthickness = 5.0\nfixed = true\n"
         "[[body]]\nname = \"floe\"\npolygon = " + floe_polygon + "\nthickness = 1.0\nvelocity = " + floe_velocity + "\n";
}

/// N: the water drag on that floe at rest, which the wall carries in equilibrium:
/// 1/2 rho_w C_w W d u^2 + rho_w C_dw A u^2 with draft d = h rho_i / rho_w (docs/model.md 2).
double wall_load() {
  const double draft = 1.0 * 900.0 / 1025.0;
  return 0.5 * 1025.0 * 0.9 * 10.0 * draft * 0.25 + 1025.0 * 5e-4 * 100.0 * 0.25;
}

}  // namespace

TEST_CASE("output layout: bodies, frames, contacts, attributes", "[output]") {
  const fs::path dir = test::temp_dir("layout");
  const std::string out = (dir / "r.h5").string();
  Scene s = test::scene_from(kScene, {"run.output_every=10"});
  RunOptions o;
  o.output = out;
  const RunSummary sum = run_scene(s, o);
  CHECK(fs::exists(out));
  CHECK_FALSE(fs::exists(out + ".partial"));
  CHECK(sum.collision_impulses > 0);

  H5::H5File f(out, H5F_ACC_RDONLY);
  CHECK(string_attribute(f.openGroup("/"), "status") == "complete");
  CHECK(string_attribute(f.openGroup("/"), "engine") == "native");
  CHECK(string_attribute(f.openGroup("/"), "scenario") == kScene);
  CHECK(string_attribute(f.openGroup("/"), "overrides") == "run.output_every=10");
  CHECK_FALSE(string_attribute(f.openGroup("/"), "floedem_version").empty());
  CHECK(format_of(f) == kOutputFormatVersion);
  double dt = 0;
  f.openAttribute("dt").read(H5::PredType::NATIVE_DOUBLE, &dt);
  CHECK(dt == 0.01);

  // 100 steps, every 10th, plus t = 0: 11 frames.
  CHECK(shape(f.openDataSet("/time")) == std::vector<hsize_t>{11});
  CHECK(shape(f.openDataSet("/bodies/position")) == std::vector<hsize_t>{11, 2, 2});
  CHECK(shape(f.openDataSet("/bodies/angle")) == std::vector<hsize_t>{11, 2});
  CHECK(shape(f.openDataSet("/bodies/velocity")) == std::vector<hsize_t>{11, 2, 2});
  CHECK(shape(f.openDataSet("/bodies/angular_velocity")) == std::vector<hsize_t>{11, 2});
  CHECK(shape(f.openDataSet("/bodies/name")) == std::vector<hsize_t>{2});
  CHECK(shape(f.openDataSet("/bodies/polygon_vertices")) == std::vector<hsize_t>{7, 2});
  std::vector<std::int64_t> offsets(3);
  f.openDataSet("/bodies/polygon_offsets").read(offsets.data(), H5::PredType::NATIVE_INT64);
  CHECK(offsets == std::vector<std::int64_t>{0, 4, 7});
  std::vector<double> mass(2);
  f.openDataSet("/bodies/mass").read(mass.data(), H5::PredType::NATIVE_DOUBLE);
  CHECK(mass[0] == Approx(90000.0));
  // Vertices are body-local: the centroid of each polygon is the origin.
  std::vector<double> v(14);
  f.openDataSet("/bodies/polygon_vertices").read(v.data(), H5::PredType::NATIVE_DOUBLE);
  CHECK(v[0] == Approx(-5.0));
  CHECK(v[1] == Approx(-5.0));

  std::vector<double> time(11);
  f.openDataSet("/time").read(time.data(), H5::PredType::NATIVE_DOUBLE);
  CHECK(time[0] == 0.0);
  CHECK(time[10] == Approx(1.0));
  const hsize_t rows = shape(f.openDataSet("/contacts/time"))[0];
  CHECK(rows == static_cast<hsize_t>(sum.contact_rows));
  for (const char* name : {"body_a", "body_b", "normal_impulse", "tangent_impulse", "kind", "approach_velocity", "separation"})
    CHECK(shape(f.openDataSet(std::string("/contacts/") + name)) == std::vector<hsize_t>{rows});
  CHECK(shape(f.openDataSet("/contacts/point")) == std::vector<hsize_t>{rows, 2});
  CHECK(shape(f.openDataSet("/contacts/normal")) == std::vector<hsize_t>{rows, 2});
  // Collision events: one row each, every column the same length, forces from the impulse.
  const hsize_t events = shape(f.openDataSet("/contacts/collisions/time"))[0];
  CHECK(events == static_cast<hsize_t>(sum.collision_events));
  CHECK(events >= 1);
  for (const char* name : {"body_a", "body_b", "normal_impulse", "effective_mass", "approach_speed",
                           "restitution_achieved", "duration", "mean_force", "peak_force"})
    CHECK(shape(f.openDataSet(std::string("/contacts/collisions/") + name)) == std::vector<hsize_t>{events});
  std::vector<double> impulse(events), duration(events), mean(events);
  f.openDataSet("/contacts/collisions/normal_impulse").read(impulse.data(), H5::PredType::NATIVE_DOUBLE);
  f.openDataSet("/contacts/collisions/duration").read(duration.data(), H5::PredType::NATIVE_DOUBLE);
  f.openDataSet("/contacts/collisions/mean_force").read(mean.data(), H5::PredType::NATIVE_DOUBLE);
  CHECK(mean[0] == Approx(impulse[0] / duration[0]).epsilon(1e-15));
  fs::remove_all(dir);
}

TEST_CASE("a run killed mid-way leaves a readable .partial and no final file", "[output]") {
  const fs::path dir = test::temp_dir("killed");
  const fs::path scenario = dir / "long.toml";
  std::ofstream(scenario) << test::header_toml(1e7, 0.01, 0.3, 0.3) +
                                 test::body_toml({"a", test::box({5, 5}, 10, 10), {1.0, 0.0}}) +
                                 test::body_toml({"w", test::box({20, 5}, 2, 20), {}, 0.0, true});
  const fs::path out = dir / "r.h5";
  const std::string cmd = std::string("timeout -s KILL 3 ") + FLOEDEM_EXE + " run " + scenario.string() +
                          " --quiet --set run.output_every=100 --out " + out.string() + " > /dev/null 2>&1";
  const int rc = std::system(cmd.c_str());
  CHECK(rc != 0);
  CHECK_FALSE(fs::exists(out));
  REQUIRE(fs::exists(out.string() + ".partial"));
  // A killed process can outlive `timeout` for a moment as a zombie that still holds the
  // file's lock: wait for it (up to 10 s) as a user would.
  H5::H5File f;
  for (int attempt = 0;; ++attempt) {
    try {
      f.openFile(out.string() + ".partial", H5F_ACC_RDONLY);
      break;
    } catch (const H5::Exception&) {
      REQUIRE(attempt < 100);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  CHECK(string_attribute(f.openGroup("/"), "status") == "running");
  const hsize_t frames = shape(f.openDataSet("/time"))[0];
  CHECK(frames > 10);  // written and flushed at each full chunk of frames over ~2 s
  std::vector<double> t(frames);
  f.openDataSet("/time").read(t.data(), H5::PredType::NATIVE_DOUBLE);
  CHECK(t[frames - 1] == Approx(1.0 * static_cast<double>(frames - 1)));  // every 100th step of 0.01 s
  CHECK(shape(f.openDataSet("/bodies/position"))[0] == frames);
  fs::remove_all(dir);
}

TEST_CASE("an unwritable output directory is an output error, and nothing is left", "[output]") {
  const Scene s = test::scene_from(kScene);
  RunOptions o;
  o.output = "/nonexistent-dir/r.h5";
  CHECK_THROWS_AS(run_scene(s, o), OutputError);
  CHECK_FALSE(fs::exists("/nonexistent-dir/r.h5.partial"));
}

TEST_CASE("/loads: a floe pressed on a wall by the current loads it with the floe's drag", "[output][loads]") {
  // The floe at rest against the wall: in equilibrium the wall carries its drag (wall_load).
  const Scene s = test::scene_from(wall_and_floe("[[0,-5],[10,-5],[10,5],[0,5]]", "[0.0, 0.0]"));
  const fs::path out = fs::temp_directory_path() / ("floedem-loads-" + std::to_string(::getpid()) + ".h5");
  RunOptions o;
  o.output = out.string();
  o.progress = false;
  run_scene(s, o);
  H5::H5File f(out.string(), H5F_ACC_RDONLY);
  H5::DataSet force = f.openDataSet("/loads/force");
  hsize_t dims[3];
  REQUIRE(force.getSpace().getSimpleExtentNdims() == 3);
  force.getSpace().getSimpleExtentDims(dims);
  CHECK(dims[0] == 60);  // every 10 steps of 600
  CHECK(dims[1] == 1);
  std::vector<double> v(dims[0] * 2);
  force.read(v.data(), H5::PredType::NATIVE_DOUBLE);
  const double drag = wall_load();
  CHECK(v[2 * (dims[0] - 1)] == Approx(-drag).epsilon(1e-6));  // the floe pushes the wall along -x
  CHECK(v[2 * (dims[0] - 1) + 1] == Approx(0.0).margin(1e-6 * drag));
  fs::remove(out);
}

TEST_CASE("run summary: the headline figures are the file's means over the second half", "[output][loads]") {
  // The floe of the test above, drifting 1 m onto the wall first: a collision, then the floe
  // pressed. The headline's load is the mean of the /loads rows that start at or after 30 s,
  // reduced here by hand from the file, and is the drag in equilibrium; its largest collision is
  // the largest row of /contacts/collisions.
  const Scene s = test::scene_from(wall_and_floe("[[1,-5],[11,-5],[11,5],[1,5]]", "[-0.5, 0.0]"));
  const fs::path out = fs::temp_directory_path() / ("floedem-headline-" + std::to_string(::getpid()) + ".h5");
  RunOptions o;
  o.output = out.string();
  const RunSummary sum = run_scene(s, o);
  const RunHeadline& h = sum.headline;
  CHECK(h.window_start == 30.0);
  CHECK(h.window_end == Approx(60.0));
  CHECK_FALSE(h.tow);
  REQUIRE(h.loads.size() == 1);
  CHECK(h.loads[0].body == "wall");

  H5::H5File f(out.string(), H5F_ACC_RDONLY);
  std::vector<double> time(60), force(120);
  f.openDataSet("/loads/time").read(time.data(), H5::PredType::NATIVE_DOUBLE);
  f.openDataSet("/loads/force").read(force.data(), H5::PredType::NATIVE_DOUBLE);
  double fx = 0.0, fy = 0.0;
  int rows = 0;
  for (std::size_t i = 1; i < time.size(); ++i)
    if (time[i - 1] >= 30.0 - 1e-9) fx += force[2 * i], fy += force[2 * i + 1], ++rows;
  CHECK(rows == 30);  // rows of equal span: the weighted mean is the plain one
  CHECK(h.loads[0].force.x == Approx(fx / rows).epsilon(1e-12));
  CHECK(h.loads[0].force.y == Approx(fy / rows).margin(1e-9));
  const double drag = wall_load();
  CHECK(h.loads[0].force.x == Approx(-drag).epsilon(1e-6));

  H5::DataSet peak = f.openDataSet("/contacts/collisions/peak_force");
  std::vector<double> peaks(static_cast<std::size_t>(peak.getSpace().getSimpleExtentNpoints()));
  REQUIRE_FALSE(peaks.empty());
  peak.read(peaks.data(), H5::PredType::NATIVE_DOUBLE);
  REQUIRE(h.largest_collision);
  CHECK(h.largest_collision->peak_force == *std::max_element(peaks.begin(), peaks.end()));
  CHECK(h.largest_collision->body_a == "wall");
  CHECK(h.largest_collision->body_b == "floe");
  CHECK(h.largest_collision->time < 5.0);  // 1 m at 0.5 m/s
  const std::string text_summary = format_summary(s, sum, out.string());
  CHECK(text_summary.find("load        wall, mean over t = 30 to 60 s") != std::string::npos);
  CHECK(text_summary.find("the largest of any collision: wall and floe") != std::string::npos);
  fs::remove(out);
}

TEST_CASE("a run's output of another format_version is refused, naming the file and both versions", "[output]") {
  const std::string out = run_small_scene("format");
  {
    H5::H5File f(out, H5F_ACC_RDWR);
    const std::int64_t newer = kOutputFormatVersion + 1;
    f.openAttribute("format_version").write(H5::PredType::NATIVE_INT64, &newer);
  }
  for (const bool as_field : {false, true}) {
    INFO((as_field ? "read_body_frame" : "read_stored_run"));
    try {
      if (as_field)
        read_body_frame(out);
      else
        read_stored_run(out);
      FAIL("a newer format was read");
    } catch (const InputError& e) {
      const std::string m = e.what();
      CHECK(m.find(out) == 0);
      CHECK(m.find("/@format_version: is " + std::to_string(kOutputFormatVersion + 1) + ", this floedem (" + version() +
                   ") reads " + std::to_string(kOutputFormatVersion)) != std::string::npos);
      CHECK(m.find("a newer floedem wrote it") != std::string::npos);
    }
  }
}

TEST_CASE("a frame records the velocities at the instant of its positions", "[output]") {
  // free_drift_analytic.toml (a floe in a current with Coriolis) for an hour, a frame every 10
  // steps: each frame's velocity is the Stepper's frame_state at that step, to the bit, which
  // differs from the engine's own half-step velocity by (dt / 2) a (test_environment.cpp holds
  // both against the closed form).
  const fs::path dir = test::temp_dir("frame_velocity");
  const std::string out = (dir / "r.h5").string();
  const Scene s = load_scenario(std::string(FLOEDEM_SOURCE_DIR) + "/scenarios/free_drift_analytic.toml",
                                {"run.duration=3600", "run.output_every=10"});
  RunOptions o;
  o.output = out;
  o.progress = false;
  run_scene(s, o);
  H5::H5File f(out, H5F_ACC_RDONLY);
  std::vector<double> v(2 * 7);
  f.openDataSet("/bodies/velocity").read(v.data(), H5::PredType::NATIVE_DOUBLE);
  Stepper run(s, "native");
  BodyStates frame;
  run.frame_state(frame);
  CHECK(v[0] == frame.velocity[0].x);  // t = 0: the scene's own
  for (int k = 1; k <= 60; ++k) {
    run.step();
    if (k % 10 != 0) continue;
    run.frame_state(frame);
    INFO("step " << k);
    CHECK(v[2 * static_cast<std::size_t>(k / 10)] == frame.velocity[0].x);
    CHECK(v[2 * static_cast<std::size_t>(k / 10) + 1] == frame.velocity[0].y);
    CHECK(frame.velocity[0].x != run.state().velocity[0].x);
  }
}

TEST_CASE("format 1 files, with variable-length strings, are read and continued in format 1", "[output][resume]") {
  // Files written by a floedem of format 1, kept in the repository (tests/io/format1): a field,
  // a complete run and a run with checkpoints. Each is read as before; the last is continued
  // by --resume to a longer duration and stays a format 1 file (its strings variable-length).
  const fs::path dir = test::temp_dir("format1");
  auto unpack = [&](const std::string& name) {
    const std::string out = (dir / name).string();
    const std::string command = "gunzip -c '" + std::string(FLOEDEM_SOURCE_DIR) + "/tests/io/format1/" + name +
                                ".gz' > '" + out + "'";
    REQUIRE(std::system(command.c_str()) == 0);
    return out;
  };
  const BodyFrame field = read_body_frame(unpack("field.h5"));
  CHECK(field.names.size() == field.polygons.size());
  CHECK_FALSE(field.names.front().empty());
  const StoredRun run = read_stored_run(unpack("run.h5"));
  CHECK(run.status == "complete");
  CHECK(run.engine == "native");
  CHECK(run.scenario.find("[run]") != std::string::npos);
  const std::string checkpointed = unpack("checkpoint.h5");
  const StoredRun before = read_stored_run(checkpointed);
  const ResumeResult r = resume_run(checkpointed, {"run.duration=" + std::to_string(before.duration + 10.0)}, false);
  CHECK(r.ran);
  H5::H5File f(checkpointed, H5F_ACC_RDONLY);
  CHECK(format_of(f) == 1);
  CHECK(f.openAttribute("status").getStrType().isVariableStr());
  CHECK(f.openDataSet("/bodies/name").getStrType().isVariableStr());
  const StoredRun after = read_stored_run(checkpointed);
  CHECK(after.status == "complete");
  CHECK(after.duration == Approx(before.duration + 10.0));
}

TEST_CASE("format 2 stores every string fixed-length", "[output]") {
  const std::string out = run_small_scene("format2");
  H5::H5File f(out, H5F_ACC_RDONLY);
  CHECK(format_of(f) == 2);
  auto fixed = [](const H5::StrType& t) { return !t.isVariableStr(); };
  H5::Group root = f.openGroup("/");
  for (int k = 0; k < root.getNumAttrs(); ++k) {
    const H5::Attribute a = root.openAttribute(static_cast<unsigned>(k));
    INFO(a.getName());
    if (a.getTypeClass() == H5T_STRING) CHECK(fixed(a.getStrType()));
  }
  H5::Group engine = f.openGroup("/engine");
  for (int k = 0; k < engine.getNumAttrs(); ++k) {
    const H5::Attribute a = engine.openAttribute(static_cast<unsigned>(k));
    INFO(a.getName());
    if (a.getTypeClass() == H5T_STRING) CHECK(fixed(a.getStrType()));
  }
  CHECK(fixed(f.openDataSet("/bodies/name").getStrType()));
  CHECK(string_attribute(root, "status") == "complete");
  CHECK(read_stored_run(out).status == "complete");
  CHECK(read_body_frame(out).names == std::vector<std::string>{"a", "b"});
}
