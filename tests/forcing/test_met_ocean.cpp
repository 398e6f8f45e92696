// Forcing that changes in time (docs/forcing.md): tidal current ellipses and wind or current
// series, against the closed form of a floe under linearised skin drag and Coriolis,
//   dw/dt = a (W(t) - w) - i f w,  w = v_x + i v_y,
// whose solution for W(t) a sum of exponentials C_j e^{lambda_j t} from rest is
//   w(t) = sum_j a C_j (e^{lambda_j t} - e^{-s t}) / (s + lambda_j),   s = a + i f,
// and for W(t) linear on each segment is taken segment by segment, exactly.
#include <catch2/catch.hpp>

#include <netcdf.h>

#include <algorithm>
#include <complex>
#include <fstream>
#include <functional>
#include <sstream>

#include "floedem/scene/geo.hpp"
#include "forcing/flow_grid.hpp"
#include "forcing/forcing.hpp"
#include "run/stepper.hpp"
#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/run/simulation.hpp"
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

/// Three floes that close on each other (a collision within the first minutes).
std::string three_floes() {
  std::string b;
  const Vec2 at[] = {{0, 0}, {30, 2}, {60, -3}};
  const Vec2 v[] = {{0.5, 0.0}, {-0.2, 0.0}, {0.0, 0.1}};
  for (int k = 0; k < 3; ++k)
    b += "[[body]]\nname = \"f" + std::to_string(k) + "\"\npolygon = " + test::toml_polygon(test::box(at[k], 20, 16, 0.2)) +
         "\nthickness = 1.5\nvelocity = " + test::vec_toml(v[k]) + "\n";
  return b;
}

struct Bad {
  const char* what;
  std::string text;
  std::vector<std::string> expect;  // substrings of the message
};

/// Each case refused with one line that holds every expected part.
void check_refusals(const std::vector<Bad>& cases) {
  for (const Bad& c : cases) {
    std::string message;
    try {
      test::scene_from(c.text);
    } catch (const InputError& e) {
      message = e.what();
    }
    INFO(c.what << ": " << message);
    CHECK(!message.empty());
    CHECK(message.find('\n') == std::string::npos);
    for (const std::string& s : c.expect) CHECK(message.find(s) != std::string::npos);
  }
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
  const std::string head = "[run]\nduration = 3600.0\ndt = 0.5\n[environment]\nlatitude = 75.0\n";
  const Scene steady = test::scene_from(head + "current = [0.3, -0.1]\nwind = [8.0, 3.0]\n" + three_floes());
  const Scene series = test::scene_from(head + "[environment.current_file]\nfile = \"" + (dir / "current.csv").string() +
                                        "\"\n[environment.wind_file]\nfile = \"" + (dir / "wind.csv").string() +
                                        "\"\nu = \"east\"\nv = \"north\"\n" + three_floes());
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
  check_refusals(cases);
}

TEST_CASE("run.start is read as UTC seconds since 1970", "[input][met_ocean]") {
  const std::string body = "[[body]]\nname = \"a\"\npolygon = [[0,0],[1,0],[1,1],[0,1]]\nthickness = 1.0\n";
  const Scene s = test::scene_from("[run]\nduration = 1.0\ndt = 0.1\nstart = \"2024-03-01T06:30:00Z\"\n" + body);
  CHECK(s.run.start_unix == 1709274600.0);  // date -u -d 2024-03-01T06:30:00Z +%s
  CHECK(s.run.start == "2024-03-01T06:30:00Z");
}

// ---- Gridded fields (CF-NetCDF) --------------------------------------------------------------

