#include "collision/pair_cache.hpp"

#include <algorithm>
#include <cmath>

#include "parallel/thread_pool.hpp"
#include "engine/headroom.hpp"

namespace floedem {

namespace {

bool inside(const Aabb& inner, const Aabb& outer) {
  return inner.lo.x >= outer.lo.x && inner.lo.y >= outer.lo.y && inner.hi.x <= outer.hi.x && inner.hi.y <= outer.hi.y;
}

/// The most parts whose fat boxes may change between rebuilds: each of them is tested
/// directly against the others that changed, so this bounds that quadratic term.
std::size_t stale_limit(std::size_t n) {
  return std::min<std::size_t>(n / 8, static_cast<std::size_t>(4.0 * std::sqrt(static_cast<double>(n))) + 64);
}

}  // namespace

void PairCache::find_pairs(std::span<const Aabb> boxes, std::span<const double> margin,
                           std::span<const std::int32_t> body, std::span<const std::uint8_t> fixed,
                           std::vector<PartPair>& out, std::span<const std::int32_t> active) {
  const std::size_t n = boxes.size();
  bool full = fat_.size() != n;
  if (full) {
    fat_.resize(n);
    stale_.assign(n, 0);
    moved_.assign(n, 0);
    stale_list_.clear();
  }
  // Per part (blocks on the pool's threads): a new fat box where it left its own; then, in
  // part order, the list of those that did. A part left out of `active` has not left its box.
  const bool all = full || active.empty();
  const std::size_t listed = all ? n : active.size();
  auto part = [&](std::size_t j) { return all ? j : static_cast<std::size_t>(active[j]); };
  left_.resize(n);
  thread_pool().for_blocks(listed, 8192, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      const std::size_t k = part(j);
      left_[k] = full || !inside(boxes[k], fat_[k]);
      if (!left_[k]) continue;
      const Vec2 m{margin[k], margin[k]};
      fat_[k] = {boxes[k].lo - m, boxes[k].hi + m};
    }
  });
  moved_list_.clear();
  for (std::size_t j = 0; j < listed; ++j)
    if (left_[part(j)]) moved_list_.push_back(static_cast<std::int32_t>(part(j)));
  refreshed_ += static_cast<std::int64_t>(moved_list_.size());
  if (!full) {
    for (const std::int32_t k : moved_list_)
      if (!stale_[k]) {
        stale_[k] = 1;
        stale_list_.push_back(k);
      }
    full = stale_list_.size() > stale_limit(n) || !grid_.gridded();
  }
  if (full)
    rebuild(body, fixed);
  else if (!moved_list_.empty())
    refresh(body, fixed);
  // The pairs of this step: candidates whose step boxes overlap (candidates are sorted), found
  // by blocks of candidates on the pool's threads and joined in block order. Each candidate is
  // written to the block's next place and the count moved on by whether its boxes overlap
  // (Aabb::overlaps_unbranched): no branch on the data, which goes either way from one
  // candidate to the next, so a branch would be mispredicted half the time.
  constexpr std::size_t kGrain = 16384;
  const std::size_t blocks = (candidates_.size() + kGrain - 1) / kGrain;
  if (overlapping_.size() < blocks) overlapping_.resize(blocks);
  if (overlapping_count_.size() < blocks) overlapping_count_.resize(blocks);
  thread_pool().for_blocks(candidates_.size(), kGrain, [&](std::size_t begin, std::size_t end) {
    std::vector<PartPair>& found = overlapping_[begin / kGrain];
    if (found.size() < end - begin) found.resize(kGrain);  // once: a block is never longer
    std::size_t count = 0;
    for (std::size_t k = begin; k < end; ++k) {
      const PartPair c = candidates_[k];
      found[count] = c;
      count += static_cast<std::size_t>(boxes[c.a].overlaps_unbranched(boxes[c.b]));
    }
    overlapping_count_[begin / kGrain] = count;
  });
  // Room for all first (and half as many again): joined by range inserts alone, the list was
  // reallocated here on 0.148 of the packed 4k field's steps (traced; 0.004 allocations a step
  // in all with this).
  std::size_t total = 0;
  for (std::size_t b = 0; b < blocks; ++b) total += overlapping_count_[b];
  reserve_with_headroom(out, total);
  out.clear();
  for (std::size_t b = 0; b < blocks; ++b) {
    const auto first = overlapping_[b].begin();
    out.insert(out.end(), first, first + static_cast<std::ptrdiff_t>(overlapping_count_[b]));
  }
}

