#pragma once
#include <memory>

#include "floedem/engine/engine.hpp"

namespace floedem {

/// floedem's own solver (registered as "native").
std::unique_ptr<Engine> make_native_engine(const Scene& scene);

}  // namespace floedem
