#pragma once
// A wind or current field from a CF-NetCDF file (docs/forcing.md): its axes checked when the
// scenario is loaded, its values read a time slice at a time while the run goes.
#include <cstddef>
#include <string>
#include <vector>

#include "floedem/scene/scene.hpp"

namespace floedem {

/// The axes of the variables u and v of `path` as a FlowGridSpec: dimensions (time, [depth],
/// y, x), each with its coordinate variable; x and y in m, depth in m (positive down, or
/// `positive = "up"`), time in "<unit> since <instant>" read against run.start. InputError,
/// naming the file, the variable or attribute and what was expected, for anything else and
/// for a time axis that does not cover [0, run.duration].
FlowGridSpec inspect_flow_grid(const std::string& path, const std::string& u, const std::string& v,
                               const RunSettings& run);

/// The values of one time slice at a time, in m/s, layout [depth][y][x], NaN where the file
/// holds a fill value.
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
  const FlowGridSpec& spec_;
  int ncid_ = -1;
  Variable u_, v_;
};

}  // namespace floedem
