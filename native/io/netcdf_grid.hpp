#pragma once
// A wind or current field from a CF-NetCDF file (docs/forcing.md): its axes checked when the
// scenario is loaded, its values read a time slice at a time while the run goes.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "floedem/scene/scene.hpp"

namespace floedem {

/// The axes of the variables u and v of `path` as a FlowGridSpec: dimensions (time, [depth],
/// y, x), each with its coordinate variable; x and y in m, or in a geographic scene longitude
/// and latitude (degrees_east, degrees_north: FlowGridSpec::lon, lat), depth in m (positive
/// down), time in "<unit> since <instant>" read against run.start. InputError, naming the
/// file, the variable or attribute and what was expected, for anything else and for a time
/// axis that does not cover [0, run.duration].
FlowGridSpec inspect_flow_grid(const std::string& path, const std::string& u, const std::string& v,
                               const RunSettings& run, const GeoSpec& geo);

/// The values of one time slice at a time, in m/s, layout [depth][y][x] of the spec's x and y,
/// NaN where the file holds a fill value. A grid on longitude and latitude is resampled onto
/// the plane's lattice (FlowGridSpec::x, y): bilinear in longitude and latitude at each node,
/// its east and north components turned onto the plane's axes there (NaN at a node off the
/// file's grid).
class NetcdfSlices {
 public:
  explicit NetcdfSlices(const FlowGridSpec& spec);
  ~NetcdfSlices();
  NetcdfSlices(const NetcdfSlices&) = delete;
  NetcdfSlices& operator=(const NetcdfSlices&) = delete;
  void read(std::size_t k, std::vector<double>& u, std::vector<double>& v) const;

 private:
  struct Variable {
    int id = -1;
    double scale = 1.0, offset = 0.0;  // packing: value = scale * raw + offset
    std::vector<double> fill;          // raw values that mean "no data"
  };
  void read_one(const Variable& var, std::size_t k, std::vector<double>& out) const;
  /// A lattice node of a grid on longitude and latitude: the file's cell that holds it (i, j
  /// of its lower-left corner; i < 0 off the grid), the weights within it, and the plane's unit
  /// vectors of east and north there.
  struct Node {
    std::ptrdiff_t i = -1, j = -1;
    double wx = 0.0, wy = 0.0;
    Vec2 east, north;
  };
  const FlowGridSpec& spec_;
  std::vector<Node> nodes_;
  int ncid_ = -1;
  Variable u_, v_;
};

}  // namespace floedem
