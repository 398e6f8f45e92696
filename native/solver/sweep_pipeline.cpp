#include "solver/sweep_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include "parallel/thread_pool.hpp"
#include "parallel/threads.hpp"
#include "solver/headroom.hpp"
#include "solver/sweep_row.hpp"

namespace floedem {

namespace {
// Rows a part must have at least for a thread of its own: the pipeline's set-up (a few passes
// over the rows) and its waits at the cuts must stay small against the part's sweeps.
constexpr std::size_t kRowsPerPart = 1024;

constexpr std::uint8_t kWaitA = 1, kWaitB = 2;    // a wait before the row, for its body a, b
constexpr std::uint8_t kPublish = 4;              // another part waits for this row
constexpr std::uint8_t kFirstA = 8, kFirstB = 16; // the sweep's first update of body a, b

bool moving(const BodyArrays& s, std::int32_t body) { return s.inv_mass[static_cast<std::size_t>(body)] != 0.0; }

// Waits for another thread: a short watch, then the core is offered to others (more threads
// than cores, as with ctest -j on a small machine).
template <class Ready>
bool wait_until(Ready ready) {
  for (int spins = 0;; ++spins) {
    if (ready()) return true;
    if (spins < 256)
      cpu_relax();
    else
      std::this_thread::yield();
  }
}
}  // namespace

unsigned SweepPipeline::parts_for(std::size_t rows) {
  const std::size_t threads = thread_pool().size();
  return static_cast<unsigned>(std::max<std::size_t>(1, std::min(threads, rows / kRowsPerPart)));
}

void SweepPipeline::plan(std::span<const SweepRow> rows, const BodyArrays& s, unsigned parts) {
  // Four passes over the rows (the plan costs about a sweep and a half on one thread; it was
  // twice that with a pass per step and a selection for the cuts).
  const std::size_t r_count = rows.size();
  resize_with_headroom(key_, 2 * r_count);
  resize_with_headroom(place_, r_count);
  if (last_.size() < s.inv_mass.size()) {
    last_.resize(s.inv_mass.size());
    current_.resize(s.inv_mass.size());
  }
  // 1. Per row, the largest x and y of its moving bodies (the position of its further body along
  // either axis), and per moving body, its last row of the sweep.
  constexpr double none = -std::numeric_limits<double>::infinity();
  Vec2 lo{-none, -none}, hi{none, none};
  for (std::size_t i = 0; i < r_count; ++i) {
    Vec2 key{none, none};
    for (const std::int32_t b : {rows[i].body_a, rows[i].body_b})
      if (moving(s, b)) {
        const Vec2 x = s.position[static_cast<std::size_t>(b)];
        key = {std::max(key.x, x.x), std::max(key.y, x.y)};
        last_[static_cast<std::size_t>(b)] = static_cast<std::int32_t>(i);
        current_[static_cast<std::size_t>(b)] = -1;
      }
    key_[2 * i] = key.x;
    key_[2 * i + 1] = key.y;
    if (key.x > none) {
      lo = {std::min(lo.x, key.x), std::min(lo.y, key.y)};
      hi = {std::max(hi.x, key.x), std::max(hi.y, key.y)};
    }
  }
  // 2. The parts: slabs across the longer extent, of about equal numbers of rows, cut at the
  // edges of a histogram's bins (a row's part is its bin's).
  const int axis = hi.x - lo.x >= hi.y - lo.y ? 0 : 1;
  const double low = axis == 0 ? lo.x : lo.y;
  const double extent = axis == 0 ? hi.x - lo.x : hi.y - lo.y;
  const double scale = extent > 0.0 ? (kBins - 1) / extent : 0.0;
  auto bin_of = [&](std::size_t i) {
    const double key = key_[2 * i + static_cast<std::size_t>(axis)];
    if (!(key > none)) return std::size_t{0};  // a row of no moving body (or a NaN key): part 0
    // Clamped, so that no key makes a bin that is not there: not one beyond the extent, nor a
    // NaN (inf * 0 where coordinates overflow the extent; std::clamp would pass it through, and
    // its cast to an integer is undefined). The bins only place rows in parts: any is correct.
    const double at = (key - low) * scale;
    return at > 0.0 ? static_cast<std::size_t>(std::min(at, double{kBins - 1})) : std::size_t{0};
  };
  std::fill(std::begin(bin_part_), std::end(bin_part_), 0);
  for (std::size_t i = 0; i < r_count; ++i) ++bin_part_[bin_of(i)];
  std::size_t below = 0;
  for (std::size_t bin = 0; bin < kBins; ++bin) {
    const std::size_t count = bin_part_[bin];
    // The part of the bin's middle row: parts of equal numbers of rows, within a bin's count.
    bin_part_[bin] = static_cast<std::uint32_t>(std::min<std::size_t>(parts - 1, (below + count / 2) * parts / r_count));
    below += count;
  }
  // 3. Each row into its part's list, in the serial order.
  if (parts_.size() < parts) parts_.resize(parts);
  for (unsigned t = 0; t < parts; ++t) {
    Part& part = parts_[t];
    part.rows.clear();
    reserve_with_headroom(part.rows, r_count);
    part.waits.clear();
    part.logged_sweep = -1;
    part.logged_bodies = part.logged_rows = 0;
  }
  for (std::size_t i = 0; i < r_count; ++i) {
    const std::uint32_t t = bin_part_[bin_of(i)];
    std::vector<PartRow>& list = parts_[t].rows;
    place_[i] = {static_cast<std::int32_t>(t), static_cast<std::int32_t>(list.size())};
    list.push_back({static_cast<std::int32_t>(i), 0});
  }
  // 4. Per moving body, the update before each of its updates in the serial order: the row
  // before in the same sweep, or (for its first row of a sweep) its last row of the sweep before.
  // Where that row is another part's, a wait.
  std::size_t first_updates[kMaxParts] = {};
  for (unsigned t = 0; t < parts; ++t) reserve_with_headroom(parts_[t].waits, 2 * parts_[t].rows.size());
  for (std::size_t i = 0; i < r_count; ++i) {
    const Place here = place_[i];
    Part& part = parts_[static_cast<std::size_t>(here.part)];
    PartRow& row = part.rows[static_cast<std::size_t>(here.local)];
    for (const bool is_a : {true, false}) {
      const std::int32_t b = is_a ? rows[i].body_a : rows[i].body_b;
      if (!moving(s, b)) continue;
      std::int32_t& seen = current_[static_cast<std::size_t>(b)];
      std::int32_t before = seen;
      std::int64_t offset = 0;
      if (before < 0) {
        before = last_[static_cast<std::size_t>(b)];
        offset = -1;
        row.flags |= is_a ? kFirstA : kFirstB;
        ++first_updates[static_cast<std::size_t>(here.part)];
      }
      seen = static_cast<std::int32_t>(i);
      const Place there = place_[static_cast<std::size_t>(before)];
      if (there.part == here.part) continue;
      // The other part's update `there.local` of this sweep (offset 0) or the one before (-1).
      Part& other = parts_[static_cast<std::size_t>(there.part)];
      const auto size = static_cast<std::int64_t>(other.rows.size());
      part.waits.push_back({there.part, static_cast<std::int32_t>(size), offset * size + there.local + 1});
      row.flags |= is_a ? kWaitA : kWaitB;
      other.rows[static_cast<std::size_t>(there.local)].flags |= kPublish;
    }
  }
  for (unsigned t = 0; t < parts; ++t) {
    resize_with_headroom(parts_[t].body_log, first_updates[t]);
    resize_with_headroom(parts_[t].impulse_log, 2 * parts_[t].rows.size());
  }
}

SweepPipeline::Result SweepPipeline::run(std::span<SweepRow> rows, BodyArrays& bodies, int iterations,
                                         double tolerance) {
  const unsigned parts = std::min<unsigned>(parts_for(rows.size()), kMaxParts);
  if (iterations <= 0 || rows.empty()) return {};
  plan(rows, bodies, parts);
  part_count_ = parts;
  iterations_ = iterations;
  tolerance_ = tolerance;
  if (counters_ < parts) {
    done_ = std::make_unique<Counter[]>(parts);
    counters_ = parts;
  }
  for (unsigned t = 0; t < parts; ++t) done_[t].value.store(0, std::memory_order_relaxed);
  for (SweepSlot& slot : slots_) slot.finished.store(0, std::memory_order_relaxed);
  resize_with_headroom(partial_change_, std::size_t{kSlots} * parts);
  resize_with_headroom(partial_impulse_, std::size_t{kSlots} * parts);
  decided_.store(0, std::memory_order_relaxed);
  last_sweep_.store(iterations - 1, std::memory_order_relaxed);
  converged_ = false;
  // One block per part, each on its own thread: parts_for gives no more parts than the pool
  // has threads, and a part cannot finish before every part has begun (its third sweep waits
  // for the first sweep's decision), so no thread holds a part while another part waits unclaimed.
  thread_pool().for_blocks(parts, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) run_part(static_cast<unsigned>(t), rows, bodies);
  });
  // Every thread has stopped: a sweep made past the last one kept is put back.
  const int kept = last_sweep_.load(std::memory_order_relaxed);
  for (unsigned t = 0; t < parts; ++t)
    if (parts_[t].logged_sweep > kept) {
      undo(parts_[t], rows, bodies);
      ++put_back_;
    }
  return {kept + 1, converged_};
}

