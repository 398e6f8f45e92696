#include "collision/part_set.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <limits>

#include "parallel/thread_pool.hpp"

namespace floedem {

PartSet::PartSet(const Scene& scene) {
  first_.push_back(0);
  first_part_.push_back(0);
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    for (const auto& part : b.local_parts) {
      double r = 0.0;
      const std::size_t m = part.size();
      for (std::size_t k = 0; k < m; ++k) {
        local_vertices_.push_back(part[k]);
        const Vec2 e = part[(k + 1) % m] - part[k];
        local_normals_.push_back(normalized(Vec2{e.y, -e.x}));
        r = std::max(r, length(part[k]));
      }
      body_.push_back(static_cast<std::int32_t>(i));
      immovable_.push_back(b.fixed || b.prescribed ? 1 : 0);
      first_.push_back(static_cast<std::int32_t>(local_vertices_.size()));
      radius_.push_back(r);
    }
    first_part_.push_back(static_cast<std::int32_t>(body_.size()));
  }
  world_vertices_.resize(local_vertices_.size());
  world_normals_.resize(local_normals_.size());
  boxes_.resize(body_.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  placed_position_.assign(body_.size(), Vec2{nan, nan});
  placed_rotation_.assign(body_.size(), Rot{});
  kept_.assign(body_.size(), 0);
}

bool PartSet::place_part(std::size_t k, std::span<const Vec2> position, std::span<const Rot> rotation) {
  // A body that has not moved since its parts were placed (a floe at rest) keeps them: the same
  // pose gives the same vertices, so nothing is recomputed. Compared bit by bit: -0 and +0 are
  // equal to ==, but a vertex at a centroid's coordinate could take either sign from them.
  const std::int32_t b = body_[k];
  const bool keep = same_bits(position[b].x, placed_position_[k].x) && same_bits(position[b].y, placed_position_[k].y) &&
                    same_bits(rotation[b].c, placed_rotation_[k].c) && same_bits(rotation[b].s, placed_rotation_[k].s);
  kept_[k] = keep ? 1 : 0;
  if (keep) return true;
  placed_position_[k] = position[b];
  placed_rotation_[k] = rotation[b];
  const Transform x{position[b], rotation[b]};
  const Vec2 first = x.apply(local_vertices_[first_[k]]);
  Aabb box{first, first};
  for (std::int32_t v = first_[k]; v < first_[k + 1]; ++v) {
    const Vec2 p = x.apply(local_vertices_[v]);
    world_vertices_[v] = p;
    world_normals_[v] = x.q.apply(local_normals_[v]);
    box.lo.x = std::min(box.lo.x, p.x);
    box.lo.y = std::min(box.lo.y, p.y);
    box.hi.x = std::max(box.hi.x, p.x);
    box.hi.y = std::max(box.hi.y, p.y);
  }
  boxes_[k] = box;
  return false;
}

namespace {
// place_one(part(j)) for j in [0, count), in blocks on the pool's threads (parts are
// independent); whether any kept its placement.
template <class Part, class PlaceOne>
bool place_blocks(std::size_t count, Part part, PlaceOne place_one) {
  std::atomic<bool> any_kept{false};
  thread_pool().for_blocks(count, 2048, [&](std::size_t begin, std::size_t end) {
    bool block_kept = false;
    for (std::size_t j = begin; j < end; ++j) block_kept = place_one(part(j)) || block_kept;
    if (block_kept) any_kept.store(true, std::memory_order_relaxed);
  });
  return any_kept.load(std::memory_order_relaxed);
}
}  // namespace

bool PartSet::place(std::span<const Vec2> position, std::span<const Rot> rotation) {
  return place_blocks(body_.size(), [](std::size_t j) { return j; },
                      [&](std::size_t k) { return place_part(k, position, rotation); });
}

bool PartSet::place(std::span<const Vec2> position, std::span<const Rot> rotation, std::span<const std::int32_t> parts) {
  return place_blocks(parts.size(), [&](std::size_t j) { return static_cast<std::size_t>(parts[j]); },
                      [&](std::size_t k) { return place_part(k, position, rotation); });
}

}  // namespace floedem
