#pragma once
// Contact islands: the manifolds grouped by the moving bodies they join. Two manifolds are in
// one island when a chain of manifolds links them through moving bodies; fixed and prescribed
// bodies (infinite mass: inv_mass = inv_inertia = 0) join nothing, since an impulse cannot
// change their velocity and so cannot pass through them. The velocity solve of one island
// reads and writes only its own bodies, so islands are solved apart, each to its own
// convergence (contact_solver.cpp), and any of them may run on any thread.
#include <cstdint>
#include <span>
#include <vector>

#include "solver/solver_types.hpp"

namespace floedem {

class ContactIslands {
 public:
  /// Groups `manifolds` (every manifold joins at least one moving body). Islands are numbered
  /// by their first manifold; each keeps its manifolds in their order in `manifolds`, so that a
  /// sweep over an island visits them as a sweep over all would.
  void build(std::span<const Manifold> manifolds, const BodyArrays& bodies);

  std::size_t size() const { return manifold_start_.empty() ? 0 : manifold_start_.size() - 1; }
  /// Island i's manifolds (indices into the manifolds given to build, ascending).
  std::span<const std::int32_t> manifolds(std::size_t i) const {
    return {manifold_.data() + manifold_start_[i], manifold_.data() + manifold_start_[i + 1]};
  }
  /// Where island i's manifolds start in the islands' list of all (islands in order, so the
  /// islands' [offset, offset + size) ranges tile [0, manifolds given to build)).
  std::size_t manifold_offset(std::size_t i) const { return static_cast<std::size_t>(manifold_start_[i]); }
  /// Island i's moving bodies (ascending).
  std::span<const std::int32_t> bodies(std::size_t i) const {
    return {body_.data() + body_start_[i], body_.data() + body_start_[i + 1]};
  }
  /// Where island i's bodies start in the islands' list of all (the bodies' ranges tile
  /// [0, moving bodies in contact), as the manifolds' do).
  std::size_t body_offset(std::size_t i) const { return static_cast<std::size_t>(body_start_[i]); }
  /// Moving bodies in any manifold.
  std::size_t body_count() const { return body_.size(); }
  /// Every island's moving bodies, island by island: each moving body of a manifold once.
  std::span<const std::int32_t> all_bodies() const { return body_; }
  /// The island that holds manifold k's moving bodies; -1 where neither moves (a held manifold).
  std::int32_t island_of_manifold(std::size_t k) const { return manifold_island_[k]; }

 private:
  std::int32_t find(std::int32_t body);

  std::vector<std::int32_t> parent_;           // union-find over bodies; -1: not in any manifold
  std::vector<std::int32_t> touched_;          // the moving bodies of this step's manifolds
  std::vector<std::int32_t> root_island_;      // per body (read at roots): its island, -1 none yet
  std::vector<std::int32_t> manifold_island_;  // per manifold
  std::vector<std::int32_t> manifold_start_, manifold_;  // islands' manifolds, grouped (CSR)
  std::vector<std::int32_t> body_start_, body_;          // islands' bodies, grouped (CSR)
  std::vector<std::int32_t> fill_;                       // per island: fill cursor
};

}  // namespace floedem
