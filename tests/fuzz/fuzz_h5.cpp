// libFuzzer target: floedem's readers of the files a user gives it (io/output.hpp: a field
// file, a run's output read as a field, a run to resume) on HDF5 file images held in memory
// through HDF5's file-image API (the core driver, no disk). Bad input must end in InputError;
// anything else escaping, a crash, a hang or a sanitizer report is a bug.
//
// The mutator takes one of two kinds of edit. Half the time it mutates the bytes of the
// datasets as stored in the image, contiguous or chunked (libFuzzer's own byte mutations,
// within each dataset's stored extent): numbers and strings as any damage leaves them, read by
// floedem's checks. These are bytes HDF5 hands back as data without parsing them: format 2's
// strings are fixed-length, stored in the dataset itself; format 1's were references into
// HDF5's global heap, and Debian's HDF5 1.10 reads a damaged global-heap object out of bounds
// within seconds. HDF5's own metadata (object headers, B-trees) is left to the other half:
// mutated byte by byte, Debian's HDF5 1.10.8 overflows a heap buffer decoding a damaged
// datatype message (H5T_copy under H5O_msg_read) within a few thousand inputs, a crash in HDF5
// that no reader can guard against. The other half is structure-aware: it opens the image with
// HDF5 and edits it through HDF5 (a value made NaN, infinite, negative, zero or huge; a dataset
// or attribute removed, or remade with another type or shape; a string changed), then hands
// back the image HDF5 writes. The seeds (tests/fuzz/corpus/h5, made by make_h5_corpus.sh) are
// real format 2 outputs and damaged ones.
#include <H5Cpp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "floedem/scene/input_error.hpp"
#include "io/output_reader.hpp"

namespace {

/// An image opened in memory; id < 0 when it is not HDF5.
hid_t open_image(const std::uint8_t* data, std::size_t size, unsigned flags) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_core(access, 1 << 16, 0);  // no backing file: nothing touches the disk
  H5Pset_file_image(access, const_cast<std::uint8_t*>(data), size);
  const hid_t id = H5Fopen("fuzz.h5", flags, access);
  H5Pclose(access);
  return id;
}

/// What the readers look at: datasets and attributes (object, attribute; "" for a dataset).
const char* const kDatasets[] = {
    "/bodies/polygon_offsets", "/bodies/polygon_vertices", "/bodies/thickness", "/bodies/density",
    "/bodies/fixed",           "/bodies/name",             "/bodies/mass",      "/time",
    "/bodies/position",        "/bodies/angle",            "/bodies/velocity",  "/bodies/angular_velocity",
    "/checkpoint/slot_a",      "/checkpoint/slot_b",       "/contacts/normal",  "/contacts/kind"};
const char* const kAttributes[][2] = {{"/", "format_version"},     {"/", "status"},   {"/", "duration"},
                                      {"/", "engine"},             {"/", "scenario"}, {"/", "overrides"},
                                      {"/checkpoint/slot_a", "step"}, {"/checkpoint/slot_a", "checksum"},
                                      {"/checkpoint/slot_b", "step"}, {"/", "floedem_version"}};

double special(std::mt19937_64& rng) {
  const double values[] = {std::nan(""), INFINITY, -INFINITY, -1.0, 0.0, 1e300, -5.0, 3.0, 1e8, 0.5};
  return values[rng() % std::size(values)];
}

bool exists(hid_t file, const std::string& path) {
  for (std::size_t at = path.find('/', 1);; at = path.find('/', at + 1)) {
    if (H5Lexists(file, (at == std::string::npos ? path : path.substr(0, at)).c_str(), H5P_DEFAULT) <= 0) return false;
    if (at == std::string::npos) return true;
  }
}