namespace {

struct GridFile {
  std::vector<double> x, y, time;  // m, m, hours since 2024-03-01
  std::vector<double> depth;       // m; empty: (time, y, x)
  std::function<Vec2(double t, double x, double y, double depth)> field;
  std::string velocity_units = "m s-1", x_units = "m", time_units = "hours since 2024-03-01 00:00:00";
  std::string y_units;  // empty: x_units
  bool fill_somewhere = false;  // the first cell of every slice holds the fill value
  bool x_over_time = false;     // the variable x lies over the time dimension (not CF)
};

void write_grid(const std::filesystem::path& path, const GridFile& g) {
  int nc = -1;
  REQUIRE(nc_create(path.c_str(), NC_CLOBBER | NC_NETCDF4, &nc) == NC_NOERR);
  auto dim = [&](const char* name, const std::vector<double>& values, const std::string& units, int over = -1) {
    int d = -1, v = -1;
    nc_def_dim(nc, name, values.size(), &d);
    nc_def_var(nc, name, NC_DOUBLE, 1, over < 0 ? &d : &over, &v);
    nc_put_att_text(nc, v, "units", units.size(), units.c_str());
    return std::pair{d, v};
  };
  const auto t = dim("time", g.time, g.time_units);
  const bool z = !g.depth.empty();
  const auto d = z ? dim("depth", g.depth, "m") : std::pair{-1, -1};
  const auto y = dim("y", g.y, g.y_units.empty() ? g.x_units : g.y_units);
  const auto x = dim("x", g.x, g.x_units, g.x_over_time ? t.first : -1);
  std::vector<int> dims = {t.first};
  if (z) dims.push_back(d.first);
  dims.push_back(y.first);
  dims.push_back(x.first);
  int u = -1, v = -1;
  nc_def_var(nc, "uo", NC_FLOAT, static_cast<int>(dims.size()), dims.data(), &u);
  nc_def_var(nc, "vo", NC_FLOAT, static_cast<int>(dims.size()), dims.data(), &v);
  const float fill = -999.0f;
  for (int var : {u, v}) {
    nc_put_att_text(nc, var, "units", g.velocity_units.size(), g.velocity_units.c_str());
    nc_put_att_float(nc, var, "_FillValue", NC_FLOAT, 1, &fill);
  }
  nc_enddef(nc);
  nc_put_var_double(nc, t.second, g.time.data());
  if (z) nc_put_var_double(nc, d.second, g.depth.data());
  nc_put_var_double(nc, y.second, g.y.data());
  nc_put_var_double(nc, x.second, (g.x_over_time ? g.time : g.x).data());
  std::vector<float> us, vs;
  const std::vector<double> levels = z ? g.depth : std::vector<double>{0.0};
  for (double time : g.time)
    for (double depth : levels)
      for (double yy : g.y)
        for (double xx : g.x) {
          const Vec2 w = g.field(time * 3600.0, xx, yy, depth);
          const bool hole = g.fill_somewhere && us.size() % (g.x.size() * g.y.size() * levels.size()) == 0;
          us.push_back(hole ? fill : static_cast<float>(w.x));
          vs.push_back(hole ? fill : static_cast<float>(w.y));
        }
  nc_put_var_float(nc, u, us.data());
  nc_put_var_float(nc, v, vs.data());
  REQUIRE(nc_close(nc) == NC_NOERR);
}

std::string grid_table(const std::filesystem::path& path) {
  return "[environment.current_file]\nfile = \"" + path.string() + "\"\nu = \"uo\"\nv = \"vo\"\n";
}

const char* kStart = "[run]\nstart = \"2024-03-01T00:00:00Z\"\n";

}  // namespace

TEST_CASE("a gridded current constant in space and time gives the steady run to the bit", "[environment][met_ocean]") {
  // Values a float holds exactly, so that the file's single precision changes nothing.
  const std::filesystem::path dir = test::temp_dir("grid-steady");
  GridFile g;
  g.x = {-2000.0, 0.0, 5000.0};
  g.y = {-3000.0, 3000.0};
  g.time = {-1.0, 0.5, 2.0};
  g.field = [](double, double, double, double) { return Vec2{0.25, -0.125}; };
  write_grid(dir / "ocean.nc", g);
  const std::string head = std::string(kStart) + "duration = 3600.0\ndt = 0.5\n[environment]\nlatitude = 75.0\nwind = [6.0, 2.0]\n";
  const Scene steady = test::scene_from(head + "current = [0.25, -0.125]\n" + three_floes());
  const Scene gridded = test::scene_from(head + grid_table(dir / "ocean.nc") + three_floes());
  REQUIRE(gridded.environment.current_grid.time.size() == 3);
  CHECK(gridded.environment.current_grid.time.front() == -3600.0);
  Stepper a(steady, "native"), b(gridded, "native");
  bool touched = false;
  for (std::int64_t k = 0; k < steady.run.steps(); ++k) {
    a.step();
    b.step();
    touched = touched || !a.engine().contacts().empty();
  }
  CHECK(touched);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(a.state().position[i].x == b.state().position[i].x);
    CHECK(a.state().position[i].y == b.state().position[i].y);
    CHECK(a.state().angle[i] == b.state().angle[i]);
  }
}

