#include "solver/contact_pipeline.hpp"

#include "engine/headroom.hpp"
#include "engine/prefetch.hpp"
#include "parallel/thread_pool.hpp"
#include "solver/contact_solver.hpp"

namespace floedem {

namespace {

// What the contact list asks for ahead of writing a new manifold: its first five lines, 320 of
// its 384 bytes (pair, bodies, normal, friction and all of the first point and most of the
// second, which fill_manifold writes); the last line, the second point's end and the reference
// face, is written too and left to the hardware's prefetch.
constexpr std::size_t kManifoldWriteBytes = 320;

}  // namespace

ContactPipeline::ContactPipeline(const StepContext& ctx) {
  part_boxes_.resize(ctx.parts.size());
  part_reach_.resize(ctx.parts.size());
  part_margin_.resize(ctx.parts.size());
  forget_narrow();
}

void ContactPipeline::find_pairs(StepContext& ctx) {
  ctx.for_active_bodies(8192, [&](std::size_t i) { ctx.set_reach(i); });
  ctx.active.refresh(ctx.parts);
  if (ctx.active.any_settled()) {
    ctx.parts.place(ctx.bodies.position, ctx.bodies.rotation, ctx.active.parts());
    any_kept_ = true;  // the settled sleepers' parts, held where they were placed
  } else {
    any_kept_ = ctx.parts.place(ctx.bodies.position, ctx.bodies.rotation);
  }
  pair_up(ctx);
}

void ContactPipeline::forget_narrow() {
  any_kept_ = false;
  previous_pairs_.clear();
  previous_narrow_.clear();
  previous_narrow_points_.clear();
  previous_reach_.clear();
}

void ContactPipeline::pair_up(StepContext& ctx) {
  ctx.active.refresh(ctx.parts);
  const bool skip = ctx.active.any_settled();  // a settled sleeper's parts keep what they have
  const std::span<const std::int32_t> active = ctx.active.parts();
  const std::size_t count = skip ? active.size() : ctx.parts.size();
  thread_pool().for_blocks(count, 8192, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      const std::int32_t k = skip ? active[j] : static_cast<std::int32_t>(j);
      part_reach_[k] = reach_of_part(ctx, k);
      part_boxes_[k] = reach_box(ctx, k, part_reach_[k]);
      // A part that leaves its fat box gets room for about four steps at its present reach and
      // a tenth of its size besides (so that a floe at rest, or creeping, keeps its box long).
      part_margin_[k] = 4.0 * part_reach_[k] + 0.1 * ctx.parts.radius(k);
    }
  });
  pair_cache_.find_pairs(part_boxes_, part_margin_, ctx.parts.body(), ctx.parts.immovable(), pairs_,
                         skip ? active : std::span<const std::int32_t>());
}

Aabb ContactPipeline::reach_box(const StepContext& ctx, std::int32_t k, double reach) const {
  const double fat = reach + 0.5 * ctx.settings.allowed_penetration;
  return {ctx.parts.boxes()[k].lo - Vec2{fat, fat}, ctx.parts.boxes()[k].hi + Vec2{fat, fat}};
}

void ContactPipeline::collide_parts(const StepContext& ctx, PartPair pair, double reach_a, double reach_b,
                                    NarrowManifold& m, SeparationHint* hint) const {
  // Contacts within both parts' reach this step (speculative), plus the allowed overlap; the
  // reference face kept unless the other is better by a tenth of it.
  auto geometry = [&](std::int32_t k) {
    const std::int32_t b = ctx.parts.body()[k];
    return ctx.parts.geometry(k, ctx.bodies.position[b], ctx.bodies.rotation[b]);
  };
  const double allowed = ctx.settings.allowed_penetration;
  collide(geometry(pair.a), geometry(pair.b), reach_a + reach_b + allowed, 0.1 * allowed, m, hint);
}

