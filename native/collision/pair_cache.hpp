#pragma once
// Coherent broad phase: pairs that cannot have met since the last step are not re-tested.
//
// Each part keeps a fat box, its step box grown by a margin, and the cache keeps the pairs
// whose fat boxes overlap (candidates). A part whose step box is still inside its fat box
// changes nothing; only a part that has left it gets a new fat box, and only its candidates
// are found again: against the hierarchical grid of the last rebuild (BroadPhase::query) for
// parts whose fat box is unchanged since, and by direct test against the few that changed.
// When too many have changed, the grid is rebuilt. The pairs handed out are the candidates
// whose step boxes overlap: exactly BroadPhase::find_pairs on the step boxes, in the same
// (sorted) order, so the solver sees the same pairs, to the bit, at a fraction of the cost
// when most floes are at rest or drift slowly (the towing case's field, a pack).
#include <cstdint>
#include <span>
#include <vector>

#include "floedem/engine/state_io.hpp"
#include "collision/broad_phase.hpp"

namespace floedem {

class PairCache {
 public:
  /// boxes[k]: part k's bounds this step (already grown by its reach); margin[k]: room given
  /// to a part that has left its fat box (m, >= 0); body and fixed as for BroadPhase.
  /// `active`, where not empty: the parts (ascending) whose boxes may have changed since the
  /// last call; every other part's box is the one it had then, inside its fat box, and is not
  /// looked at (the native engine's settled sleepers). The same pairs as without it.
  void find_pairs(std::span<const Aabb> boxes, std::span<const double> margin, std::span<const std::int32_t> body,
                  std::span<const std::uint8_t> fixed, std::vector<PartPair>& out,
                  std::span<const std::int32_t> active = {});

  /// Parts whose fat box overlaps `box` (its step box, after find_pairs, lies in its fat box):
  /// the grid for parts unchanged since the last rebuild, the changed ones directly.
  void parts_near(const Aabb& box, std::vector<std::int32_t>& out) const;

  std::int64_t rebuilds() const { return rebuilds_; }
  std::int64_t refreshed_parts() const { return refreshed_; }  ///< parts given a new fat box, over the run

  /// Checkpoint: the fat boxes, which of them the grid holds old, the candidates and the
  /// counts. Restoring rebuilds the grid over the present fat boxes: a stale part's entry
  /// then differs from the one it replaces, but stale parts are never taken from the grid
  /// (refresh() tests them directly), so every later step finds the same pairs and rebuilds
  /// at the same steps as the run that was not interrupted.
  void save(StateWriter& out) const;
  void restore(StateReader& in, std::span<const std::int32_t> body, std::span<const std::uint8_t> fixed);

 private:
  void rebuild(std::span<const std::int32_t> body, std::span<const std::uint8_t> fixed);
  void refresh(std::span<const std::int32_t> body, std::span<const std::uint8_t> fixed);

  BroadPhase grid_;                     // over fat_ as of the last rebuild
  std::vector<Aabb> fat_;
  std::vector<std::uint8_t> stale_;     // fat box changed since the last rebuild (its grid entry is old)
  std::vector<std::int32_t> stale_list_;
  std::vector<std::uint8_t> moved_;     // fat box changed this step
  std::vector<std::int32_t> moved_list_;
  std::vector<std::uint8_t> left_;      // left its fat box this step
  std::vector<std::vector<PartPair>> overlapping_;  // per block of candidates: room for all, the pairs it found first
  std::vector<std::size_t> overlapping_count_;      // ... and how many
  std::vector<PartPair> candidates_, spare_, fresh_;  // spare_: the list refresh() merges into
  std::vector<std::int32_t> hits_;
  std::int64_t rebuilds_ = 0;
  std::int64_t refreshed_ = 0;
};

}  // namespace floedem
