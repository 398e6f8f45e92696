#pragma once
// Plane polygon geometry: area, centroid, polar moment, convexity and simplicity checks.
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "floedem/geometry/vec2.hpp"

namespace floedem {

/// Signed area (positive for counter-clockwise vertices). Shoelace formula.
double signed_area(std::span<const Vec2> poly);

/// Area, centroid and second moment of a uniform lamina of unit areal density.
struct AreaMoments {
  double area = 0.0;              ///< m^2
  Vec2 centroid;                  ///< m
  double polar_moment = 0.0;      ///< integral of |r - centroid|^2 dA, m^4
};

/// Exact moments of a simple counter-clockwise polygon (any shape, convex or not).
/// Formulas: A = 1/2 sum c_i, C = 1/(6A) sum (p_i + p_i+1) c_i,
/// J_O = 1/12 sum c_i (p_i.p_i + p_i.p_i+1 + p_i+1.p_i+1), with c_i = p_i x p_i+1,
/// evaluated about the first vertex for round-off, then moved to the centroid
/// (parallel-axis theorem). Source: e.g. Bourke, "Calculating the area and centroid
/// of a polygon" (1988); Eberly, "Polyhedral mass properties" (2002), 2-D case.
AreaMoments area_moments(std::span<const Vec2> poly);

/// True if the counter-clockwise polygon is strictly convex (every turn left).
bool is_strictly_convex(std::span<const Vec2> poly);

/// Indices (i, j) of two non-adjacent edges (edge k runs from vertex k to k+1) that touch
/// or cross, or of a repeated vertex; nullopt for a simple polygon. O(n^2): polygons are small.
std::optional<std::pair<std::size_t, std::size_t>> find_self_intersection(std::span<const Vec2> poly);

/// The checks of a body's outline, the same wherever it is read (a scenario's polygon, a field
/// file's or a run's /bodies/polygon_vertices): at least 3 and at most kMaxPolygonVertices
/// vertices, each within kLargestCoordinate of the origin in x and y, no self-intersection, an
/// area above round-off. Returns why the polygon fails, as words that follow its name ("has 2
/// vertices; allowed at least 3"), or nullopt when it passes. Either orientation passes.
std::optional<std::string> polygon_problem(std::span<const Vec2> poly);

/// Coordinates within 1e7 m (ten thousand kilometres, beyond any ice field): far larger ones
/// are typing errors or damage, and they break the convex partition's arithmetic (a vertex at
/// 4e75 m crashed CGAL's optimal partition).
inline constexpr double kLargestCoordinate = 1e7;
/// The self-intersection check is O(n^2): a floe or iceberg outline has tens of vertices.
inline constexpr std::size_t kMaxPolygonVertices = 10000;

/// Removes repeated vertices and vertices on the straight line between their neighbours
/// (within a relative tolerance). Keeps the order.
std::vector<Vec2> remove_collinear(std::span<const Vec2> poly, double relative_tolerance = 1e-12);

/// Axis-aligned bounds of points.
Aabb bounds_of(std::span<const Vec2> pts);

}  // namespace floedem

namespace floedem {

/// Splits a convex counter-clockwise polygon into convex pieces of at most `max_vertices`
/// (>= 3) vertices each, as a fan of consecutive vertex runs from vertex 0.
std::vector<std::vector<Vec2>> split_convex(const std::vector<Vec2>& poly, std::size_t max_vertices);

/// Moves every edge of a convex counter-clockwise polygon inward by `distance` (m) and returns
/// the polygon of the moved edges' intersections (an inward parallel offset).
std::vector<Vec2> inset_convex(const std::vector<Vec2>& poly, double distance);

}  // namespace floedem