void ContactPipeline::collide_pairs(const StepContext& ctx, bool redetection) {
  // Narrow phase: each pair into its own slot, blocks of pairs on the pool's threads (a pure
  // function of the pair: the same manifolds on any number of threads).
  resize_with_headroom(narrow_, pairs_.size());  // with room: the pairs set new highs as a pack breathes
  resize_with_headroom(narrow_points_, pairs_.size());
  // Per pair, its slot at the last narrow phase (both lists sorted): its separation hint
  // carries over, and where both parts were kept in place with the same reaches, its manifold.
  // A redetection's narrow phase follows the step's first one with every part where it was
  // (only the reaches of the bodies that outran theirs grew): each pair of parts whose reaches
  // stayed the same gets the first one's manifold.
  const bool may_reuse = (any_kept_ || redetection) && !previous_pairs_.empty();
  if (may_reuse) resize_with_headroom(reuse_, pairs_.size());
  resize_with_headroom(narrow_hint_, pairs_.size());
  auto same_reach = [&](std::int32_t part) { return same_bits(part_reach_[part], previous_reach_[part]); };
  const std::span<const std::uint8_t> kept = ctx.parts.kept();
  std::size_t last = 0;
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const PartPair pair = pairs_[k];
    while (last < previous_pairs_.size() && previous_pairs_[last] < pair) ++last;
    const bool met = last < previous_pairs_.size() && previous_pairs_[last] == pair;
    narrow_hint_[k] = met ? previous_hint_[last] : SeparationHint{};
    if (!may_reuse) continue;
    reuse_[k] = -1;
    if (met && (redetection || (kept[pair.a] && kept[pair.b])) && same_reach(pair.a) && same_reach(pair.b)) {
      reuse_[k] = static_cast<std::int32_t>(last);
      ++narrow_reused_;
    }
  }
  narrow_pairs_ += static_cast<std::int64_t>(pairs_.size());
  const std::size_t blocks = (pairs_.size() + kPairGrain - 1) / kPairGrain;
  block_contacts_.assign(blocks + 1, 0);
  const PartSet& parts = ctx.parts;
  thread_pool().for_blocks(pairs_.size(), kPairGrain, [&](std::size_t begin, std::size_t end) {
    // The block's contacts, counted as each slot is written (a second pass would reread every
    // slot, out of cache at 16k floes): they place the block's contacts in the list.
    std::size_t found = 0;
    for (std::size_t k = begin; k < end; ++k) {
      // The geometry of the pair a few on: its second part is anywhere in the field (pairs are
      // sorted by first part), and collide()'s first loads of it, and of the reference face's
      // frame data, wait on memory. A prefetch changes no value. A pair whose manifold is
      // reused is not collided: its geometry is not asked for.
      if (k + kPrefetchPairs < end && !(may_reuse && reuse_[k + kPrefetchPairs] >= 0)) {
        const PartPair ahead = pairs_[k + kPrefetchPairs];
        parts.prefetch_world(ahead.b);
        parts.prefetch_local(ahead.b);
        parts.prefetch_local(ahead.a);
      }
      if (may_reuse && reuse_[k] >= 0) {
        const auto r = static_cast<std::size_t>(reuse_[k]);
        // A pair without contact is read for its point count alone (most pairs of fat boxes).
        narrow_points_[k] = previous_narrow_points_[r];
        if (narrow_points_[k] != 0) copy_manifold(previous_narrow_[r], narrow_[k]);
        found += narrow_points_[k] != 0;
        continue;
      }
      const PartPair pair = pairs_[k];
      // Every field the solver reads is set here or by collide() (which sets the face and
      // each point it adds in full); a slot is not cleared first (a NarrowManifold is 192 bytes,
      // and most pairs of fat boxes have no contact).
      NarrowManifold& m = narrow_[k];
      name_pair(m, pair.a, pair.b, parts.body(), ctx.contact);
      collide_parts(ctx, pair, part_reach_[pair.a], part_reach_[pair.b], m, &narrow_hint_[k]);
      narrow_points_[k] = static_cast<std::uint8_t>(m.point_count);
      found += m.point_count != 0;
    }
    block_contacts_[begin / kPairGrain + 1] = found;
  });
}

