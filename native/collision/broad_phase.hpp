#pragma once
// Broad phase: pairs of convex parts whose (fattened) bounds overlap.
//
// A hierarchical uniform grid rebuilt every step by counting sort. Level l has cells of side
// h_0 2^l, with h_0 the median part extent; each part goes to the finest level whose cells are
// at least its size, so it covers at most 2 x 2 cells there. A part is tested against the parts
// of its own cells and of the cells it covers on every coarser level. For a field of floes with
// a power-law size spread (and an iceberg far larger than any floe) that is O(N log(d_max /
// d_median)), with no allocation once the buffers have grown. A pair is reported only from the
// cell (of the coarser part's level) that holds the lower-left corner of the two boxes'
// intersection, so each pair appears once. Blocks of parts find their pairs on the pool's
// threads, each list sorted, then merged: the sorted list, whatever the number of threads.
#include <cstdint>
#include <span>
#include <vector>

#include "floedem/geometry/vec2.hpp"

namespace floedem {

struct PartPair {
  std::int32_t a = 0;  ///< part index, a < b
  std::int32_t b = 0;
  friend bool operator<(PartPair x, PartPair y) { return x.a < y.a || (x.a == y.a && x.b < y.b); }
  friend bool operator==(PartPair, PartPair) = default;
};

class BroadPhase {
 public:
  /// boxes[k]: bounds of part k; body[k]: its body (parts of one body never pair);
  /// fixed[k]: non-zero when part k's body cannot move (two such parts never pair).
  void find_pairs(std::span<const Aabb> boxes, std::span<const std::int32_t> body,
                  std::span<const std::uint8_t> fixed, std::vector<PartPair>& out);

  /// Appends to `out` every part whose box, as given to the last find_pairs, may overlap
  /// `box` (a superset; a part may appear more than once). Only after a find_pairs call that
  /// built the grid (gridded() true).
  void query(const Aabb& box, std::vector<std::int32_t>& out) const;
  bool gridded() const { return gridded_; }

 private:
  struct Level {
    double h = 0.0;
    double inv_h = 0.0;
    std::int64_t nx = 0, ny = 0;
    std::vector<std::int32_t> cell_start;  // CSR over cells
    std::vector<std::int32_t> items;
    std::int64_t count = 0;                // parts on this level
    std::int64_t cell_x(double x, double x0) const;
    std::int64_t cell_y(double y, double y0) const;
  };
  /// The grid over `boxes` (n >= kBruteForceBelow): its levels, cells and their parts.
  void build_grid(std::span<const Aabb> boxes);
  /// The pairs of the grid just built, sorted, into `out`.
  void collect_pairs(std::span<const Aabb> boxes, std::span<const std::int32_t> body,
                     std::span<const std::uint8_t> fixed, std::vector<PartPair>& out);
  /// Merges sorted runs (each sorted, all disjoint) into `out`, sorted.
  void merge_sorted(std::span<std::vector<PartPair>> runs, std::vector<PartPair>& out);

  std::vector<double> extents_;
  std::vector<std::uint8_t> level_of_;
  std::vector<Level> levels_;
  std::vector<std::int32_t> cursor_;
  std::vector<std::vector<PartPair>> found_;  // per block of parts: its pairs
  std::vector<PartPair> merged_;
  std::vector<std::int64_t> cell_base_;  // per level: where its cells begin among all levels' cells
  std::vector<std::size_t> run_end_;
  Vec2 world_lo_;      // the grid's origin at the last build
  int top_ = 0;        // the coarsest level used at the last build
  bool gridded_ = false;
};

}  // namespace floedem