/// A new dataset of a random type class and small random shape, under `path`.
void remake(hid_t file, const std::string& path, std::mt19937_64& rng) {
  if (exists(file, path)) H5Ldelete(file, path.c_str(), H5P_DEFAULT);
  const int rank = static_cast<int>(rng() % 4);
  hsize_t dims[3] = {rng() % 6, rng() % 6, rng() % 3};
  hsize_t n = 1;
  for (int k = 0; k < rank; ++k) n *= dims[k];
  const hid_t space = rank == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(rank, dims, nullptr);
  const int kind = static_cast<int>(rng() % 4);
  const hid_t type = kind == 0 ? H5T_NATIVE_DOUBLE : kind == 1 ? H5T_NATIVE_INT64 : kind == 2 ? H5T_NATIVE_UINT8 : H5T_NATIVE_FLOAT;
  const hid_t set = H5Dcreate2(file, path.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (set >= 0) {
    std::vector<double> v(n);
    for (double& x : v) x = rng() % 3 == 0 ? special(rng) : static_cast<double>(static_cast<int>(rng() % 20) - 5);
    if (n > 0) H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(set);
  }
  H5Sclose(space);
}

/// One element of a numeric dataset set to a special value (converted to the dataset's type).
void poke(hid_t file, const std::string& path, std::mt19937_64& rng) {
  const hid_t set = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (set < 0) return;
  const hid_t space = H5Dget_space(set);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  const hid_t type = H5Dget_type(set);
  const H5T_class_t c = H5Tget_class(type);
  if (n > 0 && n < (1 << 22) && (c == H5T_FLOAT || c == H5T_INTEGER)) {
    std::vector<double> v(static_cast<std::size_t>(n));
    if (H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0) {
      const std::size_t at = rng() % v.size();
      v[at] = rng() % 2 ? special(rng) : v[at] + static_cast<double>(static_cast<int>(rng() % 7) - 3);
      H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    }
  }
  H5Tclose(type);
  H5Sclose(space);
  H5Dclose(set);
}

/// An attribute removed, or remade as a number, a string or an array.
void reattribute(hid_t file, const char* object, const char* name, std::mt19937_64& rng) {
  if (!exists(file, object) && std::strcmp(object, "/") != 0) return;
  const hid_t obj = H5Oopen(file, object, H5P_DEFAULT);
  if (obj < 0) return;
  if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
  const int kind = static_cast<int>(rng() % 5);
  if (kind > 0) {
    const hsize_t three = 3;
    const hid_t space = kind == 4 ? H5Screate_simple(1, &three, nullptr) : H5Screate(H5S_SCALAR);
    if (kind == 3) {
      const char* texts[] = {"complete", "running", "", "native", "[run]\nduration = 1\ndt = 0.1\n", "x"};
      const char* text = texts[rng() % std::size(texts)];
      // Fixed-length, as format 2 writes them (a scalar of the text's length; an array of three).
      const hid_t type = H5Tcopy(H5T_C_S1);
      H5Tset_size(type, std::max<std::size_t>(1, std::strlen(text)));
      H5Tset_strpad(type, H5T_STR_NULLPAD);
      const hid_t a = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
      if (a >= 0) {
        std::string values(3 * H5Tget_size(type), '\0');
        for (std::size_t k = 0; k < 3; ++k) std::memcpy(&values[k * H5Tget_size(type)], text, std::strlen(text));
        H5Awrite(a, type, values.data());
        H5Aclose(a);
      }
      H5Tclose(type);
    } else {
      const double v[3] = {special(rng), special(rng), static_cast<double>(rng() % 4)};
      const hid_t type = kind == 1 ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE;
      const hid_t a = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
      if (a >= 0) {
        H5Awrite(a, H5T_NATIVE_DOUBLE, v);
        H5Aclose(a);
      }
    }
    H5Sclose(space);
  }
  H5Oclose(obj);
}

}  // namespace

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace {

/// The byte ranges of the image that hold datasets' stored values: each contiguous dataset's
/// extent and each chunk of a chunked one, of the datasets the readers look at.
std::vector<std::pair<std::size_t, std::size_t>> stored_extents(hid_t file, std::size_t size) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  auto keep = [&](haddr_t at, hsize_t n) {
    if (at != HADDR_UNDEF && n > 0 && at < size && n <= size - at)
      out.emplace_back(static_cast<std::size_t>(at), static_cast<std::size_t>(n));
  };
  for (const char* path : kDatasets) {
    if (!exists(file, path)) continue;
    const hid_t set = H5Dopen2(file, path, H5P_DEFAULT);
    if (set < 0) continue;
    const hid_t plist = H5Dget_create_plist(set);
    if (plist >= 0 && H5Pget_layout(plist) == H5D_CHUNKED) {
      const hid_t space = H5Dget_space(set);
      hsize_t chunks = 0;
      if (H5Dget_num_chunks(set, space, &chunks) >= 0)
        for (hsize_t c = 0; c < chunks && c < 64; ++c) {
          haddr_t at = HADDR_UNDEF;
          hsize_t n = 0;
          unsigned mask = 0;
          if (H5Dget_chunk_info(set, space, c, nullptr, &mask, &at, &n) >= 0) keep(at, n);
        }
      H5Sclose(space);
    } else {
      keep(H5Dget_offset(set), H5Dget_storage_size(set));
    }
    if (plist >= 0) H5Pclose(plist);
    H5Dclose(set);
  }
  return out;
}

}  // namespace

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
  std::mt19937_64 rng(seed);
  if (rng() % 2 == 0) {
    const hid_t file = open_image(data, size, H5F_ACC_RDONLY);
    if (file < 0) return size;
    const auto extents = stored_extents(file, size);
    H5Fclose(file);
    if (extents.empty()) return size;
    // One dataset's stored bytes, mutated in place at their size (the image keeps its layout).
    const auto [at, n] = extents[rng() % extents.size()];
    std::vector<std::uint8_t> bytes(data + at, data + at + n);
    const std::size_t changed = LLVMFuzzerMutate(bytes.data(), n, n);
    std::copy(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(std::min(changed, n)), data + at);
    return size;
  }
  const hid_t file = open_image(data, size, H5F_ACC_RDWR);
  if (file < 0) return size;
  const int edits = 1 + static_cast<int>(rng() % 3);
  for (int k = 0; k < edits; ++k) {
    const int what = static_cast<int>(rng() % 8);
    if (what < 4) {
      const std::string path = kDatasets[rng() % std::size(kDatasets)];
      if (exists(file, path)) poke(file, path, rng);
    } else if (what < 6) {
      const auto& a = kAttributes[rng() % std::size(kAttributes)];
      reattribute(file, a[0], a[1], rng);
    } else if (what == 6) {
      const std::string path = kDatasets[rng() % std::size(kDatasets)];
      if (exists(file, path)) H5Ldelete(file, path.c_str(), H5P_DEFAULT);
    } else {
      remake(file, kDatasets[rng() % std::size(kDatasets)], rng);  // fails, harmlessly, without its group
    }
  }
  H5Fflush(file, H5F_SCOPE_GLOBAL);
  const ssize_t image = H5Fget_file_image(file, nullptr, 0);
  std::size_t out = size;
  if (image > 0 && static_cast<std::size_t>(image) <= max_size) {
    if (H5Fget_file_image(file, data, static_cast<std::size_t>(image)) == image) out = static_cast<std::size_t>(image);
  }
  H5Fclose(file);
  return out;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  H5::Exception::dontPrint();
  const hid_t id = open_image(data, size, H5F_ACC_RDONLY);
  if (id < 0) return 0;  // not an HDF5 image: what H5Fis_hdf5 refuses before the readers run
  {
    H5::H5File file(id);  // takes a reference of its own
    for (const std::int64_t frame : {std::int64_t{-1}, std::int64_t{0}}) {
      try {
        (void)floedem::read_body_frame(file, "fuzz.h5", frame);
      } catch (const floedem::InputError&) {
      }
    }
    try {
      (void)floedem::read_stored_run(file, "fuzz.h5");
    } catch (const floedem::InputError&) {
    }
  }
  H5Fclose(id);
  return 0;
}
