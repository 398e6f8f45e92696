#include "io/netcdf_grid.hpp"

#include <netcdf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "floedem/scene/input_error.hpp"
#include "scene/calendar.hpp"

namespace floedem {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& field, const std::string& what) {
  throw InputError(input_message(path, 0, field, what));
}

std::string text_attribute(int nc, int var, const char* name) {
  std::size_t len = 0;
  nc_type type = NC_NAT;
  if (nc_inq_att(nc, var, name, &type, &len) != NC_NOERR || type != NC_CHAR) return "";
  std::string s(len, '\0');
  if (nc_get_att_text(nc, var, name, s.data()) != NC_NOERR) return "";
  while (!s.empty() && (s.back() == '\0' || s.back() == ' ')) s.pop_back();
  return s;
}

bool number_attribute(int nc, int var, const char* name, double& out) {
  std::size_t len = 0;
  nc_type type = NC_NAT;
  if (nc_inq_att(nc, var, name, &type, &len) != NC_NOERR || type == NC_CHAR || type == NC_STRING || len < 1)
    return false;
  std::vector<double> values(len);
  if (nc_get_att_double(nc, var, name, values.data()) != NC_NOERR) return false;
  out = values[0];
  return true;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// CF (UDUNITS) spellings of m/s and of m.
bool is_velocity_unit(const std::string& u) {
  static const char* kOk[] = {"m s-1", "m/s", "m s^-1", "m.s-1", "m s**-1", "meter second-1", "meters second-1",
                              "metre second-1", "metres second-1", "meters/second", "metres/second", "m sec-1"};
  const std::string l = lower(u);
  return std::any_of(std::begin(kOk), std::end(kOk), [&](const char* k) { return l == k; });
}

bool is_length_unit(const std::string& u) {
  const std::string l = lower(u);
  return l == "m" || l == "meter" || l == "meters" || l == "metre" || l == "metres";
}

bool is_geographic_unit(const std::string& u) {
  const std::string l = lower(u);
  return l.rfind("degree", 0) == 0;
}

// CF's spellings of longitude and latitude units (CF conventions 4.1 and 4.2).
bool is_longitude_unit(const std::string& u) {
  const std::string l = lower(u);
  return l == "degrees_east" || l == "degree_east" || l == "degree_e" || l == "degrees_e" || l == "degreee" ||
         l == "degreese";
}
bool is_latitude_unit(const std::string& u) {
  const std::string l = lower(u);
  return l == "degrees_north" || l == "degree_north" || l == "degree_n" || l == "degrees_n" || l == "degreen" ||
         l == "degreesn";
}

/// "<unit> since <instant>" as (seconds per unit, instant in s since 1970), or false.
bool parse_time_units(const std::string& units, double& per_unit, double& epoch) {
  const std::string l = lower(units);
  const std::size_t at = l.find(" since ");
  if (at == std::string::npos) return false;
  const std::string unit = l.substr(0, at);
  if (unit == "seconds" || unit == "second" || unit == "s" || unit == "sec" || unit == "secs")
    per_unit = 1.0;
  else if (unit == "minutes" || unit == "minute" || unit == "min" || unit == "mins")
    per_unit = 60.0;
  else if (unit == "hours" || unit == "hour" || unit == "h" || unit == "hr" || unit == "hrs")
    per_unit = 3600.0;
  else if (unit == "days" || unit == "day" || unit == "d")
    per_unit = 86400.0;
  else
    return false;
  const std::string when = units.substr(at + 7);
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, used = 0;
  double s = 0.0;
  if (std::sscanf(when.c_str(), "%d-%d-%d%n", &y, &mo, &d, &used) != 3) return false;
  std::string rest = when.substr(static_cast<std::size_t>(used));
  if (!rest.empty() && (rest[0] == 'T' || rest[0] == ' ')) {
    int more = 0;
    const int got = std::sscanf(rest.c_str() + 1, "%d:%d%n", &h, &mi, &more);
    if (got == 2) {
      rest = rest.substr(static_cast<std::size_t>(1 + more));
      if (!rest.empty() && rest[0] == ':') {
        int sec_used = 0;
        if (std::sscanf(rest.c_str() + 1, "%lf%n", &s, &sec_used) != 1) return false;
        rest = rest.substr(static_cast<std::size_t>(1 + sec_used));
      }
    }
  }
  while (!rest.empty() && rest[0] == ' ') rest.erase(0, 1);
  // CF's default is UTC; an offset other than zero is not read.
  if (!(rest.empty() || rest == "Z" || rest == "UTC" || rest == "+00:00" || rest == "+0000" || rest == "+00" ||
        rest == "0:00" || rest == "00:00"))
    return false;
  if (!valid_instant(y, mo, d, h, mi, s)) return false;
  epoch = unix_seconds(y, mo, d, h, mi, s);
  return true;
}

std::string range_text(const std::vector<double>& a) {
  std::ostringstream o;
  o << "[" << a.front() << ", " << a.back() << "]";
  return o.str();
}

struct Axis {
  std::string name;
  std::vector<double> values;
  std::string units;
  int var = -1;
};

Axis read_axis(int nc, int dim, const std::string& path, const std::string& variable) {
  char name[NC_MAX_NAME + 1] = {};
  std::size_t len = 0;
  nc_inq_dim(nc, dim, name, &len);
  Axis a;
  a.name = name;
  if (nc_inq_varid(nc, name, &a.var) != NC_NOERR)
    fail(path, a.name, "dimension of " + variable + " without a coordinate variable; allowed dimensions that " +
                           "have one (CF: a variable of the dimension's name)");
  int ndims = 0;
  nc_inq_varndims(nc, a.var, &ndims);
  if (ndims != 1) fail(path, a.name, "coordinate variable of " + std::to_string(ndims) + " dimensions; allowed 1");
  // CF's coordinate variable lies over the dimension it names: one over another dimension would be read
  // past the values sized for this one.
  int own = -1;
  nc_inq_vardimid(nc, a.var, &own);
  if (own != dim)
    fail(path, a.name, "coordinate variable over another dimension; allowed one over its own dimension '" + a.name + "'");
  a.values.resize(len);
  if (len > 0 && nc_get_var_double(nc, a.var, a.values.data()) != NC_NOERR)
    fail(path, a.name, "cannot read the coordinate variable");
  for (double v : a.values)
    if (!std::isfinite(v)) fail(path, a.name, "a coordinate is not finite; allowed finite coordinates");
  for (std::size_t k = 1; k < a.values.size(); ++k)
    if (!(a.values[k] > a.values[k - 1])) fail(path, a.name, "coordinates must increase (at index " + std::to_string(k) + ")");
  a.units = text_attribute(nc, a.var, "units");
  return a;
}

}  // namespace

