#include "solver/contact_islands.hpp"

#include <algorithm>

#include "engine/headroom.hpp"

namespace floedem {

std::int32_t ContactIslands::find(std::int32_t body) {
  while (parent_[body] != body) {
    parent_[body] = parent_[parent_[body]];  // path halving
    body = parent_[body];
  }
  return body;
}

namespace {
// Manifolds ahead whose first line is asked for before it is read: the loop reads 8 bytes of
// each 384-byte manifold, out of cache in a large field, and would wait for each. A prefetch
// changes no value.
constexpr std::size_t kManifoldsAhead = 8;
}  // namespace

void ContactIslands::build(std::span<const Manifold> manifolds, const BodyArrays& bodies) {
  const std::size_t nb = bodies.inv_mass.size();
  if (parent_.size() != nb) {
    parent_.assign(nb, -1);
    root_island_.assign(nb, -1);
    touched_.clear();
  }
  for (const std::int32_t b : touched_) parent_[b] = root_island_[b] = -1;  // last build's, only
  touched_.clear();
  auto moving = [&](std::int32_t b) { return bodies.inv_mass[b] != 0.0; };  // as apply_impulse
  auto touch = [&](std::int32_t b) {
    if (parent_[b] >= 0) return;
    parent_[b] = b;
    touched_.push_back(b);
  };
  // Each manifold's first moving body (-1: none) is kept in manifold_island_ for the numbering
  // below, which so reads 4 bytes a manifold and not its 384-byte struct again (out of cache
  // at 16k floes).
  const std::size_t nm = manifolds.size();
  resize_with_headroom(manifold_island_, nm);
  for (std::size_t k = 0; k < nm; ++k) {
    if (k + kManifoldsAhead < nm) __builtin_prefetch(&manifolds[k + kManifoldsAhead].body_a);
    const Manifold& m = manifolds[k];
    const bool ma = moving(m.body_a), mb = moving(m.body_b);
    manifold_island_[k] = ma ? m.body_a : mb ? m.body_b : -1;
    if (ma) touch(m.body_a);
    if (mb) touch(m.body_b);
    if (!ma || !mb) continue;
    const std::int32_t ra = find(m.body_a), rb = find(m.body_b);
    if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
  }

  // Islands numbered by their first manifold. A manifold between two bodies that cannot move
  // (two sleeping bodies, or a sleeping and a fixed one: the broad phase never pairs two fixed
  // ones) is in no island: nothing can change its impulses, which stay as they were carried.
  std::int32_t islands = 0;
  std::size_t held = 0;
  for (std::size_t k = 0; k < nm; ++k) {
    const std::int32_t b = manifold_island_[k];
    if (b < 0) {
      ++held;
      continue;
    }
    const std::int32_t r = find(b);
    if (root_island_[r] < 0) root_island_[r] = islands++;
    manifold_island_[k] = root_island_[r];
  }

  // Grouped by island (counting sort, stable: each island's manifolds and bodies ascending).
  reserve_with_headroom(manifold_start_, static_cast<std::size_t>(islands) + 1);
  reserve_with_headroom(fill_, static_cast<std::size_t>(islands) + 1);
  reserve_with_headroom(body_start_, static_cast<std::size_t>(islands) + 1);
  manifold_start_.assign(static_cast<std::size_t>(islands) + 1, 0);
  for (std::size_t k = 0; k < nm; ++k)
    if (manifold_island_[k] >= 0) ++manifold_start_[manifold_island_[k] + 1];
  for (std::int32_t i = 0; i < islands; ++i) manifold_start_[i + 1] += manifold_start_[i];
  fill_.assign(manifold_start_.begin(), manifold_start_.end() - 1);
  resize_with_headroom(manifold_, nm - held);
  for (std::size_t k = 0; k < nm; ++k)
    if (manifold_island_[k] >= 0) manifold_[fill_[manifold_island_[k]]++] = static_cast<std::int32_t>(k);

  // The bodies in contact, ascending: sorted where they are few (the towing case), read off
  // the union-find in one pass where they are most of the scene (a packed field, where a sort
  // of them all costs more than the pass). The same list either way.
  if (touched_.size() > nb / 16) {
    touched_.clear();
    for (std::size_t b = 0; b < nb; ++b)
      if (parent_[b] >= 0) touched_.push_back(static_cast<std::int32_t>(b));
  } else {
    std::sort(touched_.begin(), touched_.end());
  }
  body_start_.assign(static_cast<std::size_t>(islands) + 1, 0);
  for (const std::int32_t b : touched_) ++body_start_[root_island_[find(b)] + 1];
  for (std::int32_t i = 0; i < islands; ++i) body_start_[i + 1] += body_start_[i];
  fill_.assign(body_start_.begin(), body_start_.end() - 1);
  resize_with_headroom(body_, touched_.size());
  for (const std::int32_t b : touched_) body_[fill_[root_island_[find(b)]]++] = b;
}

}  // namespace floedem
