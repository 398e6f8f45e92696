#pragma once
// Splits a simple polygon into convex parts. CGAL is included here and in field/power_diagram.cpp only: it costs
// tens of seconds and about a gigabyte of memory per translation unit to compile.
#include <span>
#include <vector>

#include "floedem/geometry/vec2.hpp"

namespace floedem {

/// Convex parts of a simple counter-clockwise polygon whose union is the polygon.
/// Uses CGAL's optimal convex partition (Greene 1983; fewest parts) for up to 64 vertices in
/// general position (no three on a line), and the Hertel-Mehlhorn approximation (at most 4x
/// the optimum) otherwise or when the optimal answer fails its check. Every answer is checked
/// (convex counter-clockwise parts that tile the polygon); none passing, the result is empty.
/// A convex input is returned as its single part.
std::vector<std::vector<Vec2>> convex_partition(std::span<const Vec2> ccw_polygon);

}  // namespace floedem
