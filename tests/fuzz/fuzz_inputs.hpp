#pragma once
// What fuzz_inputs.cpp and make_input_seeds.cpp share: the kinds of input, the file each is
// written to and the scenario that names it.
#include <netcdf.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace floedem::fuzz {

/// The first byte of an input, modulo kKinds.
enum class InputKind { kPlaneGrid = 0, kLonLatGrid = 1, kRecord = 2, kChart = 3, kShapefile = 4 };
inline constexpr int kKinds = 5;
/// Forcing files and charts of a few kB hold every structure the readers check.
inline constexpr std::size_t kMaxInput = 1 << 16;

inline const char* file_name(InputKind kind) {
  switch (kind) {
    case InputKind::kPlaneGrid: return "current.nc";
    case InputKind::kLonLatGrid: return "lonlat.nc";
    case InputKind::kRecord: return "wind.csv";
    case InputKind::kChart: return "chart.geojson";
    case InputKind::kShapefile: return "chart.shp";
  }
  return "";
}

/// A shapefile chart is four files; an input of that kind holds them in turn, after the
/// lengths of the first three (16-bit, little-endian): .shp, .shx, .dbf, and the rest .prj
/// (none where it is empty). Lengths beyond the input are cut to what there is.
inline constexpr const char* kShapefileParts[4] = {".shp", ".shx", ".dbf", ".prj"};

inline std::vector<std::string> split_shapefile(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> parts(4);
  std::size_t at = std::min<std::size_t>(size, 6);
  for (int k = 0; k < 3; ++k) {
    const std::size_t want = 2 * static_cast<std::size_t>(k) + 1 < size
                                 ? static_cast<std::size_t>(data[2 * k]) | static_cast<std::size_t>(data[2 * k + 1]) << 8
                                 : 0;
    const std::size_t n = std::min(want, size - at);
    parts[static_cast<std::size_t>(k)].assign(reinterpret_cast<const char*>(data + at), n);
    at += n;
  }
  parts[3].assign(reinterpret_cast<const char*>(data + at), size - at);
  return parts;
}

inline std::string join_shapefile(const std::vector<std::string>& parts) {
  std::string out;
  for (int k = 0; k < 3; ++k) {
    const std::size_t n = parts[static_cast<std::size_t>(k)].size();
    out += static_cast<char>(n & 0xff);
    out += static_cast<char>(n >> 8);
  }
  for (const std::string& p : parts) out += p;
  return out;
}

/// A floe of 10 m in an hour's run from 2024-03-01, at (20 E, 70 N) where the kind is
/// geographic. The grids: variables uo and vo over (time, [depth], y, x), times in hours since
/// the start; the record: columns time, u and v; a chart (GeoJSON or shapefile): the field of a 400 m by 240 m
/// domain about the floe (small, so that a chart of small floes fills it with a few dozen).
inline std::string scene_text(InputKind kind, const std::string& file) {
  std::string s = "[run]\nstart = \"2024-03-01T00:00:00Z\"\nduration = 3600.0\ndt = 60.0\nseed = 3\n";
  if (kind != InputKind::kPlaneGrid && kind != InputKind::kRecord) s += "[geo]\norigin = [20.0, 70.0]\n";
  switch (kind) {
    case InputKind::kPlaneGrid:
    case InputKind::kLonLatGrid:
      s += "[environment]\n[environment.current_file]\nfile = \"" + file + "\"\nu = \"uo\"\nv = \"vo\"\n";
      break;
    case InputKind::kRecord:
      s += "[environment]\n[environment.wind_file]\nfile = \"" + file + "\"\n";
      break;
    case InputKind::kChart:
    case InputKind::kShapefile:
      s += "[field]\nchart = \"" + file + "\"\norigin = [-200.0, -120.0]\nwidth = 400.0\nheight = 240.0\nalpha = 2.0\n";
      break;
  }
  return s + "[[body]]\nname = \"floe\"\npolygon = [[-5.0, -5.0], [5.0, -5.0], [5.0, 5.0], [-5.0, 5.0]]\nthickness = 1.0\n";
}

