#pragma once
// Everything in an HDF5 file, object by object, for the tests that hold a resumed or faulted
// run to the uninterrupted run's file, every dataset and attribute to the bit.
#include <catch2/catch.hpp>

#include <hdf5.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace floedem::test {

/// Everything in a file, object by object: each dataset's shape and values and each
/// attribute's value, as bytes (variable-length strings as their text).
using Contents = std::map<std::string, std::string>;

inline std::string read_values(hid_t obj, hid_t type, hid_t space, bool attribute) {
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  if (rank > 0) H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  std::string out = "shape";
  for (const hsize_t d : dims) out += " " + std::to_string(d);
  out += ":";
  if (H5Tis_variable_str(type) > 0) {
    std::vector<char*> strings(static_cast<std::size_t>(n));
    hid_t mem = H5Tcopy(H5T_C_S1);
    H5Tset_size(mem, H5T_VARIABLE);
    H5Tset_cset(mem, H5Tget_cset(type));
    if (attribute)
      H5Aread(obj, mem, strings.data());
    else
      H5Dread(obj, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, strings.data());
    for (char* s : strings) out += std::string(s ? s : "") + '\0';
    H5Dvlen_reclaim(mem, space, H5P_DEFAULT, strings.data());
    H5Tclose(mem);
    return out;
  }
  std::string bytes(static_cast<std::size_t>(n) * H5Tget_size(type), '\0');
  if (!bytes.empty()) {
    if (attribute)
      H5Aread(obj, type, bytes.data());
    else
      H5Dread(obj, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data());
  }
  return out + bytes;
}

inline herr_t read_attribute(hid_t obj, const char* name, const H5A_info_t*, void* data) {
  auto& [contents, path] = *static_cast<std::pair<Contents*, std::string>*>(data);
  const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  const hid_t type = H5Aget_type(a), space = H5Aget_space(a);
  (*contents)[path + "@" + name] = read_values(a, type, space, true);
  H5Sclose(space);
  H5Tclose(type);
  H5Aclose(a);
  return 0;
}

inline herr_t read_object(hid_t file, const char* name, const H5O_info_t* info, void* data) {
  auto* contents = static_cast<Contents*>(data);
  const hid_t obj = H5Oopen(file, name, H5P_DEFAULT);
  const std::string path = std::string(name) == "." ? "/" : "/" + std::string(name);
  std::pair<Contents*, std::string> at{contents, path};
  H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, nullptr, read_attribute, &at);
  if (info->type == H5O_TYPE_DATASET) {
    const hid_t type = H5Dget_type(obj), space = H5Dget_space(obj);
    (*contents)[path] = read_values(obj, type, space, false);
    H5Sclose(space);
    H5Tclose(type);
  } else {
    (*contents)[path] = "group";
  }
  H5Oclose(obj);
  return 0;
}

inline Contents contents(const std::filesystem::path& file) {
  Contents out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  H5Ovisit(f, H5_INDEX_NAME, H5_ITER_INC, read_object, &out);
  H5Fclose(f);
  return out;
}

/// The names of the objects and attributes that differ (both ways).
inline std::vector<std::string> differences(const Contents& a, const Contents& b) {
  std::vector<std::string> out;
  for (const auto& [k, v] : a) {
    const auto it = b.find(k);
    if (it == b.end() || it->second != v) out.push_back(k);
  }
  for (const auto& [k, v] : b)
    if (!a.count(k)) out.push_back(k);
  return out;
}

/// Checks that `file` holds what `expected` does, naming the first object that differs.
inline void check_same_contents(const Contents& expected, const std::filesystem::path& file) {
  const auto diff = differences(expected, contents(file));
  INFO("differing: " << (diff.empty() ? std::string() : diff.front()));
  CHECK(diff.empty());
}

}  // namespace floedem::test
