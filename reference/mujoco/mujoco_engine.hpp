#pragma once
#include <memory>

#include "floedem/engine/engine.hpp"

namespace floedem {

/// MuJoCo 2.2 as a reference engine (registered as "mujoco"): soft contacts solved as a convex
/// optimisation, a family apart from the complementarity solvers of the other references.
std::unique_ptr<Engine> make_mujoco_engine(const Scene& scene);

}  // namespace floedem