TEST_CASE("a gridded current with a linear shear gives the analytic force and torque", "[environment][met_ocean]") {
  // V = (0, s x) across a square floe of side L at x0, at rest, under linearised skin drag
  // (k = rho_w C_dw U_ref per unit area): F_y = k s x0 L^2 and, about the centroid,
  // tau = k \int (x - x0) s x dA = k s L^4 / 12. Bilinear interpolation holds a linear field
  // exactly, and the skin drag's quadrature is exact for it.
  const std::filesystem::path dir = test::temp_dir("grid-shear");
  const double s = 1.0 / 8192.0, x0 = 150.0, L = 40.0;  // the grid's values (+-0.125 m/s) exact in a float
  GridFile g;
  g.x = {-1024.0, 0.0, 1024.0};
  g.y = {-1024.0, 1024.0};
  g.time = {0.0, 1.0};
  g.field = [&](double, double x, double, double) { return Vec2{0.0, s * x}; };
  write_grid(dir / "shear.nc", g);
  const Scene sc = test::scene_from(
      std::string(kStart) + "duration = 10.0\ndt = 1.0\n[environment]\ndrag_reference_speed = 0.1\n" +
      grid_table(dir / "shear.nc") +
      "[environment.drag]\nwater_form = 0.0\nwater_skin = 0.005\nair_form = 0.0\nair_skin = 0.0\n[[body]]\nname = \"f\"\n"
      "polygon = " + test::toml_polygon(test::box({x0, 0.0}, L, L)) + "\nthickness = 1.0\n");
  Forcing forcing(sc);
  BodyStates st;
  st.resize(1);
  st.position[0] = sc.bodies[0].centroid;
  forcing.evaluate(st, 0.0);
  const double k = 1025.0 * 0.005 * 0.1;
  const std::array<double, 3> q = forcing.environment_force(0);
  CHECK(q[0] == Approx(0.0).margin(1e-9));
  CHECK(q[1] == Approx(k * s * x0 * L * L).epsilon(1e-12));
  CHECK(q[2] == Approx(k * s * std::pow(L, 4) / 12.0).epsilon(1e-12));
}

TEST_CASE("a gridded current that changes in time follows the record it samples", "[environment][met_ocean]") {
  // The current record of the closed-form test above as a grid uniform in space, sampled every
  // 3 h: the same velocities at every step, so the same drift to the bit as the CSV record, and
  // so the same second-order convergence to the closed form.
  const std::filesystem::path dir = test::temp_dir("grid-time");
  GridFile g;
  g.x = {-1e5, 1e5};
  g.y = {-1e5, 1e5};
  std::ofstream csv(dir / "current.csv");
  csv.precision(17);
  csv << "time,u,v\n";
  for (int k = 0; k <= 8; ++k) {
    g.time.push_back(3.0 * k);
    // floats, so that the file holds the CSV's numbers exactly
    const float u = static_cast<float>(0.15 + 0.2 * std::cos(0.7 * k)), v = static_cast<float>(0.05 - 0.1 * std::sin(1.3 * k));
    csv << 10800.0 * k << ',' << static_cast<double>(u) << ',' << static_cast<double>(v) << '\n';
  }
  csv.close();
  g.field = [](double t, double, double, double) {
    const int k = static_cast<int>(std::lround(t / 10800.0));
    return Vec2{static_cast<float>(0.15 + 0.2 * std::cos(0.7 * k)), static_cast<float>(0.05 - 0.1 * std::sin(1.3 * k))};
  };
  write_grid(dir / "ocean.nc", g);
  const Scene by_csv = test::scene_from(
      std::string(kStart) +
      drift_scene(60.0, "", "[environment.current_file]\nfile = \"" + (dir / "current.csv").string() + "\"\n").substr(6));
  const Scene by_grid = test::scene_from(std::string(kStart) + drift_scene(60.0, "", grid_table(dir / "ocean.nc")).substr(6));
  Stepper a(by_csv, "native"), b(by_grid, "native");
  for (std::int64_t k = 0; k < by_csv.run.steps(); ++k) {
    a.step();
    b.step();
  }
  CHECK(a.state().position[0].x == b.state().position[0].x);
  CHECK(a.state().position[0].y == b.state().position[0].y);
}

