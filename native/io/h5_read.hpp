#pragma once
// Reading floedem's HDF5 files (io/*.cpp only: it includes H5Cpp.h). read_all and read_strings
// read files floedem has just written itself; CheckedFile reads files a user gives (a field
// file, a run's output as a field, a run to resume), checking each dataset and attribute before
// it is used, so that a damaged or foreign file is an InputError of one line, never a crash.
#include <H5Cpp.h>

#include <cstdint>
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

/// Every string of a 1-D dataset of UTF-8 strings, fixed-length (format 2, as the recorder
/// writes /bodies/name) or variable-length (format 1).
std::vector<std::string> read_strings(H5::H5File& f, const std::string& name);

/// A file given by the user, read with every check. Each failure throws InputError
/// "LABEL: WHAT: PROBLEM" (LABEL: the file's path). Shapes are given as extents, -1 for any.
class CheckedFile {
 public:
  CheckedFile(H5::H5File& file, std::string label) : file_(file), label_(std::move(label)) {}

  [[noreturn]] void fail(const std::string& what, const std::string& problem) const;
  /// True when the object (a group or dataset, absolute path) exists, its parents too.
  bool exists(const std::string& path) const;

  /// The root attribute format_version, which must be one this floedem reads
  /// (kOldestOutputFormatVersion to kOutputFormatVersion); returns it.
  std::int64_t check_format_version() const;
  /// A scalar string attribute of the root; empty when absent and !required. Of format 2 on,
  /// a variable-length one is refused unread (it would be read from the global heap).
  std::string text_attribute(const std::string& name, bool required) const;
  /// A string attribute of `object` (a group or dataset path); required.
  std::string text_attribute(const std::string& object, const std::string& name) const;
  /// A scalar numeric attribute of `object` (a group or dataset path).
  double real_attribute(const std::string& object, const std::string& name) const;
  std::int64_t integer_attribute(const std::string& object, const std::string& name) const;
  std::uint64_t unsigned_attribute(const std::string& object, const std::string& name) const;

  /// A float dataset of this shape, every value finite; its shape in `dims`.
  std::vector<double> reals(const std::string& name, const std::vector<std::int64_t>& shape, std::vector<hsize_t>& dims) const;
  /// Row `row` of a float dataset [rows, shape...], every value finite.
  std::vector<double> real_row(const std::string& name, const std::vector<std::int64_t>& shape, hsize_t row) const;
  /// An integer dataset of this shape, read as int64 (bytes: uint8).
  std::vector<std::int64_t> integers(const std::string& name, const std::vector<std::int64_t>& shape, std::vector<hsize_t>& dims) const;
  std::vector<std::uint8_t> bytes(const std::string& name, const std::vector<std::int64_t>& shape) const;
  /// A 1-D dataset of n strings.
  std::vector<std::string> strings(const std::string& name, std::int64_t n) const;

  /// The dataset, checked for its type class and shape (and that it stores what it claims),
  /// unread; its shape in `dims`.
  H5::DataSet dataset(const std::string& name, H5T_class_t type_class, const std::vector<std::int64_t>& shape,
                      std::vector<hsize_t>& dims) const;

  const std::string& label() const { return label_; }

 private:
  H5::Attribute scalar_attribute(const std::string& object, const std::string& name, H5T_class_t type_class) const;
  H5::H5File& file_;
  std::string label_;
  mutable std::int64_t format_ = 0;  // check_format_version's (0: not checked yet)
  // The file's format as far as its strings go: check_format_version's, else the root's
  // format_version where it is one integer, else this floedem's.
  std::int64_t string_format() const;
  bool fixed_strings() const { return string_format() >= 2; }
};

}  // namespace floedem
