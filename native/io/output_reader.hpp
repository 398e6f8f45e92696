#pragma once
// The readers of io/output.hpp on a file already open, for the fuzz target (tests/fuzz), which
// reads file images from memory. `label` names the file in messages.
#include <H5Cpp.h>

#include <string>

#include "floedem/io/output.hpp"

namespace floedem {

BodyFrame read_body_frame(H5::H5File& file, const std::string& label, std::int64_t frame);
StoredRun read_stored_run(H5::H5File& file, const std::string& label);

}  // namespace floedem
