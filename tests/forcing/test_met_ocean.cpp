// Forcing that changes in time (docs/forcing.md): tidal current ellipses and wind or current
// series, against the closed form of a floe under linearised skin drag and Coriolis,
//   dw/dt = a (W(t) - w) - i f w,  w = v_x + i v_y,
// whose solution for W(t) a sum of exponentials C_j e^{lambda_j t} from rest is
//   w(t) = sum_j a C_j (e^{lambda_j t} - e^{-s t}) / (s + lambda_j),   s = a + i f,
// and for W(t) linear on each segment is taken segment by segment, exactly.
#include <catch2/catch.hpp>

#include <complex>
#include <fstream>
#include <sstream>

#include "run/stepper.hpp"
#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/input_error.hpp"
#include "support.hpp"

using namespace floedem;
using cplx = std::complex<double>;

namespace {

constexpr double kOmega = 7.2921e-5;

// The floe of scenarios/free_drift_analytic.toml (10 m square, 1 m thick, linearised skin drag
// with U_ref = 0.1 m/s, 75 N) with `extra` added to its [environment] and the scene's other
// tables after it.
std::string drift_scene(double dt, const std::string& environment, const std::string& tables = "") {
  std::ostringstream o;
  o.precision(17);
  o << "[run]\nduration = 86400.0\ndt = " << dt << "\n[environment]\nlatitude = 75.0\nsea_surface_tilt = false\n"
    << "drag_reference_speed = 0.1\n" << environment
    << "\n[environment.drag]\nwater_form = 0.0\nwater_skin = 0.005\nair_form = 0.0\nair_skin = 0.0\n" << tables
    << "\n[[body]]\nname = \"floe\"\npolygon = [[-5.0, -5.0], [5.0, -5.0], [5.0, 5.0], [-5.0, 5.0]]\n"
    << "thickness = 1.0\ndensity = 900.0\n";
  return o.str();
}

double drag_rate(const Scene& s) { return 1025.0 * 0.005 * s.bodies[0].area * 0.1 / s.bodies[0].mass; }
cplx sigma(const Scene& s) { return {drag_rate(s), 2.0 * kOmega * std::sin(75.0 * M_PI / 180.0)}; }

/// The largest position error (m) of the run against z(t), every step.
template <class Exact>
double worst_position_error(const Scene& s, Exact exact) {
  Stepper run(s, "native");
  double worst = 0.0;
  for (std::int64_t k = 0; k < s.run.steps(); ++k) {
    run.step();
    const Vec2 p = run.state().position[0] - s.bodies[0].centroid;
    worst = std::max(worst, std::abs(cplx(p.x, p.y) - exact(run.time())));
  }
  return worst;
}

struct Tide {
  double period, major, minor, inclination_deg, phase_deg;
};

std::string tide_toml(const std::vector<Tide>& tides) {
  std::ostringstream o;
  o.precision(17);
  for (const Tide& t : tides)
    o << "[[environment.tide]]\nperiod = " << t.period << "\nmajor = " << t.major << "\nminor = " << t.minor
      << "\ninclination = " << t.inclination_deg << "\nphase = " << t.phase_deg << "\n";
  return o.str();
}

}  // namespace

