#include "io/body_frame.hpp"

#include <H5Cpp.h>

#include <filesystem>

#include "io/h5_read.hpp"
#include "scene/input_error.hpp"

namespace floedem {
namespace {

/// Rows [row, row + 1) of a dataset [T, rest...].
std::vector<double> read_row(H5::H5File& f, const std::string& name, hsize_t row, std::vector<hsize_t>& dims) {
  H5::DataSet ds = f.openDataSet(name);
  H5::DataSpace space = ds.getSpace();
  dims.assign(static_cast<std::size_t>(space.getSimpleExtentNdims()), 0);
  space.getSimpleExtentDims(dims.data());
  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  start[0] = row;
  count[0] = 1;
  hsize_t n = 1;
  for (std::size_t k = 1; k < dims.size(); ++k) n *= dims[k];
  std::vector<double> out(n);
  space.selectHyperslab(H5S_SELECT_SET, count.data(), start.data());
  H5::DataSpace memory(static_cast<int>(count.size()), count.data());
  ds.read(out.data(), H5::PredType::NATIVE_DOUBLE, memory, space);
  return out;
}

}  // namespace

BodyFrame read_body_frame(const std::string& path, std::int64_t frame) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path + ": cannot open: no such file");
  H5::Exception::dontPrint();
  std::string step = "open the file";
  try {
    H5::H5File f(path, H5F_ACC_RDONLY);
    step = "read the root attribute 'status'";
    std::string status;
    {
      H5::Attribute a = f.openGroup("/").openAttribute("status");
      a.read(a.getDataType(), status);
    }
    if (status != "complete")
      throw InputError(path + ": status is '" + status + "'; allowed only a complete file (the run that wrote it did not finish)");
    BodyFrame out;
    std::vector<hsize_t> dims;
    step = "read /bodies/polygon_offsets";
    const auto offsets = read_all<std::int64_t>(f, "/bodies/polygon_offsets", H5::PredType::NATIVE_INT64, dims);
    const std::size_t n = offsets.empty() ? 0 : offsets.size() - 1;
    step = "read /bodies/polygon_vertices";
    const auto vertices = read_all<double>(f, "/bodies/polygon_vertices", H5::PredType::NATIVE_DOUBLE, dims);
    step = "read /bodies/thickness";
    out.thickness = read_all<double>(f, "/bodies/thickness", H5::PredType::NATIVE_DOUBLE, dims);
    step = "read /bodies/density";
    out.density = read_all<double>(f, "/bodies/density", H5::PredType::NATIVE_DOUBLE, dims);
    step = "read /bodies/fixed";
    out.fixed = read_all<std::uint8_t>(f, "/bodies/fixed", H5::PredType::NATIVE_UINT8, dims);
    step = "read /bodies/name";
    out.names = read_strings(f, "/bodies/name");
    step = "read /time";
    const auto times = read_all<double>(f, "/time", H5::PredType::NATIVE_DOUBLE, dims);
    const auto frames = static_cast<std::int64_t>(times.size());
    const std::int64_t k = frame < 0 ? frames + frame : frame;
    if (k < 0 || k >= frames)
      throw InputError(path + ": frame " + std::to_string(frame) + " is out of range; the file has " +
                       std::to_string(frames) + " frames (allowed 0 to " + std::to_string(frames - 1) +
                       ", or -1 to -" + std::to_string(frames) + " from the end)");
    out.frame = k;
    out.time = times[static_cast<std::size_t>(k)];
    step = "read /bodies/position";
    const auto pos = read_row(f, "/bodies/position", static_cast<hsize_t>(k), dims);
    step = "read /bodies/angle";
    const auto ang = read_row(f, "/bodies/angle", static_cast<hsize_t>(k), dims);
    step = "read /bodies/velocity";
    const auto vel = read_row(f, "/bodies/velocity", static_cast<hsize_t>(k), dims);
    step = "read /bodies/angular_velocity";
    out.angular_velocity = read_row(f, "/bodies/angular_velocity", static_cast<hsize_t>(k), dims);
    if (out.names.size() != n || out.thickness.size() != n || out.density.size() != n || out.fixed.size() != n ||
        pos.size() != 2 * n ||
        ang.size() != n || vel.size() != 2 * n || out.angular_velocity.size() != n ||
        (n > 0 && static_cast<std::size_t>(offsets.back()) * 2 != vertices.size()))
      throw InputError(path + ": /bodies datasets disagree on the number of bodies or vertices; not a floedem file?");
    for (std::size_t i = 0; i < n; ++i) {
      const Transform x{{pos[2 * i], pos[2 * i + 1]}, Rot::from_angle(ang[i])};
      std::vector<Vec2> poly;
      for (auto v = offsets[i]; v < offsets[i + 1]; ++v)
        poly.push_back(x.apply({vertices[2 * static_cast<std::size_t>(v)], vertices[2 * static_cast<std::size_t>(v) + 1]}));
      out.polygons.push_back(std::move(poly));
      out.velocity.push_back({vel[2 * i], vel[2 * i + 1]});
    }
    return out;
  } catch (const H5::Exception& e) {
    throw InputError(path + ": cannot " + step + " (" + e.getDetailMsg() + "); not a floedem HDF5 file?");
  }
}

}  // namespace floedem