void SweepPipeline::run_part(unsigned t, std::span<SweepRow> rows, BodyArrays& bodies) {
  for (int sweep = 0;; ++sweep) {
    // At most one sweep ahead of the decisions: sweep k begins once k - 2 is decided.
    wait_until([&] { return decided_.load(std::memory_order_acquire) >= sweep - 1; });
    if (sweep > last_sweep_.load(std::memory_order_acquire)) return;
    // Speculative while the decision on the sweep before is not known.
    const bool speculative = decided_.load(std::memory_order_acquire) < sweep;
    const bool made = speculative ? sweep_part<true>(t, sweep, rows, bodies) : sweep_part<false>(t, sweep, rows, bodies);
    if (!made) return;
    // The last part to finish the sweep decides it (the stop rule of run_sweeps, on the maxima
    // of the parts' maxima: the same as the serial loop's, a maximum being exact in any order).
    SweepSlot& slot = slots_[sweep % kSlots];
    if (slot.finished.fetch_add(1, std::memory_order_acq_rel) + 1 != static_cast<int>(part_count_)) continue;
    const std::size_t at = static_cast<std::size_t>(sweep % kSlots) * part_count_;
    double change = 0.0, impulse = 0.0;
    for (unsigned p = 0; p < part_count_; ++p) {
      change = std::max(change, partial_change_[at + p]);
      impulse = std::max(impulse, partial_impulse_[at + p]);
    }
    // A sweep made after the one the sweeps stopped at (every part went on into it before the
    // stop was known; it is put back) decides nothing.
    if (sweep <= last_sweep_.load(std::memory_order_relaxed) && change <= tolerance_ * impulse) {
      converged_ = true;
      last_sweep_.store(sweep, std::memory_order_relaxed);
    }
    slot.finished.store(0, std::memory_order_relaxed);  // free for sweep + kSlots (begun after this is decided)
    decided_.store(sweep + 1, std::memory_order_release);
  }
}