/// A CF-NetCDF grid as the fuzzer describes it: what a writer of forcing files controls (the
/// axes, their units and values, the variables' type, packing, fill values and shape, the
/// coordinate variables' own dimensions) written by netCDF-C itself, then damaged as files are
/// (cut short; bytes of the data section changed). The header that netCDF-C decodes is left
/// whole: byte-mutated, netCDF-C 4.9's classic reader sizes its buffers from the header's
/// counts before checking them against the file (calloc of 4 and 11 GB from a 700-byte file
/// within seconds of fuzzing), a memory spike in netCDF-C that no reader of it can prevent.
struct GridDescription {
  enum Flag : std::uint16_t {
    kCdf2 = 1,              ///< 64-bit offsets (CDF-2), else CDF-1
    kDepth = 2,             ///< a depth axis: (time, depth, y, x)
    kPacked = 4,            ///< shorts with scale_factor and add_offset
    kDouble = 8,            ///< doubles (unpacked), else floats
    kNoFill = 16,           ///< no _FillValue attribute (the type's default fill applies)
    kMissingValue = 32,     ///< a missing_value attribute besides
    kVOtherShape = 64,      ///< vo over (time, x, y): not u's grid
    kVMissing = 128,        ///< no variable vo
    kXOnOtherDim = 256,     ///< the coordinate variable x defined over the time dimension
    kNoYCoordinate = 512,   ///< no coordinate variable y
    kCalendar = 1024,       ///< a calendar attribute on time
    kPositiveUp = 2048,     ///< depth.positive = "up"
    kUTwoDims = 4096,       ///< uo over (y, x) alone
  };
  std::uint16_t flags = 0;
  std::vector<double> x, y, time, depth;
  std::string x_units = "m", y_units = "m", time_units = "hours since 2024-03-01 00:00:00", velocity_units = "m s-1",
              calendar = "standard";
  double fill = -999.0, missing = -998.0, scale = 0.001, offset = 0.05;
  std::vector<double> u, v;  ///< the variables' stored values, cell by cell (shorts when packed), cycled
  std::uint32_t keep = 0;    ///< bytes kept of the file; 0: all
  std::vector<std::pair<std::uint32_t, std::uint8_t>> flips;  ///< (offset into the data section, xor)
};

/// The bytes of a description and back (fuzz_inputs reads them, make_input_seeds writes them):
/// flags, the axes' sizes and values, the units, the attributes' values, the variables' values,
/// the damage. Where the bytes run out, what is left is zero or empty.
class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  template <class T>
  T take() {
    T value{};
    const std::size_t n = std::min(sizeof(T), size_ - at_);
    std::memcpy(&value, data_ + at_, n);
    at_ += n;
    return value;
  }
  std::string text() {
    const std::size_t n = std::min<std::size_t>(take<std::uint8_t>(), size_ - at_);
    std::string s(reinterpret_cast<const char*>(data_ + at_), n);
    at_ += n;
    return s;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_, at_ = 0;
};

inline GridDescription decode(const std::uint8_t* data, std::size_t size) {
  Bytes in(data, size);
  GridDescription g;
  g.flags = in.take<std::uint16_t>();
  // At most 6 points an axis (4 depths): every check sees a grid of that size as of any other.
  const std::size_t n[4] = {in.take<std::uint8_t>() % 7u, in.take<std::uint8_t>() % 7u, in.take<std::uint8_t>() % 7u,
                            in.take<std::uint8_t>() % 5u};
  for (auto [axis, count] : {std::pair{&g.x, n[0]}, std::pair{&g.y, n[1]}, std::pair{&g.time, n[2]}, std::pair{&g.depth, n[3]}})
    for (std::size_t k = 0; k < count; ++k) axis->push_back(in.take<double>());
  for (std::string* t : {&g.x_units, &g.y_units, &g.time_units, &g.velocity_units, &g.calendar}) *t = in.text();
  for (double* d : {&g.fill, &g.missing, &g.scale, &g.offset}) *d = in.take<double>();
  for (std::vector<double>* values : {&g.u, &g.v}) {
    const std::size_t count = in.take<std::uint8_t>();
    for (std::size_t k = 0; k < count; ++k) values->push_back(in.take<double>());
  }
  g.keep = in.take<std::uint32_t>();
  const std::size_t flips = in.take<std::uint8_t>() % 16u;
  for (std::size_t k = 0; k < flips; ++k) g.flips.emplace_back(in.take<std::uint32_t>(), in.take<std::uint8_t>());
  return g;
}

