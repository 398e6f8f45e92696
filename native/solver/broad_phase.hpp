#pragma once
// Broad phase: pairs of convex parts whose (fattened) bounds overlap.
//
// A uniform grid rebuilt every step by counting sort: O(N) for a field of floes of comparable
// size, no allocation once its buffers have grown. The cell size follows the median part size,
// so a power-law field (many small floes, few large) keeps few parts per cell; parts that would
// cover many cells (an iceberg) are kept out of the grid and tested against every box, which is
// O(N) per such part. A pair is reported only from the cell holding the lower-left corner of the
// two boxes' intersection, so every pair appears once, in a deterministic order, sorted at the end.
#include <cstdint>
#include <span>
#include <vector>

#include "geometry/vec2.hpp"

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
  /// fixed[k]: non-zero when part k's body cannot move (two fixed parts never pair).
  void find_pairs(std::span<const Aabb> boxes, std::span<const std::int32_t> body,
                  std::span<const std::uint8_t> fixed, std::vector<PartPair>& out);

 private:
  std::vector<double> extents_;
  std::vector<std::int32_t> cell_start_;
  std::vector<std::int32_t> cell_items_;
  std::vector<std::int32_t> cursor_;
  std::vector<std::int32_t> large_;
  std::vector<std::uint8_t> is_large_;
};

}  // namespace floedem