FlowGridSpec inspect_flow_grid(const std::string& path, const std::string& u, const std::string& v,
                               const RunSettings& run, const GeoSpec& geo) {
  int nc = -1;
  if (const int e = nc_open(path.c_str(), NC_NOWRITE, &nc); e != NC_NOERR)
    fail(path, "file", std::string("cannot open as NetCDF: ") + nc_strerror(e));
  struct Closer {
    int nc;
    ~Closer() { nc_close(nc); }
  } closer{nc};
  FlowGridSpec spec;
  spec.file = path;
  spec.u = u;
  spec.v = v;
  int ids[2] = {-1, -1};
  int dims[2][NC_MAX_VAR_DIMS] = {};
  int ndims[2] = {0, 0};
  const std::string names[2] = {u, v};
  for (int c = 0; c < 2; ++c) {
    if (nc_inq_varid(nc, names[c].c_str(), &ids[c]) != NC_NOERR)
      fail(path, names[c], "no such variable; allowed the name of the file's variable (the scenario's u and v)");
    const std::string units = text_attribute(nc, ids[c], "units");
    if (!is_velocity_unit(units))
      fail(path, names[c] + ".units", "'" + printable(units) + "' is not a velocity; allowed m s-1 (or m/s)");
    nc_inq_varndims(nc, ids[c], &ndims[c]);
    if (ndims[c] != 3 && ndims[c] != 4)
      fail(path, names[c], std::to_string(ndims[c]) + " dimensions; allowed (time, y, x) or (time, depth, y, x)");
    nc_inq_vardimid(nc, ids[c], dims[c]);
  }
  if (ndims[0] != ndims[1] || !std::equal(dims[0], dims[0] + ndims[0], dims[1]))
    fail(path, v, "dimensions differ from " + u + "'s; allowed the same grid for both components");
  const int n = ndims[0];
  const Axis time = read_axis(nc, dims[0][0], path, u);
  const Axis x = read_axis(nc, dims[0][n - 1], path, u);
  const Axis y = read_axis(nc, dims[0][n - 2], path, u);
  // Time: against the run's start.
  double per_unit = 0.0, epoch = 0.0;
  if (!parse_time_units(time.units, per_unit, epoch))
    fail(path, time.name + ".units", "'" + printable(time.units) + "' is not a time axis; allowed \"<seconds|minutes|hours|" +
                                         "days> since YYYY-MM-DD hh:mm:ss\" in UTC (the first dimension is time)");
  const std::string calendar = lower(text_attribute(nc, time.var, "calendar"));
  if (!(calendar.empty() || calendar == "standard" || calendar == "gregorian" || calendar == "proleptic_gregorian"))
    fail(path, time.name + ".calendar", "'" + printable(calendar) + "'; allowed standard, gregorian or proleptic_gregorian");
  if (run.start.empty())
    fail(path, time.name, "a dated time axis needs the run's start; allowed a scenario with [run] start");
  for (double t : time.values) spec.time.push_back(t * per_unit + (epoch - run.start_unix));
  if (spec.time.empty() || spec.time.front() > 0.0 || spec.time.back() < run.duration) {
    std::ostringstream o;
    o << (spec.time.empty() ? std::string("has no times") : "covers " + range_text(spec.time) + " s of the run")
      << "; allowed times from <= 0 to >= " << run.duration << " s after run.start " << run.start
      << " (the file must cover the run)";
    fail(path, time.name, o.str());
  }
  const bool lonlat = is_geographic_unit(x.units) || is_geographic_unit(y.units);
  for (const Axis* a : {&x, &y}) {
    if (lonlat && !geo.present)
      fail(path, a->name + ".units", "'" + printable(a->units) + "': longitude and latitude need a geographic scene ([geo]); " +
                                         "allowed x and y in m, the scene's own coordinates, without one");
    if (lonlat && a == &x && !is_longitude_unit(a->units))
      fail(path, a->name + ".units", "'" + printable(a->units) + "'; allowed degrees_east (the last dimension is longitude)");
    if (lonlat && a == &y && !is_latitude_unit(a->units))
      fail(path, a->name + ".units", "'" + printable(a->units) + "'; allowed degrees_north (the last but one is latitude)");
    if (!lonlat && !is_length_unit(a->units)) fail(path, a->name + ".units", "'" + printable(a->units) + "'; allowed m");
    if (a->values.size() < 2) fail(path, a->name, "fewer than 2 points; allowed a grid of at least 2 x 2");
  }
  if (lonlat) {  // the plane's lattice comes once the bodies are known (place_lonlat_grid)
    if (y.values.front() < -90.0 || y.values.back() > 90.0)
      fail(path, y.name, "latitudes " + range_text(y.values) + "; allowed [-90, 90]");
    if (x.values.back() - x.values.front() > 360.0)
      fail(path, x.name, "longitudes " + range_text(x.values) + " span more than 360 deg");
    spec.lon = x.values;
    spec.lat = y.values;
    spec.geo = geo;
  } else {
    spec.x = x.values;
    spec.y = y.values;
  }
  if (n == 4) {
    Axis z = read_axis(nc, dims[0][1], path, u);
    if (!is_length_unit(z.units)) fail(path, z.name + ".units", "'" + printable(z.units) + "'; allowed m (depth)");
    if (lower(text_attribute(nc, z.var, "positive")) == "up")
      fail(path, z.name + ".positive", "\"up\"; allowed a depth axis positive down (depths that increase downward)");
    spec.depth = z.values;
  }
  return spec;
}

