#pragma once
// Exact checks for the field tests, with CGAL's exact predicates (a test-only CGAL unit).
#include <optional>
#include <utility>
#include <vector>

#include "floedem/geometry/vec2.hpp"

namespace floedem::test {

/// True when the interiors of two convex counter-clockwise polygons are disjoint, decided
/// exactly: for convex polygons they are iff one polygon's edge line has the other polygon
/// entirely on its outer side or on it (the separating axis theorem), and each side test is
/// CGAL's exact orientation predicate.
bool convex_interiors_disjoint(const std::vector<Vec2>& a, const std::vector<Vec2>& b);

/// The first overlapping pair among convex polygons (pairs found by sorting on x; each pair
/// decided exactly), or nullopt.
std::optional<std::pair<std::size_t, std::size_t>> first_overlap(const std::vector<std::vector<Vec2>>& polygons);

/// Exact: every vertex in [lo.x, hi.x] x [lo.y, hi.y].
bool inside_box(const std::vector<Vec2>& polygon, Vec2 lo, Vec2 hi);

}  // namespace floedem::test