template <bool Speculative>
bool SweepPipeline::sweep_part(unsigned t, int sweep, std::span<SweepRow> rows, BodyArrays& s) {
  // The loop keeps its counts in locals and writes the part's only when it leaves: a store per
  // row to the part (next to the other part's in memory) made the threads share a cache line.
  Part& part = parts_[t];
  const std::span<const PartRow> list = part.rows;
  const std::span<const Wait> waits = part.waits;
  const std::span<BodyLog> body_log = part.body_log;
  const std::span<double> impulse_log = part.impulse_log;
  const std::int64_t base = static_cast<std::int64_t>(sweep) * static_cast<std::int64_t>(list.size());
  std::atomic<std::int64_t>& done = done_[t].value;
  part.logged_sweep = Speculative ? sweep : -1;
  std::size_t next_wait = 0, logged_bodies = 0, local = 0;
  double change = 0.0, impulse = 0.0;
  bool made = true;
  for (; local < list.size(); ++local) {
    const PartRow row = list[local];
    if (row.flags & (kWaitA | kWaitB)) {
      const int count = ((row.flags & kWaitA) != 0) + ((row.flags & kWaitB) != 0);
      for (int w = 0; w < count && made; ++w) {
        const Wait& wait = waits[next_wait++];
        const std::int64_t need = static_cast<std::int64_t>(sweep) * wait.size + wait.bias;
        std::atomic<std::int64_t>& other = done_[static_cast<std::size_t>(wait.part)].value;
        if (other.load(std::memory_order_acquire) >= need) continue;
        // Waiting on a part that stopped: this sweep is not to be made (it was speculative).
        wait_until([&] {
          if (other.load(std::memory_order_acquire) >= need) return true;
          made = last_sweep_.load(std::memory_order_relaxed) >= sweep;
          return !made;
        });
      }
      if (!made) break;
    }
    SweepRow& p = rows[static_cast<std::size_t>(row.row)];
    if (Speculative) {
      const auto a = static_cast<std::size_t>(p.body_a), b = static_cast<std::size_t>(p.body_b);
      if (row.flags & kFirstA) body_log[logged_bodies++] = {p.body_a, s.velocity[a], s.angular_velocity[a]};
      if (row.flags & kFirstB) body_log[logged_bodies++] = {p.body_b, s.velocity[b], s.angular_velocity[b]};
      impulse_log[2 * local] = p.normal_impulse;
      impulse_log[2 * local + 1] = p.tangent_impulse;
    }
    const RowChange d = sweep_row(p, s);
    change = std::max(change, std::abs(d.normal) + std::abs(d.tangent));
    impulse = std::max(impulse, p.normal_impulse + std::abs(p.tangent_impulse));
    if (row.flags & kPublish) done.store(base + static_cast<std::int64_t>(local) + 1, std::memory_order_release);
  }
  if (Speculative) {
    part.logged_bodies = logged_bodies;
    part.logged_rows = local;  // the rows made
  }
  if (!made) return false;
  const std::size_t at = static_cast<std::size_t>(sweep % kSlots) * part_count_ + t;
  partial_change_[at] = change;
  partial_impulse_[at] = impulse;
  done.store(base + static_cast<std::int64_t>(list.size()), std::memory_order_release);
  return true;
}

void SweepPipeline::undo(Part& part, std::span<SweepRow> rows, BodyArrays& s) const {
  for (std::size_t local = 0; local < part.logged_rows; ++local) {
    SweepRow& p = rows[static_cast<std::size_t>(part.rows[local].row)];
    p.normal_impulse = part.impulse_log[2 * local];
    p.tangent_impulse = part.impulse_log[2 * local + 1];
  }
  // Each body is logged once a sweep, by its first update (the value the sweep before left).
  for (std::size_t k = 0; k < part.logged_bodies; ++k) {
    const BodyLog& log = part.body_log[k];
    s.velocity[static_cast<std::size_t>(log.body)] = log.velocity;
    s.angular_velocity[static_cast<std::size_t>(log.body)] = log.angular_velocity;
  }
  part.logged_sweep = -1;
}

}  // namespace floedem