NetcdfSlices::NetcdfSlices(const FlowGridSpec& spec) : spec_(spec) {
  if (spec.lonlat()) {
    // Where each node of the plane's lattice falls in the file's grid, and which way east and
    // north point there: PROJ five times a node, once for the run.
    const GeoProjection projection(spec.geo);
    const std::vector<double>& lon = spec.lon;
    const std::vector<double>& lat = spec.lat;
    nodes_.resize(spec.x.size() * spec.y.size());
    auto locate = [](const std::vector<double>& axis, double value, std::ptrdiff_t& index, double& weight) {
      if (!(value >= axis.front() && value <= axis.back())) return false;
      const auto k = std::upper_bound(axis.begin(), axis.end(), value) - axis.begin() - 1;
      index = std::clamp<std::ptrdiff_t>(k, 0, static_cast<std::ptrdiff_t>(axis.size()) - 2);
      weight = (value - axis[index]) / (axis[index + 1] - axis[index]);
      return true;
    };
    constexpr double kDelta = 1e-4;  // deg: about 11 m of latitude, for the directions
    for (std::size_t j = 0; j < spec.y.size(); ++j)
      for (std::size_t i = 0; i < spec.x.size(); ++i) {
        Node& n = nodes_[j * spec.x.size() + i];
        const LonLat at = projection.to_lonlat({spec.x[i], spec.y[j]});
        if (!std::isfinite(at.lat)) continue;
        double longitude = at.lon;
        if (longitude < lon.front() && longitude + 360.0 <= lon.back()) longitude += 360.0;
        if (longitude > lon.back() && longitude - 360.0 >= lon.front()) longitude -= 360.0;
        std::ptrdiff_t ci = 0, cj = 0;
        if (!locate(lon, longitude, ci, n.wx) || !locate(lat, at.lat, cj, n.wy)) continue;
        try {
          const double up = std::min(at.lat + kDelta, 90.0), down = std::max(at.lat - kDelta, -90.0);
          n.east = normalized(projection.to_plane({at.lon + kDelta, at.lat}) - projection.to_plane({at.lon - kDelta, at.lat}));
          n.north = normalized(projection.to_plane({at.lon, up}) - projection.to_plane({at.lon, down}));
        } catch (const InputError&) {
          continue;  // at the edge of the projection's domain: no value there
        }
        n.i = ci;
        n.j = cj;
      }
  }
  if (const int e = nc_open(spec.file.c_str(), NC_NOWRITE, &ncid_); e != NC_NOERR)
    fail(spec.file, "file", std::string("cannot open as NetCDF: ") + nc_strerror(e));
  for (auto [var, name] : {std::pair{&u_, &spec.u}, std::pair{&v_, &spec.v}}) {
    nc_inq_varid(ncid_, name->c_str(), &var->id);
    number_attribute(ncid_, var->id, "scale_factor", var->scale);
    number_attribute(ncid_, var->id, "add_offset", var->offset);
    double f = 0.0;
    nc_type type = NC_NAT;
    nc_inq_vartype(ncid_, var->id, &type);
    if (number_attribute(ncid_, var->id, "_FillValue", f))
      var->fill.push_back(f);
    else  // the library's default fill of the type (NetCDF User Guide, "Fill Values")
      var->fill.push_back(type == NC_FLOAT ? static_cast<double>(NC_FILL_FLOAT)
                          : type == NC_SHORT ? static_cast<double>(NC_FILL_SHORT)
                          : type == NC_INT   ? static_cast<double>(NC_FILL_INT)
                                             : NC_FILL_DOUBLE);
    if (number_attribute(ncid_, var->id, "missing_value", f)) var->fill.push_back(f);
  }
}

