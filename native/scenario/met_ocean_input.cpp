#include "scenario/met_ocean_input.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "floedem/scene/input_error.hpp"
#include "io/netcdf_grid.hpp"
#include "scenario/input_file.hpp"
#include "scene/calendar.hpp"

namespace floedem {

namespace {

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

}  // namespace

double read_utc_instant(TableReader& r, std::string_view key) {
  const std::string text = r.string(key, std::nullopt);
  const char* allowed = "allowed an instant in UTC as \"YYYY-MM-DDTHH:MM:SSZ\" (e.g. \"2024-03-01T00:00:00Z\")";
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, consumed = 0;
  double s = 0.0;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%lf%n", &y, &mo, &d, &h, &mi, &s, &consumed) != 6)
    r.fail(key, "'" + text + "' is not an instant; " + allowed);
  const std::string zone = text.substr(static_cast<std::size_t>(consumed));
  if (zone != "Z" && zone != "+00:00")
    r.fail(key, "'" + text + "' is not in UTC (it must end in Z); " + allowed);
  if (!valid_instant(y, mo, d, h, mi, s)) r.fail(key, "'" + text + "' is not a valid date and time; " + allowed);
  return unix_seconds(y, mo, d, h, mi, s);
}

void read_tides(TableReader& env, Scene& scene) {
  const auto tables = env.array_of_tables("tide");
  for (std::size_t k = 0; k < tables.size(); ++k) {
    TableReader r(*tables[k], scene.source_path, "environment.tide[" + std::to_string(k) + "]");
    TidalConstituent c;
    if (r.has("period") == r.has("constituent"))
      r.fail("period", "give period (s) or constituent (" + [] {
        std::string names;
        for (const std::string& n : tidal_constituent_names()) names += (names.empty() ? "" : ", ") + n;
        return names;
      }() + "), one of them");
    if (r.has("constituent")) {
      c.name = r.string("constituent", std::nullopt, tidal_constituent_names());
      c.period = tidal_period(c.name);
    } else {
      c.period = r.real("period", std::nullopt, Range::positive());
    }
    // Tidal currents reach some 5 m/s in the swiftest straits; 10 m/s bounds any ocean current.
    c.major = r.real("major", std::nullopt, Range::closed(0.0, 10.0));
    c.minor = r.real("minor", 0.0, Range::closed(-c.major, c.major));
    c.inclination = r.real("inclination", 0.0, Range::closed(-360.0, 360.0)) * M_PI / 180.0;
    c.phase = r.real("phase", 0.0, Range::closed(-360.0, 360.0)) * M_PI / 180.0;
    r.reject_unknown();
    scene.environment.tides.push_back(c);
  }
}

bool read_velocity_file(TableReader& env, std::string_view key, Scene& scene, VelocitySeries& series,
                        FlowGridSpec& grid) {
  const toml::table* t = env.table(key);
  if (!t) return false;
  TableReader r(*t, scene.source_path, "environment." + std::string(key));
  std::filesystem::path path = r.string("file", std::nullopt);
  const std::string u_name = r.string("u", "u"), v_name = r.string("v", "v");
  r.reject_unknown();
  const std::string extension = path.extension().string();
  if (extension != ".csv" && extension != ".nc")
    r.fail("file", "'" + path.string() + "': allowed a time series in CSV (.csv) or a grid in CF-NetCDF (.nc)");
  if (path.is_relative()) path = std::filesystem::path(scene.source_path).parent_path() / path;
  const std::string name = path.string();
  if (extension == ".nc") {
    if (!std::filesystem::is_regular_file(path)) r.fail("file", "cannot open '" + name + "': no such file");
    grid = inspect_flow_grid(name, u_name, v_name, scene.run, scene.geo);
    record_input_file(scene, "environment." + std::string(key) + ".file", name);
    return true;
  }
  std::ifstream in(name);
  if (!in) r.fail("file", "cannot open '" + name + "': " + std::strerror(errno));
  // A header naming the columns, then one sample a line; blank lines and lines from '#' are
  // left out (a record's provenance may head the file).
  std::string line;
  std::uint32_t number = 0;
  std::vector<std::string> header;
  std::size_t col_t = 0, col_u = 0, col_v = 0;
  series = VelocitySeries{};
  series.file = name;
  while (std::getline(in, line)) {
    ++number;
    const std::string text = trim(line);
    if (text.empty() || text[0] == '#') continue;
    const std::vector<std::string> cells = split_csv(text);
    if (header.empty()) {
      header = cells;
      auto column = [&](const std::string& want) {
        for (std::size_t c = 0; c < header.size(); ++c)
          if (header[c] == want) return c;
        throw InputError(input_message(name, number, want,
                                       "no such column; allowed a header naming time, " + u_name + " and " + v_name));
      };
      col_t = column("time");
      col_u = column(u_name);
      col_v = column(v_name);
      continue;
    }
    double value[3];
    const std::size_t cols[3] = {col_t, col_u, col_v};
    const std::string names[3] = {"time", u_name, v_name};
    for (int j = 0; j < 3; ++j) {
      const std::string cell = cols[j] < cells.size() ? cells[cols[j]] : "";
      char* end = nullptr;
      errno = 0;
      value[j] = std::strtod(cell.c_str(), &end);
      if (cell.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(value[j]))
        throw InputError(input_message(name, number, names[j],
                                       "'" + printable(cell) + "' is not a number; allowed a finite number (" +
                                           (j == 0 ? "s from the run's start)" : "m/s)")));
    }
    if (!series.time.empty() && !(value[0] > series.time.back())) {
      std::ostringstream above;
      above << series.time.back();
      throw InputError(input_message(name, number, "time", "times must increase; allowed a value above " +
                                                               above.str() + " s"));
    }
    if (std::abs(value[1]) > kMaxFlowComponent || std::abs(value[2]) > kMaxFlowComponent)
      throw InputError(input_message(name, number, std::abs(value[1]) > kMaxFlowComponent ? u_name : v_name,
                                     "is not a wind or current speed; allowed [-100, 100] m/s"));
    series.time.push_back(value[0]);
    series.velocity.push_back({value[1], value[2]});
  }
  if (header.empty()) throw InputError(input_message(name, 0, "time", "the file is empty; allowed a header and samples"));
  if (series.time.empty() || series.time.front() > 0.0 || series.time.back() < scene.run.duration) {
    std::ostringstream covers;
    if (series.time.empty())
      covers << "has no samples";
    else
      covers << "covers [" << series.time.front() << ", " << series.time.back() << "] s";
    throw InputError(input_message(name, 0, "time",
                                   covers.str() + "; allowed samples from <= 0 to >= " + [&] {
                                     std::ostringstream d;
                                     d << scene.run.duration;
                                     return d.str();
                                   }() + " s (run.duration: the series must cover the run)"));
  }
  record_input_file(scene, "environment." + std::string(key) + ".file", name);
  return true;
}

namespace {

/// A longitude moved by whole turns into [lo, hi] where it can be (a grid on 0 to 360 deg in a
/// scene given in -180 to 180, or the other way round).
double wrap_into(double lon, double lo, double hi) {
  if (lon < lo && lon + 360.0 <= hi) return lon + 360.0;
  if (lon > hi && lon - 360.0 >= lo) return lon - 360.0;
  return lon;
}

}  // namespace

void place_lonlat_grids(Scene& scene) {
  for (FlowGridSpec* g : {&scene.environment.current_grid, &scene.environment.wind_grid}) {
    if (g->empty() || !g->lonlat()) continue;
    const GeoProjection projection(g->geo);
    // Every moving body's outline inside the file's longitudes and latitudes.
    Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
    for (const BodySpec& b : scene.bodies) {
      if (b.fixed) continue;
      for (const Vec2 p : b.polygon) {
        const LonLat at = projection.to_lonlat(p);
        const double lon = wrap_into(at.lon, g->lon.front(), g->lon.back());
        if (!(lon >= g->lon.front() && lon <= g->lon.back() && at.lat >= g->lat.front() && at.lat <= g->lat.back())) {
          std::ostringstream o;
          o << "body '" << b.name << "' at longitude " << at.lon << ", latitude " << at.lat << " is off the grid, "
            << "longitude [" << g->lon.front() << ", " << g->lon.back() << "], latitude [" << g->lat.front() << ", "
            << g->lat.back() << "]; allowed a grid that holds every body";
          throw InputError(input_message(g->file, 0, g->u, o.str()));
        }
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
      }
    }
    if (lo.x > hi.x) lo = hi = Vec2{};  // no moving body: a lattice about the origin
    // The grid's outline on the plane (its edges, 64 points each), and the lattice: the part of
    // it within kMargin of the bodies, at half the file's finest spacing (a degree of latitude
    // taken as 111.32 km, one of longitude as that times the cosine of the grid's highest
    // latitude), coarsened until it holds at most kMaxNodes a level.
    constexpr double kMargin = 200e3, kMetresPerDegree = 111.32e3;
    constexpr std::size_t kMaxNodes = 1'000'000;
    Vec2 flo{1e300, 1e300}, fhi{-1e300, -1e300};
    auto take = [&](double lon, double lat) {
      try {
        const Vec2 p = projection.to_plane({lon, lat});
        flo = {std::min(flo.x, p.x), std::min(flo.y, p.y)};
        fhi = {std::max(fhi.x, p.x), std::max(fhi.y, p.y)};
      } catch (const InputError&) {  // a corner beyond the projection's domain: not part of the outline
      }
    };
    for (int k = 0; k <= 64; ++k) {
      const double a = k / 64.0;
      const double lon = g->lon.front() + a * (g->lon.back() - g->lon.front());
      const double lat = g->lat.front() + a * (g->lat.back() - g->lat.front());
      take(lon, g->lat.front());
      take(lon, g->lat.back());
      take(g->lon.front(), lat);
      take(g->lon.back(), lat);
    }
    const Vec2 from{std::max(flo.x, lo.x - kMargin), std::max(flo.y, lo.y - kMargin)};
    const Vec2 to{std::min(fhi.x, hi.x + kMargin), std::min(fhi.y, hi.y + kMargin)};
    double dlon = 360.0, dlat = 180.0, top = 0.0;
    for (std::size_t k = 1; k < g->lon.size(); ++k) dlon = std::min(dlon, g->lon[k] - g->lon[k - 1]);
    for (std::size_t k = 1; k < g->lat.size(); ++k) dlat = std::min(dlat, g->lat[k] - g->lat[k - 1]);
    for (const double lat : {g->lat.front(), g->lat.back()}) top = std::max(top, std::abs(lat));
    double h = 0.5 * kMetresPerDegree * std::min(dlat, dlon * std::max(std::cos(top * M_PI / 180.0), 1e-3));
    h = std::max(h, 50.0);
    auto count = [&](double step) { return std::ceil((to.x - from.x) / step) + 1.0; };
    while (count(h) * (std::ceil((to.y - from.y) / h) + 1.0) > static_cast<double>(kMaxNodes)) h *= 1.25;
    g->spacing = h;
    g->x.clear();
    g->y.clear();
    const auto nx = static_cast<std::size_t>(std::max(2.0, count(h)));
    const auto ny = static_cast<std::size_t>(std::max(2.0, std::ceil((to.y - from.y) / h) + 1.0));
    for (std::size_t i = 0; i < nx; ++i) g->x.push_back(from.x + static_cast<double>(i) * h);
    for (std::size_t j = 0; j < ny; ++j) g->y.push_back(from.y + static_cast<double>(j) * h);
  }
}

void check_grid_coverage(const Scene& scene) {
  for (const FlowGridSpec* g : {&scene.environment.current_grid, &scene.environment.wind_grid}) {
    if (g->empty()) continue;
    for (const BodySpec& b : scene.bodies) {
      if (b.fixed) continue;
      for (const Vec2 p : b.polygon)
        if (!(p.x >= g->x.front() && p.x <= g->x.back() && p.y >= g->y.front() && p.y <= g->y.back())) {
          std::ostringstream o;
          o << "body '" << b.name << "' at (" << p.x << ", " << p.y << ") m is off the grid, x [" << g->x.front() << ", "
            << g->x.back() << "], y [" << g->y.front() << ", " << g->y.back()
            << "] m; allowed a grid that holds every body";
          throw InputError(input_message(g->file, 0, g->u, o.str()));
        }
    }
  }
}

}  // namespace floedem
