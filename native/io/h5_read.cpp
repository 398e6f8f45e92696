#include "io/h5_read.hpp"

#include <algorithm>
#include <cmath>

#include "floedem/scene/input_error.hpp"
#include "floedem/version.hpp"

namespace floedem {

std::vector<std::string> read_strings(H5::H5File& f, const std::string& name) {
  H5::DataSet ds = f.openDataSet(name);
  const auto n = static_cast<std::size_t>(ds.getSpace().getSimpleExtentNpoints());
  if (!ds.getStrType().isVariableStr()) {
    // Fixed-length: n slots of `size` bytes each, a name NUL-padded (or NUL-terminated) in its slot.
    const std::size_t size = ds.getStrType().getSize();
    std::vector<char> raw(n * size);
    if (n > 0) ds.read(raw.data(), ds.getStrType());
    std::vector<std::string> out;
    for (std::size_t i = 0; i < n; ++i) {
      const char* s = raw.data() + i * size;
      out.emplace_back(s, std::find(s, s + size, '\0'));
    }
    return out;
  }
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  std::vector<char*> raw(n, nullptr);
  if (n > 0) ds.read(raw.data(), type);
  std::vector<std::string> out;
  for (char* s : raw) out.emplace_back(s ? s : "");
  if (n > 0) H5Dvlen_reclaim(type.getId(), ds.getSpace().getId(), H5P_DEFAULT, raw.data());
  return out;
}

namespace {

std::string shape_text(const std::vector<hsize_t>& dims) {
  std::string s = "[";
  for (std::size_t k = 0; k < dims.size(); ++k) s += (k ? ", " : "") + std::to_string(dims[k]);
  return s + "]";
}

std::string shape_text(const std::vector<std::int64_t>& shape) {
  std::string s = "[";
  for (std::size_t k = 0; k < shape.size(); ++k) s += (k ? ", " : "") + (shape[k] < 0 ? std::string("any") : std::to_string(shape[k]));
  return s + "]";
}

const char* class_text(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER: return "integers";
    case H5T_FLOAT: return "floating-point numbers";
    case H5T_STRING: return "strings";
    case H5T_ENUM: return "enumerated values";
    default: return "other values";
  }
}

}  // namespace

void CheckedFile::fail(const std::string& what, const std::string& problem) const {
  throw InputError(label_ + ": " + what + ": " + problem);
}

bool CheckedFile::exists(const std::string& path) const {
  // H5Lexists fails, rather than answering false, when a parent is missing: walk down.
  for (std::size_t at = path.find('/', 1);; at = path.find('/', at + 1)) {
    const std::string part = at == std::string::npos ? path : path.substr(0, at);
    if (H5Lexists(file_.getId(), part.c_str(), H5P_DEFAULT) <= 0) return false;
    if (at == std::string::npos) return true;
  }
}

H5::Attribute CheckedFile::scalar_attribute(const std::string& object, const std::string& name, H5T_class_t type_class) const {
  const std::string what = (object == "/" ? "/" : object + "/") + "@" + name;
  if (object != "/" && !exists(object)) fail(object, "missing; expected in every floedem file of this kind (docs/output.md)");
  const H5::H5Object* obj = nullptr;
  H5::Group group;
  H5::DataSet set;
  if (object == "/" || file_.childObjType(object) == H5O_TYPE_GROUP) {
    group = file_.openGroup(object);
    obj = &group;
  } else {
    set = file_.openDataSet(object);
    obj = &set;
  }
  if (!obj->attrExists(name)) fail(what, "attribute missing");
  H5::Attribute a = obj->openAttribute(name);
  if (a.getTypeClass() != type_class)
    fail(what, std::string("holds ") + class_text(a.getTypeClass()) + "; expected " + class_text(type_class));
  if (a.getSpace().getSimpleExtentNpoints() != 1) fail(what, "expected one value, found " + std::to_string(a.getSpace().getSimpleExtentNpoints()));
  return a;
}

