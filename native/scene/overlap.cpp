#include "scene/overlap.hpp"

#include <algorithm>
#include <numeric>

#include "geometry/polygon.hpp"
#include "geometry/sat.hpp"

namespace floedem {

namespace {

struct WorldPart {
  std::size_t body;
  std::vector<Vec2> vertices;
  std::vector<Vec2> normals;
  Aabb box;
  double size;
};

}  // namespace

std::optional<BodyOverlap> find_overlap(const Scene& scene) {
  std::vector<WorldPart> parts;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    for (const auto& local : b.local_parts) {
      WorldPart p{i, {}, {}, {}, 0.0};
      for (const Vec2 v : local) p.vertices.push_back(b.centroid + v);
      const std::size_t n = p.vertices.size();
      for (std::size_t k = 0; k < n; ++k)
        p.normals.push_back(normalized(Vec2{p.vertices[(k + 1) % n].y - p.vertices[k].y,
                                            p.vertices[k].x - p.vertices[(k + 1) % n].x}));
      p.box = bounds_of(p.vertices);
      p.size = length(p.box.hi - p.box.lo);
      parts.push_back(std::move(p));
    }
  }
  std::vector<std::size_t> order(parts.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return parts[x].box.lo.x < parts[y].box.lo.x || (parts[x].box.lo.x == parts[y].box.lo.x && x < y);
  });
  std::optional<BodyOverlap> first;
  for (std::size_t oi = 0; oi < order.size(); ++oi) {
    const WorldPart& p = parts[order[oi]];
    for (std::size_t oj = oi + 1; oj < order.size(); ++oj) {
      const WorldPart& q = parts[order[oj]];
      if (q.box.lo.x > p.box.hi.x) break;
      if (p.body == q.body || !p.box.overlaps(q.box)) continue;
      const ConvexView a{p.vertices.data(), p.normals.data(), static_cast<int>(p.vertices.size())};
      const ConvexView b{q.vertices.data(), q.normals.data(), static_cast<int>(q.vertices.size())};
      const double sep = std::max(max_face_separation(a, b).separation, max_face_separation(b, a).separation);
      // Touching polygons give sep = 0 up to round-off of their coordinates.
      const double tolerance = 1e-9 * (p.size + q.size);
      if (sep < -tolerance) {
        BodyOverlap o{std::min(p.body, q.body), std::max(p.body, q.body), -sep};
        if (!first || o.a < first->a || (o.a == first->a && o.b < first->b)) first = o;
      }
    }
  }
  return first;
}

}  // namespace floedem
