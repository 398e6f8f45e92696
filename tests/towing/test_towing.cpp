// Towing against closed forms.
#include <catch2/catch.hpp>

#include <H5Cpp.h>

#include <filesystem>

#include "floedem/run/simulation.hpp"
#include "run/stepper.hpp"
#include "support.hpp"
#include "towing/tow.hpp"

using namespace floedem;
namespace fs = std::filesystem;

namespace {

// A tabular iceberg 200 m x 100 m at the waterline, 80 m draft, 20 m sail, mass given.
const std::string kBerg =
    "[[body]]\nname = \"berg\"\nkind = \"iceberg\"\npolygon = [[-100,-50],[100,-50],[100,50],[-100,50]]\n"
    "draft = 80.0\nsail_height = 20.0\nmass = 1.5e9\n";

/// Calm-water drag on the iceberg moving at speed v along x (N, opposing the motion).
double drag_at(double v) {
  const double w = 100.0, area = 200.0 * 100.0;
  return 0.5 * 1025.0 * 0.9 * w * 80.0 * v * v + 1025.0 * 5e-4 * area * v * v + 0.5 * 1.25 * 1.3 * w * 20.0 * v * v +
         1.25 * 2.5e-4 * area * v * v;
}

}  // namespace

TEST_CASE("towing at constant speed in calm open water: the towing force is the drag", "[tow]") {
  const std::string text = "[run]\nduration = 100.0\ndt = 0.5\n[environment]\n" + kBerg +
                           "[tow]\nmode = \"velocity\"\nbody = \"berg\"\nvelocity = [0.7, 0.0]\n";
  const Scene s = test::scene_from(text);
  Stepper run(s, "native");
  for (int n = 0; n < 200; ++n) {
    run.step();
    const TowMonitor& tow = run.tow();
    // 1e-6 relative: the required bound; both sides are the same closed form up to round-off.
    CHECK(tow.force().x == Approx(drag_at(0.7)).epsilon(1e-6));
    CHECK(std::abs(tow.force().y) < 1e-9 * drag_at(0.7));
  }
  CHECK(run.state().position[0].x == Approx(0.7 * 100.0).epsilon(1e-12));
  CHECK(run.state().velocity[0].x == 0.7);
}

TEST_CASE("towing with Coriolis: the constraint also holds the Coriolis force", "[tow]") {
  const std::string text = "[run]\nduration = 10.0\ndt = 0.5\n[environment]\nlatitude = 75.0\n" + kBerg +
                           "[tow]\nmode = \"velocity\"\nbody = \"berg\"\nvelocity = [0.7, 0.0]\n";
  const Scene s = test::scene_from(text);
  Stepper run(s, "native");
  run.step();
  const TowMonitor& tow = run.tow();
  // -m f k x v = (0, -m f v) for v along x: the tow must supply +m f v across the path.
  const double f = 2.0 * 7.2921e-5 * std::sin(75.0 * M_PI / 180.0);
  CHECK(tow.force().y == Approx(1.5e9 * f * 0.7).epsilon(1e-12));
  CHECK(tow.force().x == Approx(drag_at(0.7)).epsilon(1e-9));
}

TEST_CASE("towing on a piecewise-linear path: the body follows it and pays for its acceleration", "[tow]") {
  const std::string text = "[run]\nduration = 200.0\ndt = 0.5\n[environment]\n" + kBerg +
                           "[tow]\nmode = \"velocity\"\nbody = \"berg\"\npath = [[0, 0.0, 0.0], [100, 0.5, 0.0]]\n";
  const Scene s = test::scene_from(text);
  Stepper run(s, "native");
  for (int n = 0; n < 400; ++n) {
    run.step();
    if (n == 99) {
      // Mid-way up the ramp, the step from 49.5 s to 50 s: m_I a + drag at the mid-step speed,
      // the velocity the body is moved with over the step.
      const double v = 0.005 * 49.75;
      CHECK(run.tow().force().x == Approx(1.5e9 * 1.5 * 0.005 + drag_at(v)).epsilon(1e-9));
    }
  }
  // Displacement: 1/2 0.5 m/s 100 s + 0.5 m/s 100 s = 75 m, exact for the piecewise-linear path.
  CHECK(run.state().position[0].x == Approx(75.0).epsilon(1e-12));
}

