#include "collision/broad_phase.hpp"

#include <algorithm>
#include <cmath>

#include "parallel/thread_pool.hpp"
#include "engine/headroom.hpp"

namespace floedem {

namespace {
constexpr int kBruteForceBelow = 24;  // fewer parts than this: the n^2/2 test is cheaper
constexpr int kMaxLevels = 32;
// Blocks large enough that the pool's hand-over is a small part of each, small enough that a
// large field's blocks share the threads evenly.
constexpr std::size_t kPartGrain = 4096;   // parts a block of the pairs across levels
constexpr std::size_t kCellGrain = 32768;  // cells a block of the pairs within a level
}  // namespace

std::int64_t BroadPhase::Level::cell_x(double x, double x0) const {
  return std::clamp(static_cast<std::int64_t>((x - x0) * inv_h), std::int64_t{0}, nx - 1);
}
std::int64_t BroadPhase::Level::cell_y(double y, double y0) const {
  return std::clamp(static_cast<std::int64_t>((y - y0) * inv_h), std::int64_t{0}, ny - 1);
}

void BroadPhase::find_pairs(std::span<const Aabb> boxes, std::span<const std::int32_t> body,
                            std::span<const std::uint8_t> fixed, std::vector<PartPair>& out) {
  out.clear();
  gridded_ = false;
  const auto n = static_cast<std::int32_t>(boxes.size());
  if (n < 2) return;  // a lone body never builds pairs

  auto consider = [&](std::int32_t i, std::int32_t j) {
    if (body[i] == body[j] || (fixed[i] && fixed[j])) return false;
    return boxes[i].overlaps(boxes[j]);
  };
  if (n < kBruteForceBelow) {
    for (std::int32_t i = 0; i < n; ++i)
      for (std::int32_t j = i + 1; j < n; ++j)
        if (consider(i, j)) out.push_back({i, j});
    return;
  }
  build_grid(boxes);
  collect_pairs(boxes, body, fixed, out);
}

void BroadPhase::build_grid(std::span<const Aabb> boxes) {
  const auto n = static_cast<std::int32_t>(boxes.size());
  // World bounds and the finest cell size (median extent; coarser for a sparse scene).
  Aabb world = boxes[0];
  extents_.resize(n);
  for (std::int32_t i = 0; i < n; ++i) {
    const Aabb& b = boxes[i];
    world.lo.x = std::min(world.lo.x, b.lo.x);
    world.lo.y = std::min(world.lo.y, b.lo.y);
    world.hi.x = std::max(world.hi.x, b.hi.x);
    world.hi.y = std::max(world.hi.y, b.hi.y);
    extents_[i] = std::max(b.hi.x - b.lo.x, b.hi.y - b.lo.y);
  }
  const double wx = world.hi.x - world.lo.x, wy = world.hi.y - world.lo.y;
  level_of_.resize(n);
  {
    std::vector<double>& tmp = extents_;  // nth_element reorders: take the median, then redo extents
    std::nth_element(tmp.begin(), tmp.begin() + n / 2, tmp.end());
  }
  double h0 = std::max(extents_[n / 2], 1e-9);
  const double cells_wanted = 4.0 * n + 64.0;  // never more than ~4 finest cells per part
  if ((wx / h0 + 1.0) * (wy / h0 + 1.0) > cells_wanted) h0 = std::sqrt(std::max(wx * wy, 1e-18) / cells_wanted) * 1.01;
  h0 = std::max(h0, std::max(wx, wy) / 65536.0);

  // Levels and counts.
  int top = 0;
  for (std::int32_t i = 0; i < n; ++i) {
    const double e = std::max(boxes[i].hi.x - boxes[i].lo.x, boxes[i].hi.y - boxes[i].lo.y);
    int l = 0;
    double h = h0;
    while (e > h && l + 1 < kMaxLevels) {
      h *= 2.0;
      ++l;
    }
    level_of_[i] = static_cast<std::uint8_t>(l);
    top = std::max(top, l);
  }
  if (static_cast<int>(levels_.size()) < top + 1) levels_.resize(top + 1);
  for (int l = 0; l <= top; ++l) {
    Level& lv = levels_[l];
    lv.h = h0 * std::ldexp(1.0, l);
    lv.inv_h = 1.0 / lv.h;
    lv.nx = static_cast<std::int64_t>(wx * lv.inv_h) + 1;
    lv.ny = static_cast<std::int64_t>(wy * lv.inv_h) + 1;
    lv.count = 0;
    lv.cell_start.assign(static_cast<std::size_t>(lv.nx * lv.ny + 1), 0);
  }
  for (std::int32_t i = 0; i < n; ++i) {
    Level& lv = levels_[level_of_[i]];
    ++lv.count;
    const std::int64_t x0 = lv.cell_x(boxes[i].lo.x, world.lo.x), x1 = lv.cell_x(boxes[i].hi.x, world.lo.x);
    const std::int64_t y0 = lv.cell_y(boxes[i].lo.y, world.lo.y), y1 = lv.cell_y(boxes[i].hi.y, world.lo.y);
    for (std::int64_t y = y0; y <= y1; ++y)
      for (std::int64_t x = x0; x <= x1; ++x) ++lv.cell_start[y * lv.nx + x + 1];
  }
  for (int l = 0; l <= top; ++l) {
    Level& lv = levels_[l];
    const std::int64_t cells = lv.nx * lv.ny;
    for (std::int64_t c = 0; c < cells; ++c) lv.cell_start[c + 1] += lv.cell_start[c];
    resize_with_headroom(lv.items, static_cast<std::size_t>(lv.cell_start[cells]));
  }
  for (int l = 0; l <= top; ++l) {
    Level& lv = levels_[l];
    if (lv.count == 0) continue;
    cursor_.assign(lv.cell_start.begin(), lv.cell_start.end() - 1);
    for (std::int32_t i = 0; i < n; ++i) {
      if (level_of_[i] != l) continue;
      const std::int64_t x0 = lv.cell_x(boxes[i].lo.x, world.lo.x), x1 = lv.cell_x(boxes[i].hi.x, world.lo.x);
      const std::int64_t y0 = lv.cell_y(boxes[i].lo.y, world.lo.y), y1 = lv.cell_y(boxes[i].hi.y, world.lo.y);
      for (std::int64_t y = y0; y <= y1; ++y)
        for (std::int64_t x = x0; x <= x1; ++x) lv.items[cursor_[y * lv.nx + x]++] = i;
    }
  }

  world_lo_ = world.lo;
  top_ = top;
  gridded_ = true;
}

void BroadPhase::collect_pairs(std::span<const Aabb> boxes, std::span<const std::int32_t> body,
                               std::span<const std::uint8_t> fixed, std::vector<PartPair>& out) {
  const auto n = static_cast<std::int32_t>(boxes.size());
  const int top = top_;
  auto consider = [&](std::int32_t i, std::int32_t j) {
    if (body[i] == body[j] || (fixed[i] && fixed[j])) return false;
    return boxes[i].overlaps(boxes[j]);
  };
  // The cell, on level lv, that reports pair (i, j): the one holding the intersection's corner.
  auto reporting_cell = [&](const Level& lv, std::int32_t i, std::int32_t j) {
    const double cx = std::max(boxes[i].lo.x, boxes[j].lo.x);
    const double cy = std::max(boxes[i].lo.y, boxes[j].lo.y);
    return lv.cell_y(cy, world_lo_.y) * lv.nx + lv.cell_x(cx, world_lo_.x);
  };

  // Pairs, in two loops whose blocks run on the pool's threads, each block into its own list,
  // sorted there; the sorted lists are then merged. The blocks are fixed by the grid and n
  // alone, and the merged list is the sorted set of pairs: the same on any number of threads.
  // Each pair is reported from one cell only (reporting_cell), so once.
  //  1. within a level: the pairs of each cell's parts, over the cells of every level as one
  //     run of indices (cell_base_: where each level's cells begin in it);
  //  2. across levels: each part against the parts of the cells it covers on coarser levels.
  cell_base_.assign(static_cast<std::size_t>(top) + 2, 0);
  for (int l = 0; l <= top; ++l)
    cell_base_[l + 1] = cell_base_[l] + (levels_[l].count < 2 ? 0 : levels_[l].nx * levels_[l].ny);
  const auto all_cells = static_cast<std::size_t>(cell_base_[top + 1]);
  const std::size_t cell_blocks = (all_cells + kCellGrain - 1) / kCellGrain;
  const std::size_t part_blocks = (static_cast<std::size_t>(n) + kPartGrain - 1) / kPartGrain;
  if (found_.size() < cell_blocks + part_blocks) found_.resize(cell_blocks + part_blocks);
  thread_pool().for_blocks(all_cells, kCellGrain, [&](std::size_t begin, std::size_t end) {
    std::vector<PartPair>& found = found_[begin / kCellGrain];
    found.clear();
    int l = 0;
    for (auto g = static_cast<std::int64_t>(begin); g < static_cast<std::int64_t>(end); ++g) {
      while (g >= cell_base_[l + 1]) ++l;
      const Level& lv = levels_[l];
      const std::int64_t c = g - cell_base_[l];
      const std::int32_t first = lv.cell_start[c], last = lv.cell_start[c + 1];
      for (std::int32_t s = first; s < last; ++s) {
        const std::int32_t i = lv.items[s];
        for (std::int32_t t = s + 1; t < last; ++t) {
          const std::int32_t j = lv.items[t];
          if (consider(i, j) && reporting_cell(lv, i, j) == c) found.push_back({std::min(i, j), std::max(i, j)});
        }
      }
    }
    std::sort(found.begin(), found.end());
  });
  thread_pool().for_blocks(static_cast<std::size_t>(n), kPartGrain, [&](std::size_t begin, std::size_t end) {
    std::vector<PartPair>& found = found_[cell_blocks + begin / kPartGrain];
    found.clear();
    for (auto i = static_cast<std::int32_t>(begin); i < static_cast<std::int32_t>(end); ++i) {
      for (int l = level_of_[i] + 1; l <= top; ++l) {
        const Level& lv = levels_[l];
        if (lv.count == 0) continue;
        const std::int64_t x0 = lv.cell_x(boxes[i].lo.x, world_lo_.x), x1 = lv.cell_x(boxes[i].hi.x, world_lo_.x);
        const std::int64_t y0 = lv.cell_y(boxes[i].lo.y, world_lo_.y), y1 = lv.cell_y(boxes[i].hi.y, world_lo_.y);
        for (std::int64_t y = y0; y <= y1; ++y) {
          for (std::int64_t x = x0; x <= x1; ++x) {
            const std::int64_t c = y * lv.nx + x;
            for (std::int32_t s = lv.cell_start[c]; s < lv.cell_start[c + 1]; ++s) {
              const std::int32_t j = lv.items[s];
              if (consider(i, j) && reporting_cell(lv, i, j) == c) found.push_back({std::min(i, j), std::max(i, j)});
            }
          }
        }
      }
    }
    std::sort(found.begin(), found.end());
  });
  merge_sorted(std::span<std::vector<PartPair>>(found_.data(), cell_blocks + part_blocks), out);
}

void BroadPhase::merge_sorted(std::span<std::vector<PartPair>> runs, std::vector<PartPair>& out) {
  // Pairwise rounds (log2 of the runs' count passes over the pairs), between out and merged_.
  out.clear();
  if (runs.empty()) return;
  run_end_.clear();
  for (const std::vector<PartPair>& r : runs) {
    out.insert(out.end(), r.begin(), r.end());
    run_end_.push_back(out.size());
  }
  while (run_end_.size() > 1) {
    merged_.resize(out.size());
    std::size_t start = 0, kept = 0;
    for (std::size_t k = 0; k < run_end_.size(); k += 2) {
      const std::size_t mid = run_end_[k], stop = k + 1 < run_end_.size() ? run_end_[k + 1] : mid;
      std::merge(out.begin() + static_cast<std::ptrdiff_t>(start), out.begin() + static_cast<std::ptrdiff_t>(mid),
                 out.begin() + static_cast<std::ptrdiff_t>(mid), out.begin() + static_cast<std::ptrdiff_t>(stop),
                 merged_.begin() + static_cast<std::ptrdiff_t>(start));
      run_end_[kept++] = stop;
      start = stop;
    }
    run_end_.resize(kept);
    out.swap(merged_);
  }
}

void BroadPhase::query(const Aabb& box, std::vector<std::int32_t>& out) const {
  // Cells are clamped to the grid, so a box reaching beyond it looks in the edge cells, which
  // hold every part that can overlap it there.
  for (int l = 0; l <= top_; ++l) {
    const Level& lv = levels_[l];
    if (lv.count == 0) continue;
    const std::int64_t x0 = lv.cell_x(box.lo.x, world_lo_.x), x1 = lv.cell_x(box.hi.x, world_lo_.x);
    const std::int64_t y0 = lv.cell_y(box.lo.y, world_lo_.y), y1 = lv.cell_y(box.hi.y, world_lo_.y);
    for (std::int64_t y = y0; y <= y1; ++y)
      for (std::int64_t x = x0; x <= x1; ++x) {
        const std::int64_t c = y * lv.nx + x;
        out.insert(out.end(), lv.items.begin() + lv.cell_start[c], lv.items.begin() + lv.cell_start[c + 1]);
      }
  }
}

}  // namespace floedem