std::int64_t CheckedFile::check_format_version() const {
  if (!H5::Group(file_.openGroup("/")).attrExists("format_version"))
    fail("/@format_version", "missing: not written by floedem, or by a floedem older than the format's first version; this floedem reads format " +
                                 std::to_string(kOutputFormatVersion));
  const std::int64_t format = integer_attribute("/", "format_version");
  if (format < kOldestOutputFormatVersion || format > kOutputFormatVersion)
    fail("/@format_version", "is " + std::to_string(format) + ", this floedem (" + version() + ") reads " +
                                 std::to_string(kOutputFormatVersion) +
                                 (format > kOutputFormatVersion ? ": a newer floedem wrote it" : ": an older floedem wrote it"));
  format_ = format;
  return format;
}

std::int64_t CheckedFile::string_format() const {
  if (format_ != 0) return format_;
  H5::Group root = file_.openGroup("/");
  if (root.attrExists("format_version")) {
    H5::Attribute a = root.openAttribute("format_version");
    std::int64_t v = 0;
    if (a.getTypeClass() == H5T_INTEGER && a.getSpace().getSimpleExtentNpoints() == 1) {
      a.read(H5::PredType::NATIVE_INT64, &v);
      if (v == 1) return 1;
    }
  }
  return kOutputFormatVersion;
}

std::string CheckedFile::text_attribute(const std::string& name, bool required) const {
  if (!required && !H5::Group(file_.openGroup("/")).attrExists(name)) return {};
  return text_attribute("/", name);
}

std::string CheckedFile::text_attribute(const std::string& object, const std::string& name) const {
  H5::Attribute a = scalar_attribute(object, name, H5T_STRING);
  const H5::StrType type = a.getStrType();
  const std::string where = object == "/" ? "/@" + name : object + "@" + name;
  if (fixed_strings() && type.isVariableStr())
    fail(where, "holds a variable-length string; format " + std::to_string(string_format()) +
                    " stores fixed-length ones: damaged, or not written by floedem");
  std::string v;
  a.read(type, v);
  return v;
}

double CheckedFile::real_attribute(const std::string& object, const std::string& name) const {
  H5::Attribute a = scalar_attribute(object, name, H5T_FLOAT);
  double v = 0.0;
  a.read(H5::PredType::NATIVE_DOUBLE, &v);
  if (!std::isfinite(v)) fail(object + "@" + name, "is not finite");
  return v;
}

std::int64_t CheckedFile::integer_attribute(const std::string& object, const std::string& name) const {
  H5::Attribute a = scalar_attribute(object, name, H5T_INTEGER);
  std::int64_t v = 0;
  a.read(H5::PredType::NATIVE_INT64, &v);
  return v;
}

std::uint64_t CheckedFile::unsigned_attribute(const std::string& object, const std::string& name) const {
  H5::Attribute a = scalar_attribute(object, name, H5T_INTEGER);
  std::uint64_t v = 0;
  a.read(H5::PredType::NATIVE_UINT64, &v);
  return v;
}

H5::DataSet CheckedFile::dataset(const std::string& name, H5T_class_t type_class, const std::vector<std::int64_t>& shape,
                              std::vector<hsize_t>& dims) const {
  if (!exists(name)) fail(name, "missing; expected in every floedem file of this kind (docs/output.md)");
  if (file_.childObjType(name) != H5O_TYPE_DATASET) fail(name, "is not a dataset");
  H5::DataSet ds = file_.openDataSet(name);
  if (ds.getTypeClass() != type_class)
    fail(name, std::string("holds ") + class_text(ds.getTypeClass()) + "; expected " + class_text(type_class));
  H5::DataSpace space = ds.getSpace();
  const int rank = space.getSimpleExtentNdims();
  dims.assign(static_cast<std::size_t>(std::max(rank, 0)), 0);
  if (rank > 0) space.getSimpleExtentDims(dims.data());
  bool fits = dims.size() == shape.size();
  for (std::size_t k = 0; fits && k < dims.size(); ++k) fits = shape[k] < 0 || dims[k] == static_cast<hsize_t>(shape[k]);
  if (!fits) fail(name, "has shape " + shape_text(dims) + "; expected " + shape_text(shape));
  // A damaged header may claim far more values than the file holds (they would read as fill
  // values, after an allocation of any size): the values must fit in what is stored, with room
  // for compression.
  long double bytes = static_cast<long double>(ds.getDataType().getSize());
  for (const hsize_t d : dims) bytes *= static_cast<long double>(d);
  const long double stored = static_cast<long double>(ds.getStorageSize());
  if (bytes > 64.0L * stored + 4096.0L)
    fail(name, "claims " + shape_text(dims) + " values but stores " + std::to_string(ds.getStorageSize()) + " bytes: damaged");
  return ds;
}