TEST_CASE("bad gridded forcing is refused with the file, the variable and what is allowed", "[input][met_ocean]") {
  const std::filesystem::path dir = test::temp_dir("grid-bad");
  auto base = [] {
    GridFile g;
    g.x = {-100.0, 100.0};
    g.y = {-100.0, 100.0};
    g.time = {0.0, 1.0};
    g.field = [](double, double, double, double) { return Vec2{0.1, 0.0}; };
    return g;
  };
  const std::string body = "[[body]]\nname = \"a\"\npolygon = [[0,0],[10,0],[10,10],[0,10]]\nthickness = 1.0\n";
  auto scene = [&](const std::string& file, const std::string& run = "") {
    return std::string(run.empty() ? kStart : run.c_str()) + "duration = 3600.0\ndt = 1.0\n[environment]\n" +
           grid_table(dir / file) + body;
  };
  std::vector<Bad> cases;
  {
    write_grid(dir / "ok.nc", base());
    cases.push_back({"no run.start", scene("ok.nc", "[run]\n"), {"ok.nc", "'time'", "[run] start"}});
    cases.push_back({"missing variable",
                     std::string(kStart) + "duration = 3600.0\ndt = 1.0\n[environment]\n[environment.current_file]\nfile = \"" +
                         (dir / "ok.nc").string() + "\"\nu = \"uu\"\nv = \"vo\"\n" + body,
                     {"ok.nc", "'uu'", "no such variable"}});
    GridFile g = base();
    g.velocity_units = "cm/s";
    write_grid(dir / "units.nc", g);
    cases.push_back({"not a velocity", scene("units.nc"), {"units.nc", "'uo.units'", "'cm/s'", "m s-1"}});
    g = base();
    g.time = {0.0, 0.5};
    write_grid(dir / "short.nc", g);
    cases.push_back({"time not covering", scene("short.nc"), {"short.nc", "'time'", "covers [0, 1800]", ">= 3600"}});
    g = base();
    g.x = {20.0, 100.0};
    write_grid(dir / "small.nc", g);
    cases.push_back({"grid not covering", scene("small.nc"), {"small.nc", "'uo'", "body 'a'", "off the grid"}});
    g = base();
    g.x_units = "degrees_east";
    write_grid(dir / "geo.nc", g);
    cases.push_back({"longitude", scene("geo.nc"), {"geo.nc", "'x.units'", "geographic"}});
    g = base();
    g.time = {0.0, 0.5, 1.0, 1.5};  // longer than x: read over x's two values, it would overflow them
    g.x_over_time = true;
    write_grid(dir / "x-over-time.nc", g);
    cases.push_back({"coordinate over another dimension", scene("x-over-time.nc"),
                     {"x-over-time.nc", "'x'", "over another dimension", "its own dimension 'x'"}});
    std::ofstream(dir / "text.nc") << "not netcdf\n";
    cases.push_back({"not netcdf", scene("text.nc"), {"text.nc", "'file'", "cannot open as NetCDF"}});
  }
  check_refusals(cases);
  // A fill value where a body is: found while stepping, the step refused with the file.
  GridFile g = base();
  g.x = {0.0, 100.0};
  g.y = {0.0, 100.0};
  g.fill_somewhere = true;
  write_grid(dir / "hole.nc", g);
  const Scene s = test::scene_from(scene("hole.nc"));
  Stepper run(s, "native");
  std::string message;
  try {
    run.step();
  } catch (const InputError& e) {
    message = e.what();
  }
  INFO(message);
  CHECK(message.find("hole.nc") != std::string::npos);
  CHECK(message.find("fill value") != std::string::npos);
  // The same through a run: refused at its first step with nothing written, neither the file
  // nor a .partial that would look like a run to continue.
  RunOptions o;
  o.output = (dir / "hole.h5").string();
  CHECK_THROWS_AS(run_scene(s, o), InputError);
  CHECK_FALSE(std::filesystem::exists(o.output));
  CHECK_FALSE(std::filesystem::exists(o.output + ".partial"));
  // And by the library's check_scene and `floedem check`, which read the forcing at t = 0 as
  // the first step does.
  CHECK_THROWS_AS(check_scene(s), InputError);
  std::ofstream(dir / "hole.toml") << scene("hole.nc");
  const auto checked = test::run_cli("check " + (dir / "hole.toml").string());
  INFO(checked.output);
  CHECK(checked.code == 2);
  CHECK(checked.output.find("fill value") != std::string::npos);
  CHECK(std::count(checked.output.begin(), checked.output.end(), '\n') == 1);
}