inline std::string encode(const GridDescription& g) {
  std::string out;
  auto put = [&](auto value) { out.append(reinterpret_cast<const char*>(&value), sizeof(value)); };
  auto text = [&](const std::string& t) {
    put(static_cast<std::uint8_t>(t.size()));
    out += t;
  };
  put(g.flags);
  for (const std::vector<double>* axis : {&g.x, &g.y, &g.time, &g.depth}) put(static_cast<std::uint8_t>(axis->size()));
  for (const std::vector<double>* axis : {&g.x, &g.y, &g.time, &g.depth})
    for (double d : *axis) put(d);
  for (const std::string* t : {&g.x_units, &g.y_units, &g.time_units, &g.velocity_units, &g.calendar}) text(*t);
  for (double d : {g.fill, g.missing, g.scale, g.offset}) put(d);
  for (const std::vector<double>* values : {&g.u, &g.v}) {
    put(static_cast<std::uint8_t>(values->size()));
    for (double d : *values) put(d);
  }
  put(g.keep);
  put(static_cast<std::uint8_t>(g.flips.size()));
  for (auto [at, bits] : g.flips) {
    put(at);
    put(bits);
  }
  return out;
}

/// Writes the grid with netCDF-C, then cuts and changes it as described. False where netCDF-C
/// refuses the description itself (a name it does not take): no file for floedem to read.
inline bool write_grid(const std::filesystem::path& path, const GridDescription& g) {
  using F = GridDescription;
  int nc = -1;
  if (nc_create(path.c_str(), NC_CLOBBER | ((g.flags & F::kCdf2) ? NC_64BIT_OFFSET : 0), &nc) != NC_NOERR) return false;
  bool ok = true;
  std::size_t data_bytes = 0;
  auto type_size = [](nc_type t) { return t == NC_SHORT ? 2u : t == NC_FLOAT ? 4u : 8u; };
  auto add = [&](std::size_t cells, nc_type t) { data_bytes += (cells * type_size(t) + 3) / 4 * 4; };
  // A value out of the type's range is stored as netCDF-C converts it (NC_ERANGE is not an
  // error of the file).
  auto fine = [](int e) { return e == NC_NOERR || e == NC_ERANGE; };
  auto text = [&](int var, const char* name, const std::string& value) {
    ok = ok && nc_put_att_text(nc, var, name, value.size(), value.c_str()) == NC_NOERR;
  };
  const bool z = (g.flags & F::kDepth) != 0;
  int dt = -1, dz = -1, dy = -1, dx = -1;
  ok = ok && nc_def_dim(nc, "time", g.time.size(), &dt) == NC_NOERR && nc_def_dim(nc, "y", g.y.size(), &dy) == NC_NOERR &&
       nc_def_dim(nc, "x", g.x.size(), &dx) == NC_NOERR && (!z || nc_def_dim(nc, "depth", g.depth.size(), &dz) == NC_NOERR);
  if (!ok) return nc_close(nc), false;
  struct Coordinate {
    const char* name;
    int dim;
    const std::vector<double>* values;
    const std::string* units;
    int var = -1;
  };
  const std::string depth_units = "m";
  std::vector<Coordinate> coordinates = {{"time", dt, &g.time, &g.time_units},
                                         {"x", (g.flags & F::kXOnOtherDim) ? dt : dx,
                                          (g.flags & F::kXOnOtherDim) ? &g.time : &g.x, &g.x_units}};
  if (!(g.flags & F::kNoYCoordinate)) coordinates.push_back({"y", dy, &g.y, &g.y_units});
  if (z) coordinates.push_back({"depth", dz, &g.depth, &depth_units});
  for (Coordinate& c : coordinates) {
    ok = ok && nc_def_var(nc, c.name, NC_DOUBLE, 1, &c.dim, &c.var) == NC_NOERR;
    if (ok) text(c.var, "units", *c.units);
    add(c.values->size(), NC_DOUBLE);
  }
  if (ok && (g.flags & F::kCalendar)) text(coordinates[0].var, "calendar", g.calendar);
  if (ok && z && (g.flags & F::kPositiveUp)) text(coordinates.back().var, "positive", "up");
  const nc_type type = (g.flags & F::kPacked) ? NC_SHORT : (g.flags & F::kDouble) ? NC_DOUBLE : NC_FLOAT;
  std::vector<int> u_dims = {dt};
  if (z) u_dims.push_back(dz);
  u_dims.push_back(dy);
  u_dims.push_back(dx);
  if (g.flags & F::kUTwoDims) u_dims = {dy, dx};
  std::vector<int> v_dims = u_dims;
  if (g.flags & F::kVOtherShape) std::swap(v_dims[v_dims.size() - 1], v_dims[v_dims.size() - 2]);
  struct Variable {
    const char* name;
    std::vector<int> dims;
    const std::vector<double>* values;
    int var = -1;
    std::size_t cells = 1;
  };
  std::vector<Variable> variables = {{"uo", u_dims, &g.u}};
  if (!(g.flags & F::kVMissing)) variables.push_back({"vo", v_dims, &g.v});
  for (Variable& v : variables) {
    if (!ok) break;
    ok = nc_def_var(nc, v.name, type, static_cast<int>(v.dims.size()), v.dims.data(), &v.var) == NC_NOERR;
    for (int d : v.dims) {
      std::size_t len = 0;
      nc_inq_dimlen(nc, d, &len);
      v.cells *= len;
    }
    add(v.cells, type);
    if (!ok) break;
    text(v.var, "units", g.velocity_units);
    if (!(g.flags & F::kNoFill)) ok = ok && fine(nc_put_att_double(nc, v.var, "_FillValue", type, 1, &g.fill));
    if (g.flags & F::kMissingValue) ok = ok && fine(nc_put_att_double(nc, v.var, "missing_value", type, 1, &g.missing));
    if (type == NC_SHORT) {
      ok = ok && nc_put_att_double(nc, v.var, "scale_factor", NC_DOUBLE, 1, &g.scale) == NC_NOERR;
      ok = ok && nc_put_att_double(nc, v.var, "add_offset", NC_DOUBLE, 1, &g.offset) == NC_NOERR;
    }
  }
  ok = ok && nc_enddef(nc) == NC_NOERR;
  for (const Coordinate& c : coordinates)
    if (ok && !c.values->empty()) ok = nc_put_var_double(nc, c.var, c.values->data()) == NC_NOERR;
  for (const Variable& v : variables) {
    if (!ok || v.cells == 0) continue;
    std::vector<double> cells(v.cells, 0.1);
    for (std::size_t k = 0; k < cells.size() && !v.values->empty(); ++k) cells[k] = (*v.values)[k % v.values->size()];
    ok = fine(nc_put_var_double(nc, v.var, cells.data()));
  }
  if (nc_close(nc) != NC_NOERR || !ok) return false;
  // The damage: bytes of the data section (the file's last data_bytes) changed, the file cut.
  const auto size = static_cast<std::size_t>(std::filesystem::file_size(path));
  if (!g.flips.empty() && data_bytes > 0 && data_bytes <= size) {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    for (auto [at, bits] : g.flips) {
      const auto where = static_cast<std::streamoff>(size - data_bytes + at % data_bytes);
      char byte = 0;
      f.seekg(where);
      f.get(byte);
      f.seekp(where);
      f.put(static_cast<char>(byte ^ static_cast<char>(bits)));
    }
  }
  if (g.keep > 0 && g.keep < size) std::filesystem::resize_file(path, g.keep);
  return true;
}

}  // namespace floedem::fuzz