std::vector<double> CheckedFile::reals(const std::string& name, const std::vector<std::int64_t>& shape,
                                       std::vector<hsize_t>& dims) const {
  H5::DataSet ds = dataset(name, H5T_FLOAT, shape, dims);
  hsize_t count = 1;
  for (const hsize_t d : dims) count *= d;
  std::vector<double> out(count);
  if (count > 0) ds.read(out.data(), H5::PredType::NATIVE_DOUBLE);
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(out[i])) fail(name, "value " + std::to_string(i) + " is not finite; expected finite numbers");
  return out;
}

std::vector<double> CheckedFile::real_row(const std::string& name, const std::vector<std::int64_t>& shape, hsize_t row) const {
  std::vector<hsize_t> dims;
  H5::DataSet ds = dataset(name, H5T_FLOAT, shape, dims);
  if (dims.empty() || row >= dims[0]) fail(name, "has no row " + std::to_string(row));
  H5::DataSpace space = ds.getSpace();
  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  start[0] = row;
  count[0] = 1;
  hsize_t n = 1;
  for (std::size_t k = 1; k < dims.size(); ++k) n *= dims[k];
  std::vector<double> out(n);
  space.selectHyperslab(H5S_SELECT_SET, count.data(), start.data());
  H5::DataSpace memory(static_cast<int>(count.size()), count.data());
  if (n > 0) ds.read(out.data(), H5::PredType::NATIVE_DOUBLE, memory, space);
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(out[i]))
      fail(name, "row " + std::to_string(row) + ", value " + std::to_string(i) + " is not finite; expected finite numbers");
  return out;
}

std::vector<std::int64_t> CheckedFile::integers(const std::string& name, const std::vector<std::int64_t>& shape,
                                                std::vector<hsize_t>& dims) const {
  H5::DataSet ds = dataset(name, H5T_INTEGER, shape, dims);
  hsize_t count = 1;
  for (const hsize_t d : dims) count *= d;
  std::vector<std::int64_t> out(count);
  if (count > 0) ds.read(out.data(), H5::PredType::NATIVE_INT64);
  return out;
}

std::vector<std::uint8_t> CheckedFile::bytes(const std::string& name, const std::vector<std::int64_t>& shape) const {
  std::vector<hsize_t> dims;
  H5::DataSet ds = dataset(name, H5T_INTEGER, shape, dims);
  if (ds.getDataType().getSize() != 1) fail(name, "expected bytes (8-bit integers)");
  hsize_t count = 1;
  for (const hsize_t d : dims) count *= d;
  std::vector<std::uint8_t> out(count);
  if (count > 0) ds.read(out.data(), H5::PredType::NATIVE_UINT8);
  return out;
}

std::vector<std::string> CheckedFile::strings(const std::string& name, std::int64_t n) const {
  std::vector<hsize_t> dims;
  H5::DataSet ds = dataset(name, H5T_STRING, {n}, dims);
  if (ds.getStrType().isVariableStr() == fixed_strings())
    fail(name, fixed_strings() ? "holds variable-length strings; expected fixed-length ones (format 2)"
                               : "holds fixed-length strings; expected variable-length ones (format 1)");
  return read_strings(file_, name);
}

}  // namespace floedem