TEST_CASE("a grid value beyond any wind or current is refused before the run", "[input][met_ocean]") {
  // A flipped exponent byte turns 0.1 m/s into 1e38 m/s; driven into a run it would fling the
  // floes, so the slice is refused where it is read, and `floedem check` reads it at t = 0.
  const std::filesystem::path dir = test::temp_dir("grid-fast");
  GridFile g;
  g.x = {-100.0, 100.0};
  g.y = {-100.0, 100.0};
  g.time = {0.0, 1.0};
  g.field = [](double, double x, double, double) { return Vec2{x > 0.0 ? 3.0e4 : 0.1, 0.0}; };
  write_grid(dir / "fast.nc", g);
  std::ofstream(dir / "fast.toml")
      << std::string(kStart) + "duration = 3600.0\ndt = 1.0\n[environment]\n" + grid_table(dir / "fast.nc") +
             "[[body]]\nname = \"a\"\npolygon = [[0,0],[10,0],[10,10],[0,10]]\nthickness = 1.0\n";
  const auto checked = test::run_cli("check " + (dir / "fast.toml").string());
  INFO(checked.output);
  CHECK(checked.code == 2);
  CHECK(std::count(checked.output.begin(), checked.output.end(), '\n') == 1);
  for (const char* s : {"fast.nc", "'uo'", "30000 m/s", "time slice 0", "[-100, 100] m/s"})
    CHECK(checked.output.find(s) != std::string::npos);
  const auto ran = test::run_cli("run " + (dir / "fast.toml").string() + " --out " + (dir / "fast.h5").string() + " --quiet");
  CHECK(ran.code == 2);
  CHECK_FALSE(std::filesystem::exists(dir / "fast.h5"));
  CHECK_FALSE(std::filesystem::exists(dir / "fast.h5.partial"));
}

TEST_CASE("a gridded current with a depth axis feeds each keel layer the current at its depth",
          "[environment][met_ocean]") {
  // u = d / 100 m/s at depth d (levels at 0 and 100 m), read linearly in depth: the keel's one
  // layer, 0 to 60 m, reads it at its middle, 30 m: 0.3 m/s, the force of a steady 0.3 m/s
  // current on that layer to the bit (form drag alone).
  const std::filesystem::path dir = test::temp_dir("grid-depth");
  GridFile g;
  g.x = {-500.0, 500.0};
  g.y = {-500.0, 500.0};
  g.depth = {0.0, 100.0};
  g.time = {0.0, 1.0};
  g.field = [](double, double, double, double depth) { return Vec2{depth / 100.0, 0.0}; };
  write_grid(dir / "layers.nc", g);
  const std::string berg =
      "[environment.drag]\nwater_skin = 0.0\nair_form = 0.0\nair_skin = 0.0\n[[body]]\nname = \"berg\"\nkind = \"iceberg\"\n"
      "polygon = [[0,0],[100,0],[100,50],[0,50]]\ndraft = 60\nsail_height = 10\nmass = 2e8\n";
  const std::string head = std::string(kStart) + "duration = 10.0\ndt = 1.0\n[environment]\n";
  const Scene gridded = test::scene_from(head + grid_table(dir / "layers.nc") + berg);
  const Scene steady = test::scene_from(head + "current = [0.3, 0.0]\n" + berg);
  REQUIRE(gridded.environment.current_grid.depth.size() == 2);
  Forcing a(gridded), b(steady);
  BodyStates st;
  st.resize(1);
  st.position[0] = gridded.bodies[0].centroid;
  a.evaluate(st, 0.0);
  b.evaluate(st, 0.0);
  CHECK(a.environment_force(0)[0] > 0.0);
  CHECK(a.environment_force(0) == b.environment_force(0));
}

