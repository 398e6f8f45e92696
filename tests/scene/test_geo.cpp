// Geographic scenes (docs/geography.md): the projection against the ellipsoid's own geometry,
// positions given in longitude and latitude, the Coriolis parameter at each body's latitude,
// the output's longitudes and latitudes, and the refusals.
#include <catch2/catch.hpp>

#include <H5Cpp.h>

#include <cmath>
#include <random>
#include <sstream>

#include "floedem/run/simulation.hpp"
#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/geo.hpp"
#include "floedem/scene/input_error.hpp"
#include "forcing/coriolis_field.hpp"
#include "geometry/polygon.hpp"
#include "run/stepper.hpp"
#include "support.hpp"

using namespace floedem;

namespace {

GeoSpec geo_at(double lon, double lat) {
  GeoSpec g;
  g.present = true;
  g.origin_lon = lon;
  g.origin_lat = lat;
  g.projection = GeoSpec::default_projection(lon, lat);
  return g;
}

/// The WGS 84 meridian arc (m) between two latitudes (deg): the integral of the meridian's
/// radius of curvature M = a (1 - e^2) / (1 - e^2 sin^2 phi)^(3/2), by Simpson's rule on 2000
/// intervals (error far below a micrometre over a degree).
double meridian_arc(double lat0, double lat1) {
  const double a = 6378137.0, f = 1.0 / 298.257223563, e2 = f * (2.0 - f);
  auto m = [&](double phi) { return a * (1.0 - e2) / std::pow(1.0 - e2 * std::sin(phi) * std::sin(phi), 1.5); };
  const int n = 2000;
  const double p0 = lat0 * M_PI / 180.0, h = (lat1 - lat0) * M_PI / 180.0 / n;
  double s = m(p0) + m(p0 + n * h);
  for (int k = 1; k < n; ++k) s += (k % 2 ? 4.0 : 2.0) * m(p0 + k * h);
  return s * h / 3.0;
}

/// A scene about (20 E, 70 N) with no drag: two floes that only turn by Coriolis.
std::string inertial_scene(const std::string& geo_or_latitude, const std::string& bodies) {
  return "[run]\nduration = 43200.0\ndt = 30.0\n" + geo_or_latitude +
         "[environment.drag]\nwater_form = 0.0\nwater_skin = 0.0\nair_form = 0.0\nair_skin = 0.0\n" + bodies;
}

/// The angle (rad, unwrapped) the velocity of `body` has turned through over the run.
double turned_angle(const Scene& s, std::size_t body) {
  Stepper run(s, "native");
  double total = 0.0;
  Vec2 before = run.state().velocity[body];
  for (std::int64_t k = 0; k < s.run.steps(); ++k) {
    run.step();
    const Vec2 v = run.state().velocity[body];
    total += std::atan2(cross(before, v), dot(before, v));
    before = v;
  }
  return total;
}

}  // namespace

TEST_CASE("geo: the default projection keeps distances from the origin true", "[geo]") {
  const GeoProjection p(geo_at(20.0, 70.0));
  const Vec2 o = p.to_plane({20.0, 70.0});
  CHECK(o.x == 0.0);
  CHECK(o.y == 0.0);
  // One degree north along the origin's meridian: the meridian arc, straight up.
  const Vec2 north = p.to_plane({20.0, 71.0});
  CHECK(std::abs(north.x) < 1e-6);
  CHECK(north.y == Approx(meridian_arc(70.0, 71.0)).epsilon(1e-9));
  // Round trips over a few hundred kilometres.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-300e3, 300e3);
  for (int k = 0; k < 200; ++k) {
    const Vec2 x{u(rng), u(rng)};
    const LonLat g = p.to_lonlat(x);
    const Vec2 back = p.to_plane(g);
    CHECK(length(back - x) < 1e-6);
  }
  // A projection the user gives: north polar stereographic (EPSG:3413), shifted to the origin.
  GeoSpec polar = geo_at(-45.0, 80.0);
  polar.projection = "EPSG:3413";
  const GeoProjection q(polar);
  CHECK(length(q.to_plane({-45.0, 80.0})) == 0.0);
  const LonLat g = q.to_lonlat(q.to_plane({-40.0, 79.5}));
  CHECK(g.lon == Approx(-40.0).margin(1e-9));
  CHECK(g.lat == Approx(79.5).margin(1e-9));
}

TEST_CASE("geo: the Coriolis field is PROJ's f to 1e-8 and the same in any order", "[geo]") {
  const GeoSpec geo = geo_at(20.0, 70.0);
  const GeoProjection p(geo);
  CoriolisField a(geo), b(geo);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-400e3, 400e3);
  std::vector<Vec2> points;
  for (int k = 0; k < 2000; ++k) points.push_back({u(rng), u(rng)});
  double worst = 0.0;
  std::vector<double> forward;
  for (const Vec2 x : points) {
    const double exact = coriolis_parameter(p.to_lonlat(x).lat);
    const double f = a.at(x);
    worst = std::max(worst, std::abs(f - exact) / std::abs(exact));
    forward.push_back(f);
  }
  CHECK(worst < 1e-8);
  // Visited backwards from a fresh field: the tiles are built in another order, the values
  // are the same to the bit (a resumed run sees what the uninterrupted one did).
  for (std::size_t k = points.size(); k-- > 0;) CHECK(b.at(points[k]) == forward[k]);
}