NetcdfSlices::~NetcdfSlices() {
  if (ncid_ >= 0) nc_close(ncid_);
}

void NetcdfSlices::read_one(const Variable& var, std::size_t k, std::vector<double>& out) const {
  const std::size_t nz = std::max<std::size_t>(1, spec_.depth.size());
  const std::size_t ny = spec_.lonlat() ? spec_.lat.size() : spec_.y.size();
  const std::size_t nx = spec_.lonlat() ? spec_.lon.size() : spec_.x.size();
  out.resize(nz * ny * nx);
  std::size_t start[4] = {k, 0, 0, 0}, count[4] = {1, nz, ny, nx};
  if (spec_.depth.empty()) count[1] = ny, count[2] = nx;
  if (const int e = nc_get_vara_double(ncid_, var.id, start, count, out.data()); e != NC_NOERR)
    fail(spec_.file, &var == &u_ ? spec_.u : spec_.v,
         "cannot read time slice " + std::to_string(k) + ": " + nc_strerror(e));
  for (double& x : out) {
    // A fill value is compared as stored (before unpacking), as CF defines it.
    const bool missing = !std::isfinite(x) || std::find(var.fill.begin(), var.fill.end(), x) != var.fill.end();
    x = missing ? std::nan("") : var.scale * x + var.offset;
    if (std::abs(x) > kMaxFlowComponent) {
      std::ostringstream value;
      value << x;
      fail(spec_.file, &var == &u_ ? spec_.u : spec_.v,
           value.str() + " m/s in time slice " + std::to_string(k) +
               " is not a wind or current speed; allowed [-100, 100] m/s or a fill value");
    }
  }
}

