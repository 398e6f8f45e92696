#include "solver/redetection.hpp"

#include <algorithm>
#include <cmath>

#include "solver/contact_solver.hpp"

namespace floedem {

Redetection::Redetection(const StepContext& ctx) {
  const std::size_t n = ctx.bodies.position.size();
  outran_.assign(n, 0);
  body_island_.assign(n, -1);
  resolve_.assign(n, 0);
  // A body is listed at most once: room for all, so that the first redetection to mark a
  // packed field's large island does not allocate mid-run.
  resolve_list_.reserve(n);
}

void Redetection::run(StepContext& ctx, ContactPipeline& pipeline, IslandStage& islands, SleepSets& sleep) {
  // A redetection builds the step's list again over solved_'s storage (redetect): room kept for
  // as many manifolds as the list has, so that the first redetection of a run, however late,
  // does not allocate (it grows when the list itself does).
  if (ctx.settings.redetect && solved_.capacity() < pipeline.manifolds().capacity())
    solved_.reserve(pipeline.manifolds().capacity());
  for (int pass = 0; ctx.settings.redetect && pass < kMaxPasses && outran_reach(ctx, pipeline, islands.islands());
       ++pass) {
    const bool unseen = meets_unseen_contact(ctx, pipeline);
    if (unseen) {
      redetect(ctx, pipeline, islands, sleep);
      ++redetections_;
    }
    for (const std::int32_t b : outran_list_) outran_[b] = 0;
    outran_list_.clear();
    if (!unseen) break;
  }
}

bool Redetection::outran_reach(StepContext& ctx, const ContactPipeline& pipeline, const ContactIslands& islands) {
  // Per part: how far it can move this step at the velocities after the impulses, against the
  // reach its pairs were found with; beyond it by half the allowed overlap, the reach of its
  // body is widened to the new speed and the step's contacts found again. Only bodies with
  // contacts can have changed speed since the reach was set (from the velocities after the
  // loads), and one within both its linear and its angular reach has no part beyond its own:
  // those checks first (the towing case's 5 000 floes cost nothing more where none is struck).
  // Each moving body of a contact once, from the islands the solve just built (a packed floe
  // has some six contacts: a loop over the manifolds looked at it six times).
  const std::span<const double> part_reach = pipeline.part_reach();
  for (const std::int32_t b : islands.all_bodies()) {
    if (!ctx.moves[b] || outran_[b]) continue;
    const double linear = ctx.dt * length(ctx.bodies.velocity[b]);
    const double angular = ctx.dt * std::abs(ctx.bodies.angular_velocity[b]);
    if (linear <= ctx.linear_reach[b] && angular <= ctx.angular_reach[b]) continue;
    bool beyond = false;
    for (std::int32_t k = ctx.parts.first_part(b); k < ctx.parts.first_part(b + 1); ++k)
      beyond = beyond ||
               linear + angular * ctx.parts.radius(k) > part_reach[k] + 0.5 * ctx.settings.allowed_penetration;
    if (!beyond) continue;
    ctx.linear_reach[b] = std::max(ctx.linear_reach[b], linear);
    ctx.angular_reach[b] = std::max(ctx.angular_reach[b], angular);
    outran_[b] = 1;
    outran_list_.push_back(b);
  }
  return !outran_list_.empty();
}

bool Redetection::meets_unseen_contact(const StepContext& ctx, const ContactPipeline& pipeline) {
  // The parts of the bodies that outran their reach, against the parts near their widened
  // boxes: a point the step's manifolds do not hold, closing by more than half the allowed
  // overlap at the velocities the solve left (gap + dt u_n), calls for the step to be solved
  // again. The rest cost a box query and a narrow phase each (towing: most floes the iceberg
  // strikes outrun the reach of a floe at rest, and meet nothing new within the step).
  const double slop = 0.5 * ctx.settings.allowed_penetration;
  const LineVector<Manifold>& manifolds = pipeline.manifolds();
  const std::span<const std::int32_t> part_body = ctx.parts.body();
  NarrowManifold probe;
  return visit_parts_near_outrun(ctx, pipeline, [&](std::int32_t k, std::int32_t j) {
    const std::int32_t a = part_body[std::min(j, k)], b = part_body[std::max(j, k)];
    if (a == b || (ctx.parts.immovable()[j] && ctx.parts.immovable()[k])) return false;
    const PartPair pair{std::min(j, k), std::max(j, k)};
    pipeline.collide_parts(ctx, pair, pipeline.reach_of_part(ctx, pair.a), pipeline.reach_of_part(ctx, pair.b), probe);
    if (probe.point_count == 0) return false;
    const auto held = find_pair(manifolds, pair);
    const bool pair_held = held != manifolds.end() && held->part_a == pair.a && held->part_b == pair.b;
    for (int q = 0; q < probe.point_count; ++q) {
      const NarrowPoint& p = probe.points[q];
      bool point_held = false;
      for (int h = 0; pair_held && h < held->point_count; ++h) point_held = point_held || held->points[h].id == p.id;
      if (point_held) continue;
      const Vec2 u = relative_velocity(ctx.bodies, a, b, p.point - ctx.bodies.position[a],
                                       p.point - ctx.bodies.position[b]);
      if (p.separation + ctx.dt * dot(u, probe.normal) < -slop) return true;
    }
    return false;
  });
}

template <class Visit>
bool Redetection::visit_parts_near_outrun(const StepContext& ctx, const ContactPipeline& pipeline, Visit&& visit) {
  auto grown = [&](std::int32_t k) { return pipeline.reach_box(ctx, k, pipeline.reach_of_part(ctx, k)); };
  for (const std::int32_t body : outran_list_)
    for (std::int32_t k = ctx.parts.first_part(body); k < ctx.parts.first_part(body + 1); ++k) {
      const Aabb box = grown(k);
      pipeline.pair_cache().parts_near(box, near_);
      for (const std::int32_t j : near_)
        if (grown(j).overlaps(box) && visit(k, j)) return true;
    }
  return false;
}

void Redetection::redetect(StepContext& ctx, ContactPipeline& pipeline, IslandStage& island_stage, SleepSets& sleep) {
  // Which contacts can change: those of a part whose reach grew (the bodies of outran_list_).
  // Every other pair keeps its parts' reaches, so the narrow phase gives it the manifold it had
  // (collide_pairs), and a new contact has a body of outran_list_ at one end. So the islands
  // of the last solve that hold such a body, or a body within its widened reach, are all that
  // can change: they are marked, their impulses taken off, and they are solved again from the
  // velocities after the loads. Every other island keeps its solution to the bit. A point the
  // first pass held keeps the classification it had there, made on the velocities before the
  // loads (the contact list): on those after them, a floe pressed on a wall by its load
  // approaches it at F dt / m, a collision rather than a resting contact, and with restitution
  // it would bounce off because a floe of its island, or one a kilometre away, was struck
  // (test_impacts.cpp). Only a point the first pass did not hold, which the widened reach
  // found, is classified on the velocities after the loads. Marking is closed: a new island is
  // the union of marked islands joined by new contacts, or an old island untouched.
  const ContactIslands& islands = island_stage.islands();
  LineVector<Manifold>& manifolds = pipeline.manifolds();
  const std::size_t ni = islands.size();
  for (std::size_t i = 0; i < ni; ++i)
    for (const std::int32_t b : islands.bodies(i)) body_island_[b] = static_cast<std::int32_t>(i);
  island_resolved_.assign(ni, 0);
  for (const std::int32_t body : outran_list_) mark_for_resolve(ctx, islands, body);
  visit_parts_near_outrun(ctx, pipeline, [&](std::int32_t, std::int32_t j) {
    mark_for_resolve(ctx, islands, ctx.parts.body()[j]);
    return false;
  });
  // The accumulated impulses are all that the solve applied (warm start included; a cold
  // restart or a direct solve reset them with the velocities): taken off, the velocities are
  // those after the loads, to rounding. Island by island: each body sees its manifolds in
  // their order in the list, as one pass over the list would apply them.
  auto take_off = [&](std::size_t i) {
    for (const std::int32_t k : islands.manifolds(i))
      apply_accumulated_impulses({&manifolds[static_cast<std::size_t>(k)], 1}, ctx.bodies, -1.0);
  };
  for (std::size_t i = 0; i < ni; ++i)
    if (island_resolved_[i]) take_off(i);
  pipeline.pair_up(ctx);
  pipeline.collide_pairs(ctx, /*redetection=*/true);
  // A body struck into a sleeping one wakes its group (with its loads), which joins islands
  // that were not marked: then every island is solved again (rare: the sleepers are far from
  // the floes that strike). Taken off before the wake: a sleeping body held, as in the solve.
  // The same where the unmarked contacts are not the last solve's (the argument above says they
  // are; checked, since a kept island with a contact more or less would be wrong).
  const bool all = (sleep.any_asleep() && sleep.touches_sleeper(ctx, pipeline.pairs(), pipeline.pair_points())) ||
                   !unmarked_contacts_held(ctx, pipeline);
  if (all) {
    for (std::size_t i = 0; i < ni; ++i)
      if (!island_resolved_[i]) take_off(i);
    if (sleep.any_asleep()) sleep.wake_touched(ctx, pipeline.pairs(), pipeline.pair_points());
  }
  for (std::size_t i = 0; i < ni; ++i)
    for (const std::int32_t b : islands.bodies(i)) body_island_[b] = -1;
  std::swap(manifolds, solved_);  // the solved list kept, the new one built over the old
  pipeline.build_contact_list(ctx, solved_, /*redetection=*/true);
  if (!all) keep_solved_contacts(pipeline);
  island_stage.solve(ctx, pipeline.manifolds(), all ? std::span<const std::uint8_t>() : std::span<const std::uint8_t>(resolve_));
  for (const std::int32_t b : resolve_list_) resolve_[b] = 0;
  resolve_list_.clear();
}

void Redetection::mark_for_resolve(const StepContext& ctx, const ContactIslands& islands, std::int32_t body) {
  // Only a moving body is marked: a fixed, towed or sleeping one joins no island (an impulse
  // cannot change its velocity), and its contacts go with the moving body at their other end.
  if (ctx.bodies.inv_mass[body] == 0.0) return;
  const std::int32_t i = body_island_[body];
  if (i < 0) {
    if (!resolve_[body]) resolve_list_.push_back(body);
    resolve_[body] = 1;
    return;
  }
  if (island_resolved_[i]) return;
  island_resolved_[i] = 1;
  for (const std::int32_t b : islands.bodies(static_cast<std::size_t>(i))) {
    resolve_[b] = 1;
    resolve_list_.push_back(b);
  }
}

bool Redetection::unmarked_contacts_held(const StepContext& ctx, const ContactPipeline& pipeline) const {
  // The new pairs with contact points and no marked body, against the last solve's manifolds
  // with no marked body: the same pairs, in the same order (both sorted by pair).
  const LineVector<Manifold>& manifolds = pipeline.manifolds();
  const std::span<const PartPair> pairs = pipeline.pairs();
  const std::span<const std::uint8_t> points = pipeline.pair_points();
  auto unmarked = [&](std::int32_t a, std::int32_t b) { return !resolve_[a] && !resolve_[b]; };
  std::size_t old = 0;
  auto next_old = [&] {
    while (old < manifolds.size() && !unmarked(manifolds[old].body_a, manifolds[old].body_b)) ++old;
  };
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (points[k] == 0) continue;
    const PartPair pair = pairs[k];
    if (!unmarked(ctx.parts.body()[pair.a], ctx.parts.body()[pair.b])) continue;
    next_old();
    if (old == manifolds.size() || manifolds[old].part_a != pair.a || manifolds[old].part_b != pair.b) return false;
    ++old;
  }
  next_old();
  return old == manifolds.size();
}

void Redetection::keep_solved_contacts(ContactPipeline& pipeline) {
  // A contact of two unmarked bodies is the one the last solve left (unmarked_contacts_held):
  // its impulses, its classification on the velocities before the step, and its bodies'
  // velocities stay.
  std::size_t old = 0;
  for (Manifold& m : pipeline.manifolds()) {
    if (resolve_[m.body_a] || resolve_[m.body_b]) continue;
    while (solved_[old].part_a != m.part_a || solved_[old].part_b != m.part_b) ++old;
    m = solved_[old++];
  }
}

}  // namespace floedem
