#include "solver/broad_phase.hpp"

#include <algorithm>
#include <cmath>

namespace floedem {

namespace {
constexpr int kBruteForceBelow = 24;      // fewer parts than this: the n^2/2 test is cheaper
constexpr std::int64_t kMaxCellsPerPart = 64;  // a part covering more is "large"
}  // namespace

void BroadPhase::find_pairs(std::span<const Aabb> boxes, std::span<const std::int32_t> body,
                            std::span<const std::uint8_t> fixed, std::vector<PartPair>& out) {
  out.clear();
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

  // Grid extent and cell size (median part extent, so that most parts cover <= 4 cells).
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
  std::nth_element(extents_.begin(), extents_.begin() + n / 2, extents_.end());
  double h = std::max(extents_[n / 2], 1e-9);
  const double wx = world.hi.x - world.lo.x;
  const double wy = world.hi.y - world.lo.y;
  // Sparse scenes: never more than ~4 cells per part.
  const double cells_wanted = 4.0 * n + 64.0;
  if ((wx / h + 1.0) * (wy / h + 1.0) > cells_wanted) h = std::sqrt(std::max(wx * wy, 1e-18) / cells_wanted) * 1.01;
  h = std::max(h, std::max(wx, wy) / 65536.0);
  const auto nx = static_cast<std::int64_t>(wx / h) + 1;
  const auto ny = static_cast<std::int64_t>(wy / h) + 1;
  const double inv_h = 1.0 / h;
  auto cell_x = [&](double x) { return std::clamp(static_cast<std::int64_t>((x - world.lo.x) * inv_h), std::int64_t{0}, nx - 1); };
  auto cell_y = [&](double y) { return std::clamp(static_cast<std::int64_t>((y - world.lo.y) * inv_h), std::int64_t{0}, ny - 1); };

  // Counting sort of parts into cells; large parts set aside.
  const std::int64_t cells = nx * ny;
  cell_start_.assign(static_cast<std::size_t>(cells + 1), 0);
  large_.clear();
  is_large_.assign(n, 0);
  for (std::int32_t i = 0; i < n; ++i) {
    const std::int64_t x0 = cell_x(boxes[i].lo.x), x1 = cell_x(boxes[i].hi.x);
    const std::int64_t y0 = cell_y(boxes[i].lo.y), y1 = cell_y(boxes[i].hi.y);
    if ((x1 - x0 + 1) * (y1 - y0 + 1) > kMaxCellsPerPart) {
      is_large_[i] = 1;
      large_.push_back(i);
      continue;
    }
    for (std::int64_t y = y0; y <= y1; ++y)
      for (std::int64_t x = x0; x <= x1; ++x) ++cell_start_[y * nx + x + 1];
  }
  for (std::int64_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(static_cast<std::size_t>(cell_start_[cells]));
  cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (std::int32_t i = 0; i < n; ++i) {
    if (is_large_[i]) continue;
    const std::int64_t x0 = cell_x(boxes[i].lo.x), x1 = cell_x(boxes[i].hi.x);
    const std::int64_t y0 = cell_y(boxes[i].lo.y), y1 = cell_y(boxes[i].hi.y);
    for (std::int64_t y = y0; y <= y1; ++y)
      for (std::int64_t x = x0; x <= x1; ++x) cell_items_[cursor_[y * nx + x]++] = i;
  }

  for (std::int64_t c = 0; c < cells; ++c) {
    const std::int32_t begin = cell_start_[c], end = cell_start_[c + 1];
    for (std::int32_t s = begin; s < end; ++s) {
      const std::int32_t i = cell_items_[s];
      for (std::int32_t t = s + 1; t < end; ++t) {
        const std::int32_t j = cell_items_[t];
        if (!consider(i, j)) continue;
        // Report from the cell holding the lower-left corner of the intersection only.
        const double cx = std::max(boxes[i].lo.x, boxes[j].lo.x);
        const double cy = std::max(boxes[i].lo.y, boxes[j].lo.y);
        if (cell_y(cy) * nx + cell_x(cx) != c) continue;
        out.push_back({std::min(i, j), std::max(i, j)});
      }
    }
  }
  for (const std::int32_t l : large_) {
    for (std::int32_t k = 0; k < n; ++k) {
      if (k == l || (is_large_[k] && k < l)) continue;
      if (consider(l, k)) out.push_back({std::min(l, k), std::max(l, k)});
    }
  }
  std::sort(out.begin(), out.end());
}

}  // namespace floedem