void NetcdfSlices::read(std::size_t k, std::vector<double>& u, std::vector<double>& v) const {
  if (!spec_.lonlat()) {
    read_one(u_, k, u);
    read_one(v_, k, v);
    return;
  }
  std::vector<double> east, north;  // the file's slice, [depth][lat][lon]
  read_one(u_, k, east);
  read_one(v_, k, north);
  const std::size_t nz = std::max<std::size_t>(1, spec_.depth.size()), nodes = nodes_.size();
  const std::size_t nlon = spec_.lon.size(), layer = nlon * spec_.lat.size();
  u.assign(nz * nodes, std::nan(""));
  v.assign(nz * nodes, std::nan(""));
  for (std::size_t z = 0; z < nz; ++z)
    for (std::size_t k2 = 0; k2 < nodes; ++k2) {
      const Node& n = nodes_[k2];
      if (n.i < 0) continue;
      const std::size_t c = z * layer + static_cast<std::size_t>(n.j) * nlon + static_cast<std::size_t>(n.i);
      // Bilinear in longitude and latitude, as FlowGrid is in x and y; a fill value at a corner
      // gives NaN, which the run reports where a body meets it.
      auto blend = [&](const std::vector<double>& a) {
        return (1.0 - n.wy) * ((1.0 - n.wx) * a[c] + n.wx * a[c + 1]) + n.wy * ((1.0 - n.wx) * a[c + nlon] + n.wx * a[c + nlon + 1]);
      };
      const double ue = blend(east), vn = blend(north);
      const Vec2 w = ue * n.east + vn * n.north;
      u[z * nodes + k2] = w.x;
      v[z * nodes + k2] = w.y;
    }
}

}  // namespace floedem
