#include "forcing/coriolis_field.hpp"

#include <cmath>
#include <string>

#include "floedem/scene/input_error.hpp"

namespace floedem {

namespace {
std::uint64_t tile_key(std::int64_t ti, std::int64_t tj) {
  return (static_cast<std::uint64_t>(ti) << 32) ^ (static_cast<std::uint64_t>(tj) & 0xffffffffu);
}
}  // namespace

CoriolisField::CoriolisField(const GeoSpec& geo) : projection_(geo) {}

const CoriolisField::Tile& CoriolisField::tile(std::int64_t ti, std::int64_t tj) const {
  const std::uint64_t key = tile_key(ti, tj);
  if (last_ && key == last_key_) return *last_;
  auto [it, fresh] = tiles_.try_emplace(key);
  if (fresh) {
    for (int j = 0; j <= kTile; ++j)
      for (int i = 0; i <= kTile; ++i) {
        const Vec2 node{static_cast<double>(ti * kTile + i) * kSpacing, static_cast<double>(tj * kTile + j) * kSpacing};
        const LonLat g = projection_.to_lonlat(node);
        if (!std::isfinite(g.lat)) {
          tiles_.erase(it);
          throw InputError("a body reached (" + std::to_string(node.x) + ", " + std::to_string(node.y) +
                           ") m, outside the domain of the scene's projection ([geo] projection)");
        }
        it->second[static_cast<std::size_t>(j * (kTile + 1) + i)] = coriolis_parameter(g.lat);
      }
  }
  last_ = &it->second;  // unordered_map keeps its elements in place as it grows
  last_key_ = key;
  return it->second;
}

double CoriolisField::at(Vec2 p) const {
  const double gx = p.x / kSpacing, gy = p.y / kSpacing;
  const double cx = std::floor(gx), cy = std::floor(gy);
  if (!(std::abs(cx) < 1e9 && std::abs(cy) < 1e9))
    throw InputError("a body is at (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                     ") m, beyond any projection's domain");
  const auto i = static_cast<std::int64_t>(cx), j = static_cast<std::int64_t>(cy);
  // Floor division: the tile holding cell (i, j) and the cell's place in it.
  const std::int64_t ti = i >= 0 ? i / kTile : -((-i + kTile - 1) / kTile);
  const std::int64_t tj = j >= 0 ? j / kTile : -((-j + kTile - 1) / kTile);
  const int li = static_cast<int>(i - ti * kTile), lj = static_cast<int>(j - tj * kTile);
  const Tile& t = tile(ti, tj);
  const double u = gx - cx, v = gy - cy;
  const std::size_t k = static_cast<std::size_t>(lj * (kTile + 1) + li);
  const double f00 = t[k], f10 = t[k + 1], f01 = t[k + kTile + 1], f11 = t[k + kTile + 2];
  return (1.0 - v) * ((1.0 - u) * f00 + u * f10) + v * ((1.0 - u) * f01 + u * f11);
}

}  // namespace floedem
