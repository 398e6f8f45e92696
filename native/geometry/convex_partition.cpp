#include "geometry/convex_partition.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Partition_traits_2.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/partition_2.h>
#include <CGAL/partition_is_valid_2.h>

#include <iterator>
#include <list>

#include "geometry/polygon.hpp"

namespace floedem {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Traits = CGAL::Partition_traits_2<Kernel>;
using Point = Traits::Point_2;
using Polygon = Traits::Polygon_2;

// True when some vertex lies on the line through two others (exact predicate). CGAL's optimal
// partition (Greene's dynamic programme over the visibility graph) is not safe on such
// polygons: with three vertices on one line a candidate diagonal runs through a vertex, and in
// a release build it returns parts that are not convex (a rectilinear polygon of ten vertices
// came back whole, as one part) or reads freed memory (the fuzzer's polygon with four vertices
// on one horizontal line). O(n^3) predicates, run only for n <= 64.
bool has_collinear_triple(const std::vector<Point>& p) {
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      for (std::size_t k = j + 1; k < n; ++k)
        if (CGAL::collinear(p[i], p[j], p[k])) return true;
  return false;
}

// Parts that are convex, counter-clockwise, do not overlap and whose union is the polygon.
bool valid(const std::vector<Point>& polygon, const std::list<Polygon>& parts) {
  if (parts.empty()) return false;
  for (const Polygon& part : parts)
    if (part.size() < 3 || !part.is_simple() || part.orientation() != CGAL::COUNTERCLOCKWISE) return false;
  return CGAL::convex_partition_is_valid_2(polygon.begin(), polygon.end(), parts.begin(), parts.end());
}

}  // namespace

std::vector<std::vector<Vec2>> convex_partition(std::span<const Vec2> ccw_polygon) {
  if (is_strictly_convex(ccw_polygon)) return {std::vector<Vec2>(ccw_polygon.begin(), ccw_polygon.end())};

  std::vector<Point> input;
  input.reserve(ccw_polygon.size());
  for (const Vec2 p : ccw_polygon) input.emplace_back(p.x, p.y);

  // CGAL's partitions require a simple counter-clockwise polygon, and check it only in debug
  // builds. The scene's checks (scenario.cpp) hold in floating point; a sliver can pass them
  // and still fail CGAL's exact predicates once shifted to its centroid (the fuzzer's triangle
  // 9 m wide and 7.8e6 m long: CGAL then popped an empty list). Such a polygon has no parts.
  if (!CGAL::is_simple_2(input.begin(), input.end(), Kernel()) ||
      CGAL::orientation_2(input.begin(), input.end(), Kernel()) != CGAL::COUNTERCLOCKWISE)
    return {};

  // Fewest parts where the optimal partition is safe (general position, at most 64 vertices:
  // it costs O(n^4)); otherwise, or when its answer fails the check, Hertel and Mehlhorn's
  // merge of a constrained Delaunay triangulation, which degenerate vertices do not upset.
  std::list<Polygon> parts;
  if (input.size() <= 64 && !has_collinear_triple(input)) {
    CGAL::optimal_convex_partition_2(input.begin(), input.end(), std::back_inserter(parts));
    if (!valid(input, parts)) parts.clear();
  }
  if (parts.empty()) {
    CGAL::approx_convex_partition_2(input.begin(), input.end(), std::back_inserter(parts));
    if (!valid(input, parts)) return {};
  }

  std::vector<std::vector<Vec2>> out;
  out.reserve(parts.size());
  for (const Polygon& part : parts) {
    std::vector<Vec2> v;
    for (auto it = part.vertices_begin(); it != part.vertices_end(); ++it)
      v.emplace_back(CGAL::to_double(it->x()), CGAL::to_double(it->y()));
    v = remove_collinear(v);
    if (v.size() >= 3) out.push_back(std::move(v));
  }
  return out;
}

}  // namespace floedem