TEST_CASE("geo: polygons and positions in longitude and latitude land where PROJ puts them", "[geo]") {
  const Scene s = test::scene_from(
      "[run]\nduration = 10.0\ndt = 1.0\n[geo]\norigin = [20.0, 70.0]\n"
      "[[body]]\nname = \"a\"\nthickness = 1.0\n"
      "polygon_lonlat = [[20.0, 70.0], [20.01, 70.0], [20.01, 70.005], [20.0, 70.005]]\n"
      "[[body]]\nname = \"b\"\nthickness = 1.0\nposition_lonlat = [20.5, 70.2]\n"
      "polygon = [[-40.0, -30.0], [40.0, -30.0], [40.0, 30.0], [-40.0, 30.0]]\n");
  const GeoProjection p(s.geo);
  REQUIRE(s.bodies.size() == 2);
  CHECK(length(s.bodies[0].polygon[0]) == 0.0);
  CHECK(length(s.bodies[0].polygon[2] - p.to_plane({20.01, 70.005})) == 0.0);
  CHECK(length(s.bodies[1].centroid - p.to_plane({20.5, 70.2})) < 1e-9);
  CHECK(s.bodies[1].area == Approx(80.0 * 60.0).epsilon(1e-12));
  CHECK(s.environment.coriolis == false);  // no [environment]: no forcing at all
}

TEST_CASE("geo: each body turns at its own latitude's Coriolis parameter", "[geo]") {
  // Floes 400 km south and 1000 km north of the origin (66.4 and 79.0 N), at 0.2 m/s: their
  // inertial circles (r = 1.5 and 1.4 km) are small, so each turns at its own f, to the change
  // of f over the circle: it turns about a centre r south of its start, where f is smaller by
  // r cot(latitude) / R = 1.0e-4 and 0.5e-4 of f (beta, R = 6.37e6 m); the latitudes' f differ
  // from each other by 7 % and from the origin's by 3 %. The first step turns by half a step
  // (docs/model.md 2): f (T - dt/2) in all. And each as a plain scene at its latitude turns it.
  const std::string square = "polygon = [[-50.0, -50.0], [50.0, -50.0], [50.0, 50.0], [-50.0, 50.0]]\n";
  const std::string floes = "[[body]]\nname = \"south\"\nthickness = 1.0\nvelocity = [0.2, 0.0]\n"
                            "position_lonlat = [20.0, 66.4]\n" + square +
                            "[[body]]\nname = \"north\"\nthickness = 1.0\nvelocity = [0.2, 0.0]\n"
                            "position_lonlat = [20.0, 79.0]\n" + square;
  const Scene geo = test::scene_from(inertial_scene("[geo]\norigin = [20.0, 70.0]\n[environment]\n", floes));
  REQUIRE(geo.environment.coriolis);
  const double t = geo.run.duration - 0.5 * geo.run.dt;
  const double south = turned_angle(geo, 0), north = turned_angle(geo, 1);
  CHECK(-south / t == Approx(coriolis_parameter(66.4)).epsilon(2.5e-4));
  CHECK(-north / t == Approx(coriolis_parameter(79.0)).epsilon(2.5e-4));
  for (const auto& [lat, angle] : {std::pair{66.4, south}, std::pair{79.0, north}}) {
    std::ostringstream at;
    at.precision(17);
    at << "[environment]\nlatitude = " << lat << "\n";
    const Scene plain = test::scene_from(
        inertial_scene(at.str(), "[[body]]\nname = \"f\"\nthickness = 1.0\nvelocity = [0.2, 0.0]\n" + square));
    CHECK(angle == Approx(turned_angle(plain, 0)).epsilon(2.5e-4));
  }
}

TEST_CASE("geo: with the sea-surface tilt, a floe far from the origin drifts with the current", "[geo]") {
  // The tilt m f k x V balances the Coriolis force on a floe moving at V only when both use
  // the floe's own f: at 82 N, 1300 km from the origin, f is 5 % above the origin's, and a tilt
  // at the origin's f would leave the floe (f - f_0) |V| / a = 6e-3 m/s off the current (a the
  // linearised drag's rate, 2.8e-4 1/s). What is left is the step's own error.
  const Scene s = test::scene_from(
      "[run]\nduration = 172800.0\ndt = 60.0\n[geo]\norigin = [20.0, 70.0]\n[environment]\ncurrent = [0.2, 0.1]\n"
      "drag_reference_speed = 0.1\n"
      "[[body]]\nname = \"floe\"\nthickness = 1.0\nposition_lonlat = [20.0, 82.0]\n"
      "polygon = [[-100.0, -100.0], [100.0, -100.0], [100.0, 100.0], [-100.0, 100.0]]\n");
  REQUIRE(s.environment.sea_surface_tilt);
  Stepper run(s, "native");
  for (std::int64_t k = 0; k < s.run.steps(); ++k) run.step();
  CHECK(length(run.state().velocity[0] - Vec2{0.2, 0.1}) < 3e-4);
}

