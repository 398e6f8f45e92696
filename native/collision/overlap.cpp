#include "collision/overlap.hpp"

#include <algorithm>
#include <tuple>

#include "geometry/polygon.hpp"
#include "geometry/sat.hpp"
#include "collision/broad_phase.hpp"

namespace floedem {

std::optional<BodyOverlap> find_overlap(const Scene& scene) {
  // Every part in world coordinates, laid end to end (part k's vertices and outward normals
  // are [first[k], first[k + 1])), with its box and its body.
  std::vector<Vec2> vertices, normals;
  std::vector<std::size_t> first{0};
  std::vector<Aabb> boxes;
  std::vector<std::int32_t> body;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    for (const auto& local : b.local_parts) {
      const std::size_t start = vertices.size(), n = local.size();
      for (const Vec2 v : local) vertices.push_back(b.centroid + v);
      for (std::size_t k = 0; k < n; ++k) {
        const Vec2 p = vertices[start + k], q = vertices[start + (k + 1) % n];
        normals.push_back(normalized(Vec2{q.y - p.y, p.x - q.x}));
      }
      first.push_back(vertices.size());
      boxes.push_back(bounds_of(std::span<const Vec2>(vertices).subspan(start, n)));
      body.push_back(static_cast<std::int32_t>(i));
    }
  }
  // The candidates are the engine's own broad phase (a hierarchical grid: O(N log) for a field
  // of floes, where a sweep on one axis meets a whole column of the field per part). No part is
  // marked fixed: two fixed bodies that overlap are reported as well.
  const std::vector<std::uint8_t> fixed(boxes.size(), 0);
  std::vector<PartPair> pairs;
  BroadPhase().find_pairs(boxes, body, fixed, pairs);

  auto view = [&](std::int32_t k) {
    return ConvexView{vertices.data() + first[k], normals.data() + first[k], static_cast<int>(first[k + 1] - first[k])};
  };
  auto size = [&](std::int32_t k) { return length(boxes[k].hi - boxes[k].lo); };
  std::optional<BodyOverlap> found;
  for (const PartPair pair : pairs) {
    const ConvexView a = view(pair.a), b = view(pair.b);
    const double sep = std::max(max_face_separation(a, b).separation, max_face_separation(b, a).separation);
    // Touching polygons give sep = 0 up to round-off of their coordinates.
    const double tolerance = 1e-9 * (size(pair.a) + size(pair.b));
    if (sep < -tolerance) {
      const auto ba = static_cast<std::size_t>(body[pair.a]), bb = static_cast<std::size_t>(body[pair.b]);
      const BodyOverlap o{std::min(ba, bb), std::max(ba, bb), -sep};
      // The first pair of bodies, and of its parts the deepest overlap.
      if (!found || std::tuple(o.a, o.b, -o.depth) < std::tuple(found->a, found->b, -found->depth)) found = o;
    }
  }
  return found;
}

}  // namespace floedem