TEST_CASE("a floe in a tidal current follows the closed form, second order in dt", "[environment][met_ocean]") {
  // M2 and K1 ellipses (opposite senses of rotation) on a mean current. An ellipse is
  // e^{i theta} (A cos psi + i B sin psi) = e^{i theta} ((A + B) / 2 e^{i psi} + (A - B) / 2 e^{-i psi}),
  // psi = omega t - phase: two exponentials each.
  const cplx mean(0.2, 0.05);
  const std::vector<Tide> tides = {{44714.16, 0.25, -0.08, 35.0, 40.0}, {86164.09, 0.1, 0.04, -20.0, 100.0}};
  auto errors = [&](double dt) {
    const Scene s = test::scene_from(drift_scene(dt, "current = [0.2, 0.05]\n", tide_toml(tides)));
    REQUIRE(s.environment.current_varies());
    const double a = drag_rate(s);
    const cplx sg = sigma(s);
    std::vector<std::pair<cplx, cplx>> terms = {{mean, 0.0}};  // (C_j, lambda_j)
    for (const Tide& t : tides) {
      const double omega = 2.0 * M_PI / t.period, phase = t.phase_deg * M_PI / 180.0;
      const cplx turn = std::polar(1.0, t.inclination_deg * M_PI / 180.0);
      terms.push_back({turn * 0.5 * (t.major + t.minor) * std::polar(1.0, -phase), cplx(0.0, omega)});
      terms.push_back({turn * 0.5 * (t.major - t.minor) * std::polar(1.0, phase), cplx(0.0, -omega)});
    }
    return worst_position_error(s, [&](double time) {
      cplx z = 0.0;
      for (const auto& [c, lambda] : terms) {
        const cplx integral = lambda == 0.0 ? cplx(time) : (std::exp(lambda * time) - 1.0) / lambda;
        z += a * c / (sg + lambda) * (integral - (1.0 - std::exp(-sg * time)) / sg);
      }
      return z;
    });
  };
  const double coarse = errors(60.0), fine = errors(15.0);
  INFO("largest position error over 24 h: " << coarse << " m at dt 60 s, " << fine << " m at dt 15 s");
  // The flow is taken at the step's start t_n, where the leapfrog takes its force: second order.
  CHECK(coarse / fine == Approx(16.0).epsilon(0.1));
  CHECK(fine < 0.02);
}

TEST_CASE("a floe under a current series follows the closed form, second order in dt", "[environment][met_ocean]") {
  // A current record every 3 h (a tidal-looking swing on a drift), linear between samples.
  const std::filesystem::path dir = test::temp_dir("current-series");
  std::vector<double> times;
  std::vector<cplx> values;
  {
    std::ofstream out(dir / "current.csv");
    out.precision(17);
    out << "# a made-up record\ntime,u,v\n";
    for (int k = 0; k <= 8; ++k) {
      const double t = 10800.0 * k;
      const cplx w(0.15 + 0.2 * std::cos(0.7 * k), 0.05 - 0.1 * std::sin(1.3 * k));
      out << t << ',' << w.real() << ',' << w.imag() << '\n';
      times.push_back(t);
      values.push_back(w);
    }
  }
  auto errors = [&](double dt) {
    const Scene s = test::scene_from(
        drift_scene(dt, "", "[environment.current_file]\nfile = \"" + (dir / "current.csv").string() + "\"\n"));
    REQUIRE(s.environment.current_series.time.size() == times.size());
    const double a = drag_rate(s);
    const cplx sg = sigma(s);
    // On a segment from t_k with W = W_k + b tau: w = c0 + c1 tau + (w_k - c0) e^{-s tau},
    // c1 = a b / s, c0 = (a W_k - c1) / s; z adds c0 tau + c1 tau^2 / 2 + (w_k - c0)(1 - e^{-s tau}) / s.
    return worst_position_error(s, [&](double time) {
      cplx w = 0.0, z = 0.0;
      for (std::size_t k = 0; k + 1 < times.size(); ++k) {
        const double tau = std::min(time, times[k + 1]) - times[k];
        if (tau <= 0.0) break;
        const cplx b = (values[k + 1] - values[k]) / (times[k + 1] - times[k]);
        const cplx c1 = a * b / sg, c0 = (a * values[k] - c1) / sg;
        const cplx decay = std::exp(-sg * tau);
        z += c0 * tau + 0.5 * c1 * tau * tau + (w - c0) * (1.0 - decay) / sg;
        w = c0 + c1 * tau + (w - c0) * decay;
      }
      return z;
    });
  };
  const double coarse = errors(60.0), fine = errors(15.0);
  INFO("largest position error over 24 h: " << coarse << " m at dt 60 s, " << fine << " m at dt 15 s");
  CHECK(coarse / fine == Approx(16.0).epsilon(0.1));
  CHECK(fine < 0.02);
}

