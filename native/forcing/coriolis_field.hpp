#pragma once
// The Coriolis parameter over a geographic scene's plane (docs/geography.md): f = 2 Omega
// sin(latitude) at each body's position, with the latitude from the scene's projection.
#include <array>
#include <cstdint>
#include <unordered_map>

#include "floedem/scene/geo.hpp"

namespace floedem {

/// f(x, y) = 2 Omega sin(latitude(x, y)), bilinear between the nodes of a square lattice of
/// spacing h = 1 km whose values PROJ gives exactly. A PROJ inverse costs about 0.7 us, a step
/// of a thousand floes about 0.8 ms: evaluating it per body per step would add most of a step.
/// The interpolation error is at most h^2 / 8 |d2 f / ds2| = h^2 / 8 * 2 Omega |sin lat| / R^2
/// = 3e-13 1/s (R = 6.37e6 m), 2.5e-9 of f at 70 deg: far below what a drift can show.
/// The nodes are computed a tile of 32 x 32 cells at a time, the first time a body enters the
/// tile: a value depends on the position alone, so a resumed run sees the same f to the bit.
/// Not for two threads at once (the force terms that read it add serially).
class CoriolisField {
 public:
  explicit CoriolisField(const GeoSpec& geo);
  /// f at a point of the plane (m); throws InputError where the projection is not defined.
  double at(Vec2 p) const;

  static constexpr double kSpacing = 1000.0;  ///< m, h

 private:
  static constexpr int kTile = 32;  ///< cells a side
  using Tile = std::array<double, (kTile + 1) * (kTile + 1)>;
  const Tile& tile(std::int64_t ti, std::int64_t tj) const;

  GeoProjection projection_;
  mutable std::unordered_map<std::uint64_t, Tile> tiles_;
  mutable const Tile* last_ = nullptr;
  mutable std::uint64_t last_key_ = 0;
};

}  // namespace floedem