TEST_CASE("a towed iceberg's pushes pass the contacts' energy check, whichever end of a contact it is", "[tow]") {
  // An island's solve is redone from zero when its contacts would add kinetic energy, less the
  // work of the bodies on a prescribed path on their floes (contacts_gain_energy): the towed
  // iceberg's push is real work. The iceberg is body_a of its contacts when it is listed
  // first, body_b when last; that work must count the same both ways, and no push restart the
  // solve. Floes of 20 m in a row ahead of the iceberg, towed into them at 0.7 m/s.
  auto run = [](bool berg_first) {
    std::string floes;
    for (int i = 0; i < 5; ++i)
      floes += test::body_toml({"floe-" + std::to_string(i), test::box({115.0 + 21.0 * i, 0.0}, 20, 20)});
    const std::string text = "[run]\nduration = 40.0\ndt = 0.1\n[environment]\n" +
                             (berg_first ? kBerg + floes : floes + kBerg) +
                             "[tow]\nmode = \"velocity\"\nbody = \"berg\"\nvelocity = [0.7, 0.0]\n";
    const Scene s = test::scene_from(text);
    Stepper stepper(s, "native");
    double pushed = 0.0;  // N s along x, on the floes, over the run
    for (int n = 0; n < 400; ++n) {
      stepper.step();
      for (const ContactRecord& c : stepper.contacts()) {
        const bool a_berg = s.bodies[static_cast<std::size_t>(c.body_a)].name == "berg";
        const bool b_berg = s.bodies[static_cast<std::size_t>(c.body_b)].name == "berg";
        if (a_berg) pushed += c.impulse().x;   // the impulse on body_b, the floe
        if (b_berg) pushed -= c.impulse().x;
      }
    }
    struct Pushed {
      double impulse;
      long restarts;
    } r{pushed, std::stol(stepper.engine().info().settings.at("cold_restarts"))};
    return r;
  };
  const auto first = run(true), last = run(false);
  INFO("impulse on the floes: berg first " << first.impulse << " N s, last " << last.impulse << " N s");
  REQUIRE(first.impulse > 1e5);  // the iceberg reached the floes and pushed them
  CHECK(first.restarts == 0);
  CHECK(last.restarts == 0);
  // The same pushes, up to the order the solve meets the contacts in.
  CHECK(last.impulse == Approx(first.impulse).epsilon(1e-3));
}

TEST_CASE("rope towing in steady state: the rope carries the drag", "[tow]") {
  // Tug at 0.5 m/s, rope 300 m, k = 1e5 N/m, damping about critical for m_I = 2.25e9 kg.
  const std::string text = "[run]\nduration = 30000.0\ndt = 1.0\noutput_every = 100\n[environment]\n" + kBerg +
                           "[tow]\nmode = \"rope\"\nbody = \"berg\"\ntug_velocity = [0.5, 0.0]\nstiffness = 1e5\n"
                           "length = 300.0\ndamping = 3e7\nattachment = [100.0, 0.0]\n";
  const Scene s = test::scene_from(text);
  CHECK(s.tow.tug_start.x == Approx(400.0));  // attachment + rope length along the tug's heading
  Stepper run(s, "native");
  for (int n = 0; n < 30000; ++n) run.step();
  const TowMonitor& tow = run.tow();
  // 1e-4 relative: the required bound. 30 000 s is ~20 drag time scales m_I / (K v).
  CHECK(tow.force().x == Approx(drag_at(0.5)).epsilon(1e-4));
  CHECK(run.state().velocity[0].x == Approx(0.5).epsilon(1e-4));
  CHECK(std::abs(run.state().angle[0]) < 1e-9);  // pulled from ahead of its centroid: stays on course
}

TEST_CASE("a slack rope carries nothing", "[tow]") {
  const std::string text = "[run]\nduration = 10.0\ndt = 1.0\n[environment]\n" + kBerg +
                           "[tow]\nmode = \"rope\"\nbody = \"berg\"\ntug_velocity = [-0.5, 0.0]\nstiffness = 1e5\n"
                           "length = 300.0\nattachment = [100.0, 0.0]\ntug_start = [300.0, 0.0]\n";
  const Scene s = test::scene_from(text);
  BodyStates st;
  st.resize(1);
  const RopeState r = rope_state(s.tow, TowLine(s.tow), nullptr, st, 0.0);
  CHECK(r.length == Approx(200.0));
  CHECK(r.tension == 0.0);
}

