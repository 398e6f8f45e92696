#include "geometry/polygon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace floedem {

double signed_area(std::span<const Vec2> poly) {
  const std::size_t n = poly.size();
  if (n < 3) return 0.0;
  // Relative to the first vertex, so that far-from-origin polygons keep their digits.
  const Vec2 o = poly[0];
  double twice = 0.0;
  for (std::size_t i = 1; i + 1 < n; ++i) twice += cross(poly[i] - o, poly[i + 1] - o);
  return 0.5 * twice;
}

AreaMoments area_moments(std::span<const Vec2> poly) {
  AreaMoments m;
  const std::size_t n = poly.size();
  if (n < 3) return m;
  const Vec2 o = poly[0];
  double a2 = 0.0;     // twice the area
  Vec2 c6;             // 6 A times the centroid (relative to o)
  double j12 = 0.0;    // 12 times the polar moment about o
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 p = poly[i] - o;
    const Vec2 q = poly[(i + 1) % n] - o;
    const double c = cross(p, q);
    a2 += c;
    c6 += c * (p + q);
    j12 += c * (dot(p, p) + dot(p, q) + dot(q, q));
  }
  m.area = 0.5 * a2;
  if (m.area == 0.0) return m;
  const Vec2 cr = (1.0 / (3.0 * a2)) * c6;  // c6 / (6 A) = c6 / (3 * a2)
  m.centroid = o + cr;
  m.polar_moment = j12 / 12.0 - m.area * dot(cr, cr);
  return m;
}

bool is_strictly_convex(std::span<const Vec2> poly) {
  const std::size_t n = poly.size();
  if (n < 3) return false;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = poly[i];
    const Vec2 b = poly[(i + 1) % n];
    const Vec2 c = poly[(i + 2) % n];
    if (cross(b - a, c - b) <= 0.0) return false;
  }
  // A strictly left-turning closed chain can still wind more than once (a star);
  // the total turning of a convex polygon is exactly 2 pi.
  double turning = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 e0 = poly[(i + 1) % n] - poly[i];
    const Vec2 e1 = poly[(i + 2) % n] - poly[(i + 1) % n];
    turning += std::atan2(cross(e0, e1), dot(e0, e1));
  }
  return std::abs(turning - 2.0 * M_PI) < 1e-6;
}

namespace {

int orientation(Vec2 a, Vec2 b, Vec2 c) {
  const double v = cross(b - a, c - a);
  return (v > 0.0) - (v < 0.0);
}

bool on_segment(Vec2 a, Vec2 b, Vec2 p) {
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}

bool segments_touch(Vec2 p1, Vec2 p2, Vec2 q1, Vec2 q2) {
  const int o1 = orientation(p1, p2, q1);
  const int o2 = orientation(p1, p2, q2);
  const int o3 = orientation(q1, q2, p1);
  const int o4 = orientation(q1, q2, p2);
  if (o1 != o2 && o3 != o4 && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0) return true;
  if (o1 == 0 && on_segment(p1, p2, q1)) return true;
  if (o2 == 0 && on_segment(p1, p2, q2)) return true;
  if (o3 == 0 && on_segment(q1, q2, p1)) return true;
  if (o4 == 0 && on_segment(q1, q2, p2)) return true;
  return o1 != o2 && o3 != o4;
}

}  // namespace

std::optional<std::pair<std::size_t, std::size_t>> find_self_intersection(std::span<const Vec2> poly) {
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (poly[i] == poly[j]) return std::make_pair(i, j);
  if (n < 4) return std::nullopt;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (segments_touch(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n]))
        return std::make_pair(i, j);
    }
  }
  return std::nullopt;
}

std::vector<Vec2> remove_collinear(std::span<const Vec2> poly, double relative_tolerance) {
  std::vector<Vec2> out(poly.begin(), poly.end());
  bool changed = true;
  while (changed && out.size() >= 3) {
    changed = false;
    const std::size_t n = out.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 a = out[(i + n - 1) % n];
      const Vec2 b = out[i];
      const Vec2 c = out[(i + 1) % n];
      const double scale = length(c - a) * std::max(length(b - a), length(c - b));
      if (b == a || std::abs(cross(b - a, c - b)) <= relative_tolerance * scale) {
        out.erase(out.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
    }
  }
  return out;
}

Aabb bounds_of(std::span<const Vec2> pts) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Aabb b{{inf, inf}, {-inf, -inf}};
  for (const Vec2 p : pts) {
    b.lo.x = std::min(b.lo.x, p.x);
    b.lo.y = std::min(b.lo.y, p.y);
    b.hi.x = std::max(b.hi.x, p.x);
    b.hi.y = std::max(b.hi.y, p.y);
  }
  return b;
}

}  // namespace floedem

namespace floedem {

std::vector<std::vector<Vec2>> split_convex(const std::vector<Vec2>& poly, std::size_t max_vertices) {
  const std::size_t n = poly.size();
  if (n <= max_vertices) return {poly};
  std::vector<std::vector<Vec2>> out;
  // Pieces (0, k, k+1, ..., k+m-2): each adds up to max_vertices - 2 new vertices.
  std::size_t k = 1;
  while (k + 1 < n) {
    const std::size_t last = std::min(n - 1, k + max_vertices - 2);
    std::vector<Vec2> piece{poly[0]};
    for (std::size_t j = k; j <= last; ++j) piece.push_back(poly[j]);
    out.push_back(std::move(piece));
    k = last;
  }
  return out;
}

std::vector<Vec2> inset_convex(const std::vector<Vec2>& poly, double distance) {
  const std::size_t n = poly.size();
  std::vector<Vec2> out;
  for (std::size_t i = 0; i < n; ++i) {
    // Vertex i joins edge (i-1, i) and edge (i, i+1); both move inward along their normals.
    const Vec2 a = poly[(i + n - 1) % n], b = poly[i], c = poly[(i + 1) % n];
    const Vec2 e0 = normalized(b - a), e1 = normalized(c - b);
    const Vec2 n0 = perp(e0), n1 = perp(e1);  // inward (left) normals of a ccw polygon
    // b + distance * (n0 + n1) / (1 + n0.n1) lies at `distance` from both edges.
    out.push_back(b + (distance / (1.0 + dot(n0, n1))) * (n0 + n1));
  }
  return out;
}

std::optional<std::string> polygon_problem(std::span<const Vec2> poly) {
  if (poly.size() < 3) return "has " + std::to_string(poly.size()) + " vertices; allowed at least 3";
  if (poly.size() > kMaxPolygonVertices)
    return "has " + std::to_string(poly.size()) + " vertices; allowed at most " + std::to_string(kMaxPolygonVertices);
  for (std::size_t k = 0; k < poly.size(); ++k)
    if (!(std::abs(poly[k].x) <= kLargestCoordinate && std::abs(poly[k].y) <= kLargestCoordinate))
      return "vertex " + std::to_string(k) + " lies beyond 1e7 m; allowed |x|, |y| <= 1e7 m";
  if (const auto hit = find_self_intersection(poly))
    return "is self-intersecting (edges " + std::to_string(hit->first) + " and " + std::to_string(hit->second) +
           " touch or cross, counting from 0); allowed a simple polygon";
  const double a = signed_area(poly);
  const Aabb box = bounds_of(poly);
  const double box_area = (box.hi.x - box.lo.x) * (box.hi.y - box.lo.y);
  if (!(std::abs(a) > 1e-12 * box_area) || box_area == 0.0)
    return std::string("has zero area; allowed a simple polygon of positive area");
  return std::nullopt;
}

}  // namespace floedem