TEST_CASE("a current on longitude and latitude is the plane's field in a geographic scene", "[met_ocean][geo]") {
  // A field linear in longitude and latitude (so bilinear in them exactly), eastward and
  // northward, about a scene at (20 E, 70 N). Resampled onto the plane's lattice (4.5 km here:
  // half the grid's 9 km of longitude at 71 N) and read there, it must be, at any point, the
  // field at that point's longitude and latitude, its east and north turned onto the plane's
  // axes there: the meridians converge by 2.5 deg 100 km east of the origin. The lattice's
  // bilinear error: the curvature of latitude over a cell, h^2 tan(lat) / (8 R^2) = 1.7e-7 rad,
  // times 0.05 m/s per degree, 5e-7 m/s.
  const std::filesystem::path dir = test::temp_dir("grid-lonlat");
  auto east = [](double lon, double lat) { return 0.2 + 0.05 * (lat - 70.0) + 0.01 * (lon - 20.0); };
  auto north = [](double lon, double) { return 0.1 - 0.02 * (lon - 20.0); };
  GridFile g;
  for (double lon = 16.0; lon <= 24.0 + 1e-9; lon += 0.25) g.x.push_back(lon);
  for (double lat = 69.0; lat <= 71.0 + 1e-9; lat += 0.1) g.y.push_back(lat);
  g.time = {-1.0, 2.0};
  g.x_units = "degrees_east";
  g.y_units = "degrees_north";
  g.field = [&](double, double lon, double lat, double) { return Vec2{east(lon, lat), north(lon, lat)}; };
  write_grid(dir / "ocean.nc", g);
  const std::string body = "[[body]]\nname = \"a\"\nthickness = 1.0\n"
                           "polygon = [[-50.0, -50.0], [50.0, -50.0], [50.0, 50.0], [-50.0, 50.0]]\n";
  const std::string head = std::string(kStart) + "duration = 3600.0\ndt = 10.0\n[geo]\norigin = [20.0, 70.0]\n"
                                                 "[environment]\n" + grid_table(dir / "ocean.nc");
  const Scene s = test::scene_from(head + body);
  const FlowGridSpec& spec = s.environment.current_grid;
  REQUIRE(spec.lonlat());
  CHECK(spec.spacing == Approx(0.5 * 111.32e3 * 0.25 * std::cos(71.0 * M_PI / 180.0)).epsilon(1e-9));
  CHECK(spec.x.front() < -150e3);  // 200 km about the floe, within the grid's outline
  CHECK(spec.x.back() > 150e3);
  FlowGrid grid(spec);
  grid.prepare(0.0);
  const GeoProjection projection(s.geo);
  double worst = 0.0, turn = 0.0;
  for (const Vec2 p : {Vec2{0.0, 0.0}, Vec2{100e3, 0.0}, Vec2{-80e3, 60e3}, Vec2{37e3, -91e3}, Vec2{120e3, 80e3}}) {
    const LonLat at = projection.to_lonlat(p);
    const Vec2 e = normalized(projection.to_plane({at.lon + 1e-4, at.lat}) - projection.to_plane({at.lon - 1e-4, at.lat}));
    const Vec2 n = normalized(projection.to_plane({at.lon, at.lat + 1e-4}) - projection.to_plane({at.lon, at.lat - 1e-4}));
    const Vec2 expected = east(at.lon, at.lat) * e + north(at.lon, at.lat) * n;
    worst = std::max(worst, length(grid.at(p, 0.0) - expected));
    turn = std::max(turn, std::abs(std::atan2(e.y, e.x)));
  }
  CHECK(worst < 2e-6);
  CHECK(turn > 0.04);  // the turn of east is there to be taken: 2.3 deg and more
  // A body off the file's longitudes and latitudes is refused by name when the scenario is read.
  try {
    (void)test::scene_from(head + "[[body]]\nname = \"far\"\nthickness = 1.0\nposition_lonlat = [30.0, 70.0]\n"
                                  "polygon = [[-50.0, -50.0], [50.0, -50.0], [50.0, 50.0], [-50.0, 50.0]]\n");
    FAIL("accepted");
  } catch (const InputError& e) {
    const std::string m = e.what();
    INFO(m);
    CHECK(m.find("ocean.nc") != std::string::npos);
    CHECK(m.find("body 'far'") != std::string::npos);
    CHECK(m.find("longitude [16, 24]") != std::string::npos);
  }
}