void ContactPipeline::build_contact_list(const StepContext& ctx, std::span<const Manifold> held_list,
                                         bool redetection) {
  // The contact list is written over the last one (or, redetecting, over the one before the
  // step's first, which the redetection keeps), slot by slot (fill_manifold writes what each
  // contact holds, not the whole struct), and cut to length at the end; what the warm start
  // needs of the last step's is in carried_.
  // The contacts, in pair order, each into its slot of the list: per block of pairs (the
  // narrow phase's blocks), its first slot is the count of contacts in the blocks before it.
  const std::size_t blocks = block_contacts_.size() - 1;
  for (std::size_t b = 0; b < blocks; ++b) block_contacts_[b + 1] += block_contacts_[b];
  const std::size_t contacts = block_contacts_[blocks];
  if (manifolds_.size() < contacts) resize_with_headroom(manifolds_, contacts);
  const BodyArrays& bodies = ctx.bodies;
  // Blocks on the pool's threads again: each manifold is written from its own slot, its
  // impulses carried over from last step's list (both lists are sorted by (part_a, part_b):
  // a merge from where the block's first pair would be) and classified, a function of the
  // manifold and the bodies alone: the same list on any number of threads. Redetecting, a point
  // the step's first pass held is classified as it was there (prepare_contact), found by the
  // same merge over that pass's list.
  thread_pool().for_blocks(pairs_.size(), kPairGrain, [&](std::size_t begin, std::size_t end) {
    std::size_t slot = block_contacts_[begin / kPairGrain];
    auto old = static_cast<std::size_t>(find_pair(carried_, pairs_[begin]) - carried_.begin());
    std::size_t first =
        redetection ? static_cast<std::size_t>(find_pair(held_list, pairs_[begin]) - held_list.begin()) : 0;
    for (std::size_t k = begin; k < end; ++k) {
      // The narrow slots it reads and the manifolds it writes, a few records on (the carried
      // contacts, 56 bytes each in order, are left to the hardware's prefetch). A prefetch
      // changes no value.
      if (k + kPrefetchPairs < end) prefetch_lines(&narrow_[k + kPrefetchPairs], sizeof(NarrowManifold));
      const PartPair pair = pairs_[k];
      if (narrow_points_[k] == 0) continue;
      if (slot + 2 < contacts) prefetch_lines(&manifolds_[slot + 2], kManifoldWriteBytes);
      const NarrowManifold& found = narrow_[k];  // narrow_ keeps the narrow phase's own result (reuse)
      Manifold& m = manifolds_[slot++];
      fill_manifold(found, m);
      // Read from the narrow phase's slot, not the fresh copy: a load from a block just copied
      // waits for the copy's stores to retire.
      while (old < carried_.size() && PartPair{carried_[old].part_a, carried_[old].part_b} < pair) ++old;
      if (old < carried_.size() && carried_[old].part_a == pair.a && carried_[old].part_b == pair.b) {
        const CarriedContact& prev = carried_[old];
        for (int q = 0; q < found.point_count; ++q) {
          for (int j = 0; j < prev.point_count; ++j) {
            if (prev.id[j] != found.points[q].id) continue;
            // Pressed last step: the bodies are already in contact here, so this is no collision.
            m.points[q].persistent = prev.normal_impulse[j] > 0.0;
            // Only resting impulses are a good first guess: a collision's impulse is a one-off.
            // A manifold between two held bodies (sleeping or fixed) keeps its impulses whatever
            // the warm start: nothing solves it, and they are the load it carries.
            const bool held = bodies.inv_mass[m.body_a] == 0.0 && bodies.inv_mass[m.body_b] == 0.0;
            if ((ctx.settings.warm_start || held) && prev.kind[j] == ContactKind::resting) {
              m.points[q].normal_impulse = prev.normal_impulse[j];
              m.points[q].tangent_impulse = prev.tangent_impulse[j];
            }
          }
        }
      }
      const Manifold* held = nullptr;
      if (redetection) {
        while (first < held_list.size() && PartPair{held_list[first].part_a, held_list[first].part_b} < pair) ++first;
        if (first < held_list.size() && held_list[first].part_a == pair.a && held_list[first].part_b == pair.b)
          held = &held_list[first];
      }
      // Classified here, while the manifold is at hand (one pass over the contact list, not three).
      prepare_contact(m, bodies, ctx.dt, ctx.contact.collision_threshold, held);
    }
  });
  manifolds_.resize(contacts);
  std::swap(narrow_, previous_narrow_);
  std::swap(narrow_points_, previous_narrow_points_);
  std::swap(narrow_hint_, previous_hint_);
  reserve_with_headroom(previous_pairs_, pairs_.size());
  previous_pairs_.assign(pairs_.begin(), pairs_.end());
  previous_reach_.assign(part_reach_.begin(), part_reach_.end());
}

