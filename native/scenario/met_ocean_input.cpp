#include "scenario/met_ocean_input.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "floedem/scene/input_error.hpp"

namespace floedem {

namespace {

/// Days from 1970-01-01 to the civil date y-m-d (proleptic Gregorian): the era arithmetic of
/// the 400-year cycle, March-based years so that the leap day ends a year.
std::int64_t days_from_civil(std::int64_t y, int m, int d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const std::int64_t yoe = y - era * 400;                               // [0, 399]
  const std::int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;  // [0, 365]
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;      // [0, 146096]
  return era * 146097 + doe - 719468;
}

bool leap(std::int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

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
  static const int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (mo < 1 || mo > 12 || d < 1 || d > kDays[mo - 1] + (mo == 2 && leap(y) ? 1 : 0) || h > 23 || mi > 59 ||
      !(s >= 0.0 && s < 60.0))
    r.fail(key, "'" + text + "' is not a valid date and time; " + allowed);
  return static_cast<double>(days_from_civil(y, mo, d)) * 86400.0 + h * 3600.0 + mi * 60.0 + s;
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

bool read_velocity_file(TableReader& env, std::string_view key, const Scene& scene, VelocitySeries& series) {
  const toml::table* t = env.table(key);
  if (!t) return false;
  TableReader r(*t, scene.source_path, "environment." + std::string(key));
  std::filesystem::path path = r.string("file", std::nullopt);
  const std::string u_name = r.string("u", "u"), v_name = r.string("v", "v");
  r.reject_unknown();
  const std::string extension = path.extension().string();
  if (extension != ".csv")
    r.fail("file", "'" + path.string() + "': allowed a time series in CSV (.csv)");
  if (path.is_relative()) path = std::filesystem::path(scene.source_path).parent_path() / path;
  const std::string name = path.string();
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
                                       "'" + cell + "' is not a number; allowed a finite number (" +
                                           (j == 0 ? "s from the run's start)" : "m/s)")));
    }
    if (!series.time.empty() && !(value[0] > series.time.back()))
      throw InputError(input_message(name, number, "time", "times must increase; allowed a value above " +
                                                               std::to_string(series.time.back()) + " s"));
    if (std::abs(value[1]) > 100.0 || std::abs(value[2]) > 100.0)
      throw InputError(input_message(name, number, std::abs(value[1]) > 100.0 ? u_name : v_name,
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
  return true;
}

}  // namespace floedem
