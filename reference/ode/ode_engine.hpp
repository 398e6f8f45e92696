#pragma once
#include <memory>

#include "floedem/engine/engine.hpp"

namespace floedem {

/// ODE 0.16 (double) as a reference engine (registered as "ode").
std::unique_ptr<Engine> make_ode_engine(const Scene& scene);

}  // namespace floedem
