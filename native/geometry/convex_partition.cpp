#include "geometry/convex_partition.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Partition_traits_2.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/partition_2.h>

#include <iterator>
#include <list>

#include "geometry/polygon.hpp"

namespace floedem {

std::vector<std::vector<Vec2>> convex_partition(std::span<const Vec2> ccw_polygon) {
  if (is_strictly_convex(ccw_polygon)) return {std::vector<Vec2>(ccw_polygon.begin(), ccw_polygon.end())};

  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Traits = CGAL::Partition_traits_2<Kernel>;
  using Point = Traits::Point_2;
  using Polygon = Traits::Polygon_2;

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

  std::list<Polygon> parts;
  if (input.size() <= 64)
    CGAL::optimal_convex_partition_2(input.begin(), input.end(), std::back_inserter(parts));
  else
    CGAL::approx_convex_partition_2(input.begin(), input.end(), std::back_inserter(parts));

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
