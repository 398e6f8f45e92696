#include "field/exact_geometry.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <numeric>

namespace floedem::test {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_2;

/// b lies on the outer (right) side of some edge line of a, or on it.
bool separated_by_edge_of(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  const std::size_t n = a.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Point p(a[k].x, a[k].y), q(a[(k + 1) % n].x, a[(k + 1) % n].y);
    bool all_outside = true;
    for (const Vec2 v : b) {
      if (CGAL::orientation(p, q, Point(v.x, v.y)) == CGAL::LEFT_TURN) {
        all_outside = false;
        break;
      }
    }
    if (all_outside) return true;
  }
  return false;
}

}  // namespace

bool convex_interiors_disjoint(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  return separated_by_edge_of(a, b) || separated_by_edge_of(b, a);
}

std::optional<std::pair<std::size_t, std::size_t>> first_overlap(const std::vector<std::vector<Vec2>>& polygons) {
  const std::size_t n = polygons.size();
  std::vector<Aabb> box(n);
  for (std::size_t i = 0; i < n; ++i) {
    box[i] = {polygons[i][0], polygons[i][0]};
    for (const Vec2 v : polygons[i]) {
      box[i].lo = {std::min(box[i].lo.x, v.x), std::min(box[i].lo.y, v.y)};
      box[i].hi = {std::max(box[i].hi.x, v.x), std::max(box[i].hi.y, v.y)};
    }
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return box[a].lo.x < box[b].lo.x; });
  for (std::size_t u = 0; u < n; ++u) {
    const std::size_t i = order[u];
    for (std::size_t v = u + 1; v < n && box[order[v]].lo.x <= box[i].hi.x; ++v) {
      const std::size_t j = order[v];
      if (box[j].lo.y > box[i].hi.y || box[i].lo.y > box[j].hi.y) continue;
      if (!convex_interiors_disjoint(polygons[i], polygons[j])) return std::pair{std::min(i, j), std::max(i, j)};
    }
  }
  return std::nullopt;
}

bool inside_box(const std::vector<Vec2>& polygon, Vec2 lo, Vec2 hi) {
  return std::all_of(polygon.begin(), polygon.end(),
                     [&](Vec2 v) { return v.x >= lo.x && v.x <= hi.x && v.y >= lo.y && v.y <= hi.y; });
}

}  // namespace floedem::test