TEST_CASE("tow output: /tow/force and /tow/tug_position per frame", "[tow][output]") {
  const std::string text = "[run]\nduration = 10.0\ndt = 0.5\noutput_every = 2\n[environment]\n" + kBerg +
                           "[tow]\nmode = \"velocity\"\nbody = \"berg\"\nvelocity = [0.7, 0.0]\n";
  const Scene s = test::scene_from(text);
  const fs::path out = fs::temp_directory_path() / ("floedem-tow-" + std::to_string(::getpid()) + ".h5");
  RunOptions o;
  o.output = out.string();
  run_scene(s, o);
  H5::H5File f(out.string(), H5F_ACC_RDONLY);
  H5::DataSet force = f.openDataSet("/tow/force");
  hsize_t dims[2];
  force.getSpace().getSimpleExtentDims(dims);
  CHECK(dims[0] == 11);  // t = 0 and 10 frames
  CHECK(dims[1] == 2);
  std::vector<double> v(22), tug(22);
  force.read(v.data(), H5::PredType::NATIVE_DOUBLE);
  f.openDataSet("/tow/tug_position").read(tug.data(), H5::PredType::NATIVE_DOUBLE);
  CHECK(std::isnan(v[0]));  // no step before t = 0
  CHECK(v[2] == Approx(drag_at(0.7)).epsilon(1e-6));
  CHECK(tug[20] == Approx(7.0).epsilon(1e-12));  // the path's position at t = 10 s
  fs::remove(out);
}

namespace {
std::vector<double> read_all(const H5::H5File& f, const std::string& name) {
  H5::DataSet d = f.openDataSet(name);
  const hssize_t n = d.getSpace().getSimpleExtentNpoints();
  std::vector<double> v(static_cast<std::size_t>(n));
  d.read(v.data(), H5::PredType::NATIVE_DOUBLE);
  return v;
}
}  // namespace

TEST_CASE("tow output: tow_every rows of /tow, and the ice part is the impulse the floes took", "[tow][output]") {
  // No environment: the towing force is all ice (and inertia, none at constant speed). The berg
  // at 1 m/s meets a 20 m floe at rest; the towing impulse, the sum of the ice part over the
  // rows, must equal the momentum the floe carries away (nothing else acts on it).
  const std::string text =
      "[run]\nduration = 20.0\ndt = 0.05\noutput_every = 100\n[output]\ntow_every = 3\n[contact]\nrestitution = 0.5\n"
      "friction = 0.0\n" + kBerg +
      "[[body]]\nname = \"floe\"\npolygon = [[105,-10],[125,-10],[125,10],[105,10]]\nthickness = 1.0\n"
      "[tow]\nmode = \"velocity\"\nbody = \"berg\"\nvelocity = [1.0, 0.0]\n";
  const Scene s = test::scene_from(text);
  const fs::path out = fs::temp_directory_path() / ("floedem-tow-every-" + std::to_string(::getpid()) + ".h5");
  RunOptions o;
  o.output = out.string();
  run_scene(s, o);
  H5::H5File f(out.string(), H5F_ACC_RDONLY);
  const std::vector<double> t = read_all(f, "/tow/time");
  const std::vector<double> force = read_all(f, "/tow/force_mean");
  const std::vector<double> ice = read_all(f, "/tow/ice_force_mean");
  const std::vector<double> frames = read_all(f, "/time");
  REQUIRE(t.size() == 1 + 400 / 3 + 1);  // t = 0, every 3rd of 400 steps, and the last
  CHECK(frames.size() == 5);              // t = 0 and every 100th step
  CHECK(t[1] == Approx(0.15).epsilon(1e-12));
  CHECK(t.back() == Approx(20.0).epsilon(1e-12));
  double impulse = 0.0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    CHECK(force[2 * k] == Approx(ice[2 * k]).margin(1e-9 * std::abs(ice[2 * k]) + 1e-6));  // no drag, no inertia
    impulse += ice[2 * k] * (t[k] - t[k - 1]);
  }
  const std::vector<double> velocity = read_all(f, "/bodies/velocity");  // [T, bodies, 2]
  const double floe_mass = 900.0 * 400.0 * 1.0;
  const double floe_vx = velocity[velocity.size() - 2];
  CHECK(floe_vx == Approx(1.5).epsilon(1e-6));  // (1 + e) u against an infinite mass
  CHECK(impulse == Approx(floe_mass * floe_vx).epsilon(1e-9));
  fs::remove(out);
}