void PairCache::parts_near(const Aabb& box, std::vector<std::int32_t>& out) const {
  out.clear();
  if (!grid_.gridded()) {
    for (std::size_t k = 0; k < fat_.size(); ++k)
      if (fat_[k].overlaps(box)) out.push_back(static_cast<std::int32_t>(k));
    return;
  }
  grid_.query(box, out);
  std::erase_if(out, [&](std::int32_t j) { return stale_[j] || !fat_[j].overlaps(box); });  // stale: old grid entry
  for (const std::int32_t j : stale_list_)
    if (fat_[j].overlaps(box)) out.push_back(j);
}

void PairCache::rebuild(std::span<const std::int32_t> body, std::span<const std::uint8_t> fixed) {
  grid_.find_pairs(fat_, body, fixed, candidates_);
  for (const std::int32_t k : stale_list_) stale_[k] = 0;
  stale_list_.clear();
  ++rebuilds_;
}

void PairCache::refresh(std::span<const std::int32_t> body, std::span<const std::uint8_t> fixed) {
  // New candidates of the parts whose fat box changed this step.
  for (const std::int32_t k : moved_list_) moved_[k] = 1;
  fresh_.clear();
  auto consider = [&](std::int32_t i, std::int32_t j) {
    if (i == j || body[i] == body[j] || (fixed[i] && fixed[j]) || !fat_[i].overlaps(fat_[j])) return;
    fresh_.push_back({std::min(i, j), std::max(i, j)});
  };
  for (const std::int32_t m : moved_list_) {
    hits_.clear();
    grid_.query(fat_[m], hits_);
    for (const std::int32_t j : hits_)
      if (!stale_[j]) consider(m, j);  // the grid holds j's present fat box
    for (const std::int32_t j : stale_list_) consider(m, j);
  }
  std::sort(fresh_.begin(), fresh_.end());
  fresh_.erase(std::unique(fresh_.begin(), fresh_.end()), fresh_.end());
  // Old candidates of the moved parts go; the rest stay; both lists are sorted: merged in one
  // pass into the spare list, which becomes the candidates (the old ones the spare). The
  // same list as std::merge of the kept and the fresh (no pair is in both: a fresh pair has a
  // moved part, a kept one none), in one read and one write of it instead of two each: a few
  // parts leave their fat boxes on most steps of the towing case, whose list is a field's.
  resize_with_headroom(spare_, candidates_.size() + fresh_.size());
  auto out = spare_.begin();
  auto f = fresh_.cbegin();
  for (const PartPair& p : candidates_) {
    if (moved_[p.a] || moved_[p.b]) continue;
    for (; f != fresh_.cend() && *f < p; ++f) *out++ = *f;
    *out++ = p;
  }
  out = std::copy(f, fresh_.cend(), out);
  spare_.resize(static_cast<std::size_t>(out - spare_.begin()));
  std::swap(candidates_, spare_);
  for (const std::int32_t k : moved_list_) moved_[k] = 0;
}

void PairCache::save(StateWriter& out) const {
  out.tag("pair_cache");
  out.vector(fat_);
  out.vector(stale_list_);
  out.vector(candidates_);
  out.value(rebuilds_);
  out.value(refreshed_);
}

void PairCache::restore(StateReader& in, std::span<const std::int32_t> body, std::span<const std::uint8_t> fixed) {
  in.tag("pair_cache");
  in.vector(fat_);
  if (!fat_.empty() && fat_.size() != body.size()) throw StateError("checkpoint: the broad phase has another number of parts");
  in.vector(stale_list_);
  in.vector(candidates_);
  in.value(rebuilds_);
  in.value(refreshed_);
  const std::size_t n = fat_.size();
  stale_.assign(n, 0);
  moved_.assign(n, 0);
  for (const std::int32_t k : stale_list_) {
    if (k < 0 || static_cast<std::size_t>(k) >= n) throw StateError("checkpoint: broad phase part out of range");
    stale_[k] = 1;
  }
  for (const PartPair& p : candidates_)
    if (p.a < 0 || p.b < 0 || static_cast<std::size_t>(p.b) >= n) throw StateError("checkpoint: broad phase pair out of range");
  if (n > 0) grid_.find_pairs(fat_, body, fixed, fresh_);  // the grid only; its pairs are not used
}

}  // namespace floedem
