#pragma once
// floedem's version, and the version of the layout of the files it writes.
#include <cstdint>

namespace floedem {

/// The release and the commit this library was built from, "MAJOR.MINOR.PATCH+DESCRIBE"
/// (DESCRIBE: `git describe --always --dirty --tags` of the source, "unknown" outside a
/// checkout). `floedem --version` prints it, every output file stores it as its root attribute
/// `floedem_version`, and the CMake package's version is its MAJOR.MINOR.PATCH.
const char* version();

/// The output layout's version, the root attribute `format_version` of every file floedem writes
/// (runs and fields). It rises by one whenever a change would make a reader of the last layout
/// misread a file: a dataset or attribute removed or renamed, or its unit, shape, type or meaning
/// changed. Adding a dataset or an attribute leaves it as it is (readers ignore what they do not
/// know). floedem's readers (io/output.hpp) read every version from kOldestOutputFormatVersion
/// on and refuse another, naming both. Version 2: every string fixed-length (version 1's were
/// variable-length, stored on HDF5's global heap).
inline constexpr std::int64_t kOutputFormatVersion = 2;
inline constexpr std::int64_t kOldestOutputFormatVersion = 1;

}  // namespace floedem