TEST_CASE("geo: the output holds each body's longitude and latitude per frame", "[geo][output]") {
  const std::string out = (test::temp_dir("geo-output") / "g.h5").string();
  RunOptions o;
  o.output = out;
  const Scene s = test::scene_from(
      "[run]\nduration = 3600.0\ndt = 60.0\noutput_every = 10\n[geo]\norigin = [-50.0, 60.0]\n"
      "[environment]\nwind = [10.0, 0.0]\n"
      "[[body]]\nname = \"floe\"\nthickness = 1.0\nposition_lonlat = [-49.5, 60.3]\n"
      "polygon = [[-100.0, -100.0], [100.0, -100.0], [100.0, 100.0], [-100.0, 100.0]]\n");
  run_scene(s, o);
  H5::H5File f(out, H5F_ACC_RDONLY);
  const H5::DataSet position = f.openDataSet("/bodies/position"), lonlat = f.openDataSet("/bodies/lonlat");
  hsize_t dims[3];
  lonlat.getSpace().getSimpleExtentDims(dims);
  REQUIRE(dims[0] == 7);
  REQUIRE(dims[1] == 1);
  std::vector<double> xy(14), ll(14);
  position.read(xy.data(), H5::PredType::NATIVE_DOUBLE);
  lonlat.read(ll.data(), H5::PredType::NATIVE_DOUBLE);
  const GeoProjection p(s.geo);
  for (int k = 0; k < 7; ++k) {
    const LonLat g = p.to_lonlat({xy[2 * k], xy[2 * k + 1]});
    CHECK(ll[2 * k] == g.lon);
    CHECK(ll[2 * k + 1] == g.lat);
  }
  CHECK(ll[0] == Approx(-49.5).margin(1e-9));
  CHECK(ll[1] == Approx(60.3).margin(1e-9));
  CHECK(ll[12] > ll[0]);  // blown east
  std::string projection;
  const H5::Attribute a = f.openGroup("/geo").openAttribute("projection");
  a.read(a.getStrType(), projection);
  CHECK(projection.find("+proj=aeqd") == 0);
}

TEST_CASE("geo: bad input is refused with the field and what is allowed", "[geo][input]") {
  const std::string run = "[run]\nduration = 10.0\ndt = 1.0\n";
  const std::string square = "polygon = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]\n";
  const std::string body = "[[body]]\nname = \"a\"\nthickness = 1.0\n";
  struct Bad {
    const char* what;
    std::string text, expect;
  };
  const Bad bad[] = {
      {"longitude", run + "[geo]\norigin = [190.0, 70.0]\n" + body + square, "geo.origin"},
      {"pole", run + "[geo]\norigin = [0.0, 90.0]\n" + body + square, "allowed (-90, 90)"},
      {"unreadable projection", run + "[geo]\norigin = [0.0, 70.0]\nprojection = \"+proj=nonsense\"\n" + body + square,
       "geo.projection"},
      {"geographic projection", run + "[geo]\norigin = [0.0, 70.0]\nprojection = \"EPSG:4326\"\n" + body + square,
       "not a projected coordinate reference system in metres"},
      {"latitude too", run + "[geo]\norigin = [0.0, 70.0]\n[environment]\nlatitude = 70.0\n" + body + square,
       "environment.latitude"},
      {"no geo", run + body + "polygon_lonlat = [[0.0, 70.0], [0.1, 70.0], [0.1, 70.1]]\n", "needs a [geo] table"},
      {"both polygons", run + "[geo]\norigin = [0.0, 70.0]\n" + body + square +
                            "polygon_lonlat = [[0.0, 70.0], [0.1, 70.0], [0.1, 70.1]]\n", "not both"},
      {"latitude of a vertex", run + "[geo]\norigin = [0.0, 70.0]\n" + body +
                                   "polygon_lonlat = [[0.0, 70.0], [0.1, 95.0], [0.1, 70.1]]\n", "vertex 1"},
      {"position and lonlat polygon", run + "[geo]\norigin = [0.0, 70.0]\n" + body + "position_lonlat = [0.0, 70.0]\n" +
                                          "polygon_lonlat = [[0.0, 70.0], [0.1, 70.0], [0.1, 70.1]]\n",
       "body[0].position_lonlat"},
      {"field origin in degrees without geo", run + body + square +
                                                  "[field]\norigin_lonlat = [0.0, 70.0]\nwidth = 100.0\nheight = 100.0\n"
                                                  "concentration = 0.3\nalpha = 2.0\nd_min = 5.0\nd_max = 20.0\n"
                                                  "thickness = 1.0\n",
       "field.origin_lonlat"},
  };
  for (const Bad& b : bad) {
    INFO(b.what);
    try {
      (void)test::scene_from(b.text);
      FAIL("accepted");
    } catch (const InputError& e) {
      const std::string m = e.what();
      INFO(m);
      CHECK(m.find("test.toml") == 0);
      CHECK(m.find(b.expect) != std::string::npos);
      CHECK(m.find('\n') == std::string::npos);
    }
  }
}
