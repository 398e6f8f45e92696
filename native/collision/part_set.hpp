#pragma once
// The convex parts of every body, in their body's frame and placed in the world each step:
// what the broad and narrow phases read. Shared by the native engine and by reference
// engines that take floedem's 2-D contact geometry (ODE).
#include <cstdint>
#include <span>
#include <vector>

#include "engine/line_vector.hpp"
#include "floedem/scene/scene.hpp"
#include "collision/narrow_phase.hpp"

namespace floedem {

class PartSet {
 public:
  explicit PartSet(const Scene& scene);
  std::size_t size() const { return body_.size(); }

  /// World vertices, normals and tight bounds of every part for the bodies' placements. A part
  /// whose body's pose is, to the bit, the one of the last call keeps what it has (the same pose
  /// gives the same vertices): kept() says which did. Returns whether any part kept its own.
  bool place(std::span<const Vec2> position, std::span<const Rot> rotation);
  /// The same for the listed parts alone (ascending): the others are left as they are, kept()
  /// included. Returns whether any listed part kept its own.
  bool place(std::span<const Vec2> position, std::span<const Rot> rotation, std::span<const std::int32_t> parts);
  /// Marks a part kept, for a caller that will leave it out of place() while its body stays
  /// where it was last placed (the native engine's settled sleepers).
  void hold(std::int32_t part) { kept_[static_cast<std::size_t>(part)] = 1; }
  /// Per part: 1 where the last place() kept the part's placement (its body did not move).
  std::span<const std::uint8_t> kept() const { return kept_; }

  /// Inline: the narrow phase asks for two a pair, and out of line the call and the copy of its
  /// result are paid for every pair of a packed field.
  PartGeometry geometry(std::int32_t part, Vec2 position, Rot rotation) const {
    const std::int32_t first = first_[part];
    return PartGeometry{ConvexView{&world_vertices_[first], &world_normals_[first], first_[part + 1] - first},
                        &local_vertices_[first], &local_normals_[first], Transform{position, rotation}};
  }
  /// Asks for the cache lines of a part's world vertices and normals (the narrow phase, a few
  /// pairs ahead: a pair's second part is anywhere in the field). Changes no value.
  void prefetch_world(std::int32_t part) const {
    const std::int32_t first = first_[part];
    __builtin_prefetch(&world_vertices_[first]);
    __builtin_prefetch(&world_normals_[first]);
  }
  /// The same for its vertices and normals in its body's frame (a reference face's, in collide()).
  void prefetch_local(std::int32_t part) const {
    const std::int32_t first = first_[part];
    __builtin_prefetch(&local_vertices_[first]);
    __builtin_prefetch(&local_normals_[first]);
  }
  std::span<const std::int32_t> body() const { return body_; }
  /// A body's parts are parts first_part(b) to first_part(b + 1) - 1 (parts are in body order).
  std::int32_t first_part(std::int32_t body) const { return first_part_[body]; }
  /// Non-zero for parts of bodies of infinite mass in contacts (fixed or prescribed).
  std::span<const std::uint8_t> immovable() const { return immovable_; }
  /// Largest distance of a vertex of the part from its body's centroid (m).
  double radius(std::int32_t part) const { return radius_[part]; }
  std::span<const Aabb> boxes() const { return boxes_; }

 private:
  std::vector<std::int32_t> body_;
  std::vector<std::uint8_t> immovable_;
  std::vector<std::int32_t> first_;  // first vertex of part k; part k ends at first_[k + 1]
  std::vector<std::int32_t> first_part_;  // first part of body b; its parts end at first_part_[b + 1]
  LineVector<Vec2> local_vertices_, local_normals_;
  LineVector<Vec2> world_vertices_, world_normals_;
  std::vector<double> radius_;
  LineVector<Aabb> boxes_;
  std::vector<Vec2> placed_position_;  // per part: the pose it was last placed at (NaN: never)
  std::vector<Rot> placed_rotation_;
  std::vector<std::uint8_t> kept_;
  bool place_part(std::size_t k, std::span<const Vec2> position, std::span<const Rot> rotation);
};

}  // namespace floedem
