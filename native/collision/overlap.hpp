#pragma once
#include <cstddef>
#include <optional>

#include "floedem/scene/scene.hpp"

namespace floedem {

struct BodyOverlap {
  std::size_t a = 0;
  std::size_t b = 0;
  double depth = 0.0;  ///< m, penetration along the separating axis of least overlap
};

/// The first pair of bodies (in index order of a, then b) whose polygons overlap at t = 0 by
/// more than round-off (touching is allowed), with the deepest overlap of their parts. The
/// broad phase's grid for candidates, exact SAT on convex parts.
std::optional<BodyOverlap> find_overlap(const Scene& scene);

}  // namespace floedem
