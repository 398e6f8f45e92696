#pragma once
// Whole-dataset reads shared by floedem's HDF5 readers (io/*.cpp only: it includes H5Cpp.h).
#include <H5Cpp.h>

#include <string>
#include <vector>

namespace floedem {

/// Every value of dataset `name` as T, its shape in `dims`.
template <class T>
std::vector<T> read_all(H5::H5File& f, const std::string& name, const H5::DataType& type, std::vector<hsize_t>& dims) {
  H5::DataSet ds = f.openDataSet(name);
  H5::DataSpace space = ds.getSpace();
  dims.assign(static_cast<std::size_t>(space.getSimpleExtentNdims()), 0);
  space.getSimpleExtentDims(dims.data());
  hsize_t count = 1;
  for (const hsize_t d : dims) count *= d;
  std::vector<T> out(count);
  if (count > 0) ds.read(out.data(), type);
  return out;
}

}  // namespace floedem
