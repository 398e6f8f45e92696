#include "field/power_diagram.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_vertex_base_2.h>
#include <CGAL/Triangulation_data_structure_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <utility>

namespace floedem {

PowerAdjacency power_adjacency(std::span<const Vec2> sites, std::span<const double> weights) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, Kernel,
                                                                 CGAL::Regular_triangulation_vertex_base_2<Kernel>>;
  using FaceBase = CGAL::Regular_triangulation_face_base_2<Kernel>;
  using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
  using Regular = CGAL::Regular_triangulation_2<Kernel, Tds>;
  using WeightedPoint = Kernel::Weighted_point_2;

  const std::size_t n = sites.size();
  std::vector<std::pair<WeightedPoint, std::int32_t>> input;
  input.reserve(n);
  for (std::size_t i = 0; i < n; ++i)
    input.emplace_back(WeightedPoint(Kernel::Point_2(sites[i].x, sites[i].y), weights[i]),
                       static_cast<std::int32_t>(i));
  Regular rt;
  rt.insert(input.begin(), input.end());  // spatially sorted insertion

  // Neighbour pairs in the triangulation's order, then grouped by site (counting sort): the
  // grouped order is deterministic because the triangulation is, for the same input.
  PowerAdjacency out;
  out.hidden.assign(n, 1);
  out.offsets.assign(n + 1, 0);
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  pairs.reserve(6 * n + 6);
  for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) {
    const std::int32_t i = v->info();
    out.hidden[static_cast<std::size_t>(i)] = 0;
    auto c = rt.incident_vertices(v);
    if (c == nullptr) continue;  // a single site: no neighbours
    const auto start = c;
    do {
      if (!rt.is_infinite(c)) {
        pairs.emplace_back(i, c->info());
        ++out.offsets[static_cast<std::size_t>(i) + 1];
      }
    } while (++c != start);
  }
  for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] += out.offsets[i];
  out.neighbours.resize(pairs.size());
  std::vector<std::int64_t> next(out.offsets.begin(), out.offsets.end() - 1);
  for (const auto& [i, j] : pairs) out.neighbours[static_cast<std::size_t>(next[static_cast<std::size_t>(i)]++)] = j;
  return out;
}

}  // namespace floedem
