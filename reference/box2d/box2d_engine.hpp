#pragma once
#include <memory>

#include "floedem/engine/engine.hpp"

namespace floedem {

/// Box2D 2.4 as a reference engine (registered as "box2d").
std::unique_ptr<Engine> make_box2d_engine(const Scene& scene);

}  // namespace floedem