void ContactPipeline::record() {
  // The step's contacts with an impulse, for the recorder; and each contact as the next step's
  // contact list reads it (carried_), in the same pass over the manifolds.
  records_.clear();
  resize_with_headroom(carried_, manifolds_.size());
  for (std::size_t i = 0; i < manifolds_.size(); ++i) {
    const Manifold& m = manifolds_[i];
    CarriedContact& c = carried_[i];
    c.part_a = m.part_a;
    c.part_b = m.part_b;
    c.point_count = m.point_count;
    for (int k = 0; k < m.point_count; ++k) {
      const ManifoldPoint& p = m.points[k];
      c.id[k] = p.id;
      c.kind[k] = p.kind;
      c.normal_impulse[k] = p.normal_impulse;
      c.tangent_impulse[k] = p.tangent_impulse;
      if (p.normal_impulse == 0.0 && p.tangent_impulse == 0.0) continue;
      records_.push_back(ContactRecord{m.body_a, m.body_b, p.point, m.normal, p.normal_impulse, p.tangent_impulse,
                                       p.approach_velocity, p.separation, p.kind});
    }
  }
}

void ContactPipeline::save_contacts(StateWriter& out) const {
  out.value(static_cast<std::uint64_t>(carried_.size()));  // the step's contacts (record() wrote them)
  for (const CarriedContact& c : carried_) {
    out.value(c.part_a);
    out.value(c.part_b);
    out.value(c.point_count);
    for (int k = 0; k < c.point_count; ++k) {
      out.value(c.id[k]);
      out.value(c.normal_impulse[k]);
      out.value(c.tangent_impulse[k]);
      out.value(c.kind[k]);
    }
  }
  pair_cache_.save(out);
}

void ContactPipeline::restore_contacts(StateReader& in, const StepContext& ctx) {
  const auto count = in.value<std::uint64_t>();
  if (count > in.left()) throw StateError("checkpoint: truncated");
  carried_.assign(static_cast<std::size_t>(count), CarriedContact{});
  const auto parts = static_cast<std::int32_t>(ctx.parts.size());
  for (CarriedContact& c : carried_) {
    in.value(c.part_a);
    in.value(c.part_b);
    in.value(c.point_count);
    if (c.part_a < 0 || c.part_a >= c.part_b || c.part_b >= parts || c.point_count < 1 || c.point_count > 2)
      throw StateError("checkpoint: a contact manifold that does not fit this scene");
    for (int k = 0; k < c.point_count; ++k) {
      in.value(c.id[k]);
      in.value(c.normal_impulse[k]);
      in.value(c.tangent_impulse[k]);
      in.value(c.kind[k]);
    }
  }
  manifolds_.clear();  // the next step's contact list is made from carried_ alone
  records_.clear();    // the contacts of the step before the checkpoint are not needed again
  pair_cache_.restore(in, ctx.parts.body(), ctx.parts.immovable());
  forget_narrow();  // a restored run computes its first narrow phase afresh, as the saved one did
}

}  // namespace floedem
