#pragma once
// Adjacency of a power diagram (weighted Voronoi diagram), from CGAL's regular triangulation.
// The only CGAL in the field generator: this unit is compiled once, behind a plain interface.
#include <cstdint>
#include <span>
#include <vector>

#include "floedem/geometry/vec2.hpp"

namespace floedem {

/// For each site, its neighbours in the regular triangulation: the sites whose power cells
/// share an edge with its own (power distance |x - s_i|^2 - w_i). A site whose cell is empty
/// (hidden by its neighbours' weights) has no neighbours and hidden[i] = 1.
struct PowerAdjacency {
  std::vector<std::int64_t> offsets;     ///< size n + 1; neighbours of i: [offsets[i], offsets[i+1])
  std::vector<std::int32_t> neighbours;
  std::vector<std::uint8_t> hidden;
};

PowerAdjacency power_adjacency(std::span<const Vec2> sites, std::span<const double> weights);

}  // namespace floedem
