#include "solver/broad_phase.hpp"

#include <algorithm>
#include <cmath>

namespace floedem {

namespace {
constexpr int kBruteForceBelow = 24;  // fewer parts than this: the n^2/2 test is cheaper
constexpr int kMaxLevels = 32;
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
    lv.items.resize(static_cast<std::size_t>(lv.cell_start[cells]));
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

  // The cell, on level lv, that reports pair (i, j): the one holding the intersection's corner.
  auto reporting_cell = [&](const Level& lv, std::int32_t i, std::int32_t j) {
    const double cx = std::max(boxes[i].lo.x, boxes[j].lo.x);
    const double cy = std::max(boxes[i].lo.y, boxes[j].lo.y);
    return lv.cell_y(cy, world.lo.y) * lv.nx + lv.cell_x(cx, world.lo.x);
  };

  // Pairs within a level.
  for (int l = 0; l <= top; ++l) {
    const Level& lv = levels_[l];
    if (lv.count < 2) continue;
    const std::int64_t cells = lv.nx * lv.ny;
    for (std::int64_t c = 0; c < cells; ++c) {
      const std::int32_t begin = lv.cell_start[c], end = lv.cell_start[c + 1];
      for (std::int32_t s = begin; s < end; ++s) {
        const std::int32_t i = lv.items[s];
        for (std::int32_t t = s + 1; t < end; ++t) {
          const std::int32_t j = lv.items[t];
          if (consider(i, j) && reporting_cell(lv, i, j) == c) out.push_back({std::min(i, j), std::max(i, j)});
        }
      }
    }
  }
  // Pairs across levels: each part against the coarser levels' cells it covers.
  for (std::int32_t i = 0; i < n; ++i) {
    for (int l = level_of_[i] + 1; l <= top; ++l) {
      const Level& lv = levels_[l];
      if (lv.count == 0) continue;
      const std::int64_t x0 = lv.cell_x(boxes[i].lo.x, world.lo.x), x1 = lv.cell_x(boxes[i].hi.x, world.lo.x);
      const std::int64_t y0 = lv.cell_y(boxes[i].lo.y, world.lo.y), y1 = lv.cell_y(boxes[i].hi.y, world.lo.y);
      for (std::int64_t y = y0; y <= y1; ++y) {
        for (std::int64_t x = x0; x <= x1; ++x) {
          const std::int64_t c = y * lv.nx + x;
          for (std::int32_t s = lv.cell_start[c]; s < lv.cell_start[c + 1]; ++s) {
            const std::int32_t j = lv.items[s];
            if (consider(i, j) && reporting_cell(lv, i, j) == c) out.push_back({std::min(i, j), std::max(i, j)});
          }
        }
      }
    }
  }
  std::sort(out.begin(), out.end());
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
