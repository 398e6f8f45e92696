#pragma once
#include <memory>

#include "floedem/engine/engine.hpp"

namespace floedem {

/// Bullet 3 (double precision) as a reference engine (registered as "bullet").
std::unique_ptr<Engine> make_bullet_engine(const Scene& scene);

}  // namespace floedem