TEST_CASE("a steady series gives the steady run to the bit, drag, tilt and contacts included",
          "[environment][met_ocean]") {
  // Three floes in a current and a wind, with the quadratic drags of every term, the tilt and a
  // collision (the floes close on each other): once given as constants, once as two-sample
  // records of the same values. The flows are set at every step through another path (the
  // drag terms' set_time, the pass's refresh, the tilt's change), which must change nothing.
  const std::filesystem::path dir = test::temp_dir("steady-series");
  {
    std::ofstream(dir / "current.csv") << "time,u,v\n0,0.3,-0.1\n7200,0.3,-0.1\n";
    std::ofstream(dir / "wind.csv") << "time,east,north\n-10,8.0,3.0\n7200,8.0,3.0\n";
  }
  auto floes = [] {
    std::string b;
    const Vec2 at[] = {{0, 0}, {30, 2}, {60, -3}};
    const Vec2 v[] = {{0.5, 0.0}, {-0.2, 0.0}, {0.0, 0.1}};
    for (int k = 0; k < 3; ++k)
      b += "[[body]]\nname = \"f" + std::to_string(k) + "\"\npolygon = " + test::toml_polygon(test::box(at[k], 20, 16, 0.2)) +
           "\nthickness = 1.5\nvelocity = " + test::vec_toml(v[k]) + "\n";
    return b;
  };
  const std::string head = "[run]\nduration = 3600.0\ndt = 0.5\n[environment]\nlatitude = 75.0\n";
  const Scene steady = test::scene_from(head + "current = [0.3, -0.1]\nwind = [8.0, 3.0]\n" + floes());
  const Scene series = test::scene_from(head + "[environment.current_file]\nfile = \"" + (dir / "current.csv").string() +
                                        "\"\n[environment.wind_file]\nfile = \"" + (dir / "wind.csv").string() +
                                        "\"\nu = \"east\"\nv = \"north\"\n" + floes());
  REQUIRE(series.environment.current_varies());
  REQUIRE(series.environment.wind_varies());
  REQUIRE(series.environment.sea_surface_tilt);
  Stepper a(steady, "native"), b(series, "native");
  bool touched = false;
  for (std::int64_t k = 0; k < steady.run.steps(); ++k) {
    a.step();
    b.step();
    touched = touched || !a.engine().contacts().empty();
  }
  CHECK(touched);
  // The same to the bit: the drags' flows are the same numbers (0 + V = V, and a steady record
  // interpolates to its value), the tilt averages 0 + V over the draft as the steady path
  // averages V. A rounding apart would grow through the contacts to 1e-12 within the hour.
  double worst = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    worst = std::max(worst, length(a.state().position[i] - b.state().position[i]) / length(a.state().position[i]));
    worst = std::max(worst, std::abs(a.state().angle[i] - b.state().angle[i]));
    worst = std::max(worst, length(a.state().velocity[i] - b.state().velocity[i]) / length(a.state().velocity[i]));
  }
  INFO("largest relative difference after 1 h: " << worst);
  CHECK(worst == 0.0);
}

TEST_CASE("tidal constituents: the standard periods and the ellipse", "[environment][met_ocean]") {
  CHECK(tidal_period("M2") == Approx(44714.16).epsilon(1e-7));
  CHECK(tidal_period("K1") == Approx(86164.09).epsilon(1e-7));
  CHECK(tidal_period("S2") == 43200.0);
  CHECK(tidal_period("X9") == 0.0);
  // At psi = 0 the current lies along the major axis, a quarter period on along the minor.
  TidalConstituent c{"", 1000.0, 0.4, -0.1, M_PI / 6.0, 0.0};
  CHECK(c.velocity(0.0).x == Approx(0.4 * std::cos(M_PI / 6.0)));
  CHECK(c.velocity(0.0).y == Approx(0.4 * std::sin(M_PI / 6.0)));
  CHECK(c.velocity(250.0).x == Approx(0.1 * std::sin(M_PI / 6.0)));
  CHECK(c.velocity(250.0).y == Approx(-0.1 * std::cos(M_PI / 6.0)));
  // The rate against a centred difference.
  const double h = 1e-3;
  const Vec2 d = (1.0 / (2 * h)) * (c.velocity(123.0 + h) - c.velocity(123.0 - h));
  CHECK(c.acceleration(123.0).x == Approx(d.x).epsilon(1e-6));
  CHECK(c.acceleration(123.0).y == Approx(d.y).epsilon(1e-6));
}

