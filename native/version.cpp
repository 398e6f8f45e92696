#include "floedem/version.hpp"

#include "build_version.hpp"

namespace floedem {

const char* version() { return kBuildVersion; }

}  // namespace floedem
