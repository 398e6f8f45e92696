#pragma once
// The contact pipeline of the native step: the stages broad_phase (parts placed, their boxes
// grown by their reach, pairs from the pair cache), narrow_phase (each pair's manifold, reused
// where neither part moved), contact_list (the pairs with contacts as manifolds, warm-started
// and classified) and record (the step's impulses as contact records, and what the next step's
// contact list carries over). It owns what those stages keep from step to step; the collision
// detection itself is native/collision/'s.
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "collision/narrow_phase.hpp"
#include "collision/pair_cache.hpp"
#include "engine/line_vector.hpp"
#include "floedem/engine/state_io.hpp"
#include "solver/step_context.hpp"

namespace floedem {

/// What the next step's contact list reads of one of this step's contacts: its pair, and each
/// point's feature id, kind and accumulated impulses (persistence and the warm start). 56 bytes
/// in a list of their own, written by record() as it reads the impulses, so that the contact
/// list need not read 320 bytes of each of the last step's 384-byte manifolds (at 10^5 floes
/// some 50 MB a step, from memory) nor keep that list a step for them alone.
struct CarriedContact {
  std::int32_t part_a = 0, part_b = 0;
  std::uint32_t id[2] = {};
  std::int32_t point_count = 0;
  ContactKind kind[2] = {};
  double normal_impulse[2] = {}, tangent_impulse[2] = {};
};

class ContactPipeline {
 public:
  explicit ContactPipeline(const StepContext& ctx);

  /// broad_phase: every body's reach from its velocity after the loads, the parts placed at the
  /// bodies' positions, and the pairs (pair_up).
  void find_pairs(StepContext& ctx);
  /// Each part's reach and box at the present reaches, and the pairs whose boxes overlap.
  void pair_up(StepContext& ctx);
  /// narrow_phase: each pair's manifold; `redetection`: that of a step found again (every part
  /// where the step's first narrow phase had it).
  void collide_pairs(const StepContext& ctx, bool redetection);
  /// contact_list: the narrow phase's contacts into manifolds(), warm-started from the last
  /// step's and classified. `held`, redetecting: the step's first pass (a point it held keeps
  /// its classification there); empty otherwise.
  void build_contact_list(const StepContext& ctx, std::span<const Manifold> held = {}, bool redetection = false);
  /// record: the step's contacts with an impulse as records, and what the next step carries.
  void record();
  /// No narrow-phase result is reused at the next narrow phase.
  void forget_narrow();

  /// The part's reach this step: how far any of its points can move.
  double reach_of_part(const StepContext& ctx, std::int32_t k) const {
    const std::int32_t b = ctx.parts.body()[k];
    return ctx.linear_reach[b] + ctx.angular_reach[b] * ctx.parts.radius(k);
  }
  /// The part's bounds grown by `reach` and half the allowed overlap: the pairs' test.
  Aabb reach_box(const StepContext& ctx, std::int32_t k, double reach) const;
  /// The manifold of two parts at these reaches (speculative contact within them).
  void collide_parts(const StepContext& ctx, PartPair pair, double reach_a, double reach_b, NarrowManifold& m,
                     SeparationHint* hint = nullptr) const;

  LineVector<Manifold>& manifolds() { return manifolds_; }
  const LineVector<Manifold>& manifolds() const { return manifolds_; }
  std::span<const PartPair> pairs() const { return pairs_; }
  /// Per pair of pairs(): its narrow phase's point count (0: no contact).
  std::span<const std::uint8_t> pair_points() const { return narrow_points_; }
  std::span<const double> part_reach() const { return part_reach_; }
  std::span<const ContactRecord> records() const { return records_; }
  const PairCache& pair_cache() const { return pair_cache_; }
  std::int64_t narrow_pairs() const { return narrow_pairs_; }
  std::int64_t narrow_reused() const { return narrow_reused_; }

  /// Checkpoint: the carried contacts and the pair cache (the narrow phase's counts are this
  /// process's: NativeEngine::add_work_counts).
  void save_contacts(StateWriter& out) const;
  void restore_contacts(StateReader& in, const StepContext& ctx);

 private:
  static constexpr std::size_t kPairGrain = 512;    // pairs per block (narrow phase, contact list)
  static constexpr std::size_t kPrefetchPairs = 4;  // the narrow phase and contact list read this many pairs ahead

  std::vector<double> part_reach_;   // per part: how far any of its points can move this step
  LineVector<Aabb> part_boxes_;
  std::vector<double> part_margin_;  // per part: room of its fat box in the pair cache
  PairCache pair_cache_;
  std::vector<PartPair> pairs_;
  LineVector<NarrowManifold> narrow_;  // per pair this step: the narrow phase's result
  // ... and its point count, apart: a pair without contact (most pairs of fat boxes; nearly
  // all of the towing case's, whose floes at rest reuse theirs) is known by this byte alone,
  // its 192-byte slot neither written nor read again (collide_pairs, build_contact_list).
  std::vector<std::uint8_t> narrow_points_, previous_narrow_points_;
  // Per pair, the edges that separated most at its last test, tried first (sat.hpp): the same
  // manifolds, found sooner (a pair's floes turn little in a step).
  std::vector<SeparationHint> narrow_hint_, previous_hint_;
  // Narrow-phase reuse: collide() is a pure function of the two parts' placement and reaches,
  // so a pair of parts that PartSet::place kept where they were at the last step (their bodies'
  // position and rotation the same to the bit) with the same reaches gets the manifold computed
  // last time, not a new one. In the towing case most pairs are of floes at rest.
  bool any_kept_ = false;                        // any part kept (else no reuse is looked for: a drifting field)
  LineVector<NarrowManifold> previous_narrow_;   // the last narrow phase's results ...
  std::vector<PartPair> previous_pairs_;         // ... for these pairs ...
  std::vector<double> previous_reach_;           // ... with these part reaches
  std::vector<std::int32_t> reuse_;              // per pair: its slot in previous_narrow_, or -1
  std::vector<std::size_t> block_contacts_;      // per block of pairs: contacts before it
  std::int64_t narrow_pairs_ = 0, narrow_reused_ = 0;  // pairs tested over the run, and those reused
  LineVector<Manifold> manifolds_;
  std::vector<CarriedContact> carried_;  // the last step's contacts, as the contact list reads them
  std::vector<ContactRecord> records_;
};

/// Where `pair` is, or would go, in a list sorted by (part_a, part_b): manifolds or carried contacts.
template <class List>
auto find_pair(const List& list, PartPair pair) {
  return std::lower_bound(list.begin(), list.end(), pair,
                          [](const auto& m, PartPair p) { return PartPair{m.part_a, m.part_b} < p; });
}

}  // namespace floedem
