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

/// Every string of a 1-D dataset of variable-length UTF-8 strings (as the recorder writes
/// /bodies/name).
inline std::vector<std::string> read_strings(H5::H5File& f, const std::string& name) {
  H5::DataSet ds = f.openDataSet(name);
  const auto n = static_cast<std::size_t>(ds.getSpace().getSimpleExtentNpoints());
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  std::vector<char*> raw(n, nullptr);
  if (n > 0) ds.read(raw.data(), type);
  std::vector<std::string> out;
  for (char* s : raw) out.emplace_back(s ? s : "");
  if (n > 0) H5Dvlen_reclaim(type.getId(), ds.getSpace().getId(), H5P_DEFAULT, raw.data());
  return out;
}

}  // namespace floedem