TEST_CASE("bad met-ocean input is refused with the file, the field and what is allowed", "[input][met_ocean]") {
  const std::filesystem::path dir = test::temp_dir("met-ocean-bad");
  auto csv = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string body = "[[body]]\nname = \"a\"\npolygon = [[0,0],[1,0],[1,1],[0,1]]\nthickness = 1.0\n";
  const std::string run = "[run]\nduration = 100.0\ndt = 1.0\n";
  auto with_current_file = [&](const std::string& path, const std::string& more = "") {
    return run + "[environment]\n" + more + "[environment.current_file]\nfile = \"" + path + "\"\n" + body;
  };
  struct Bad {
    const char* what;
    std::string text;
    std::vector<std::string> expect;
  };
  const std::vector<Bad> cases = {
      {"missing file", with_current_file((dir / "none.csv").string()), {"'environment.current_file.file'", "cannot open"}},
      {"not csv", with_current_file("ocean.txt"), {"'environment.current_file.file'", "allowed", ".csv"}},
      {"missing column", with_current_file(csv("a.csv", "time,u,w\n0,1,1\n100,1,1\n")), {"a.csv:1", "'v'", "no such column"}},
      {"not a number", with_current_file(csv("b.csv", "time,u,v\n0,1,1\n50,x,1\n100,1,1\n")),
       {"b.csv:3", "'u'", "not a number"}},
      {"time not increasing", with_current_file(csv("c.csv", "time,u,v\n0,1,1\n0,1,1\n100,1,1\n")),
       {"c.csv:3", "'time'", "increase"}},
      {"not covering the run", with_current_file(csv("d.csv", "time,u,v\n0,1,1\n60,1,1\n")),
       {"d.csv", "'time'", "covers [0, 60]", ">= 100"}},
      {"not a speed", with_current_file(csv("e.csv", "time,u,v\n0,1,1e4\n100,1,1\n")), {"e.csv:2", "'v'", "[-100, 100]"}},
      {"current and current_file", with_current_file(csv("f.csv", "time,u,v\n0,1,1\n100,1,1\n"), "current = [1.0, 0.0]\n"),
       {"'environment.current_file'", "one of them"}},
      {"tide without period", run + "[[environment.tide]]\nmajor = 0.2\n" + body, {"'environment.tide[0].period'", "M2"}},
      {"tide with both", run + "[[environment.tide]]\nperiod = 1000.0\nconstituent = \"M2\"\nmajor = 0.2\n" + body,
       {"'environment.tide[0].period'", "one of them"}},
      {"unknown constituent", run + "[[environment.tide]]\nconstituent = \"M3\"\nmajor = 0.2\n" + body,
       {"'environment.tide[0].constituent'", "M2"}},
      {"minor beyond major", run + "[[environment.tide]]\nconstituent = \"M2\"\nmajor = 0.2\nminor = 0.3\n" + body,
       {"'environment.tide[0].minor'", "[-0.2, 0.2]"}},
      {"start not UTC", "[run]\nduration = 1.0\ndt = 0.1\nstart = \"2024-03-01T00:00:00+01:00\"\n" + body,
       {"'run.start'", "UTC"}},
      {"start no date", "[run]\nduration = 1.0\ndt = 0.1\nstart = \"2024-02-30T00:00:00Z\"\n" + body,
       {"'run.start'", "not a valid date"}},
  };
  for (const Bad& c : cases) {
    std::string message;
    try {
      test::scene_from(c.text);
    } catch (const InputError& e) {
      message = e.what();
    }
    INFO(c.what << ": " << message);
    CHECK(message.find('\n') == std::string::npos);
    for (const std::string& s : c.expect) CHECK(message.find(s) != std::string::npos);
  }
}

TEST_CASE("run.start is read as UTC seconds since 1970", "[input][met_ocean]") {
  const std::string body = "[[body]]\nname = \"a\"\npolygon = [[0,0],[1,0],[1,1],[0,1]]\nthickness = 1.0\n";
  const Scene s = test::scene_from("[run]\nduration = 1.0\ndt = 0.1\nstart = \"2024-03-01T06:30:00Z\"\n" + body);
  CHECK(s.run.start_unix == 1709274600.0);  // date -u -d 2024-03-01T06:30:00Z +%s
  CHECK(s.run.start == "2024-03-01T06:30:00Z");
}
