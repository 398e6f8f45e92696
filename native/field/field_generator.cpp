#include "floedem/field/field_generator.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <random>
#include <sstream>
#include <thread>

#include "field/power_diagram.hpp"
#include "geometry/convex_partition.hpp"
#include "geometry/polygon.hpp"
#include "parallel/threads.hpp"

namespace floedem {
namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

double area_of_diameter(double d) { return std::numbers::pi / 4.0 * d * d; }

/// Deterministic on every platform: mt19937_64 is specified bit for bit; the conversions to
/// reals are ours (the standard distributions are implementation-defined).
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double normal() {  // Box-Muller
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
  std::size_t below(std::size_t n) { return static_cast<std::size_t>(uniform() * static_cast<double>(n)); }

 private:
  std::mt19937_64 engine_;
};

/// A convex counter-clockwise polygon whose edge k (vertex k to k+1) carries a label: the
/// neighbouring site across it, or -1 for the domain's boundary.
struct LabeledPolygon {
  std::vector<Vec2> p;
  std::vector<std::int32_t> label;
  void clear() {
    p.clear();
    label.clear();
  }
};

/// Sutherland-Hodgman clip of a convex polygon to the half-plane n.x <= c; the new edge along
/// the line gets `label`.
void clip(const LabeledPolygon& in, LabeledPolygon& out, Vec2 n, double c, std::int32_t label) {
  out.clear();
  const std::size_t m = in.p.size();
  for (std::size_t k = 0; k < m; ++k) {
    const Vec2 a = in.p[k], b = in.p[(k + 1) % m];
    const double da = dot(n, a) - c, db = dot(n, b) - c;
    if (da <= 0.0) {
      out.p.push_back(a);
      out.label.push_back(in.label[k]);
      if (db > 0.0) {  // leaving: the exit point starts the new edge
        out.p.push_back(a + (da / (da - db)) * (b - a));
        out.label.push_back(label);
      }
    } else if (db <= 0.0) {  // entering: the entry point starts the rest of edge k
      out.p.push_back(a + (da / (da - db)) * (b - a));
      out.label.push_back(in.label[k]);
    }
  }
}

/// A convex polygon cut by another convex counter-clockwise polygon (empty when they are
/// disjoint).
std::vector<Vec2> clip_to_convex(const std::vector<Vec2>& poly, const std::vector<Vec2>& convex) {
  LabeledPolygon a{poly, std::vector<std::int32_t>(poly.size(), -1)}, b;
  const std::size_t m = convex.size();
  for (std::size_t k = 0; k < m && !a.p.empty(); ++k) {
    const Vec2 e = convex[(k + 1) % m] - convex[k];
    const Vec2 n{e.y, -e.x};  // outward normal of a counter-clockwise edge
    clip(a, b, n, dot(n, convex[k]), -1);
    std::swap(a, b);
  }
  return std::move(a.p);
}

/// Area and first moment of a convex polygon cut by another convex polygon.
AreaMoments intersection_moments(const std::vector<Vec2>& cell, const std::vector<Vec2>& piece) {
  const std::vector<Vec2> cut = clip_to_convex(cell, piece);
  if (cut.size() < 3) return {};
  return area_moments(cut);
}

/// Length of the segment pq inside a convex counter-clockwise polygon (Cyrus-Beck clipping).
double length_inside(Vec2 p, Vec2 q, const std::vector<Vec2>& poly) {
  double t0 = 0.0, t1 = 1.0;
  const Vec2 d = q - p;
  const std::size_t m = poly.size();
  for (std::size_t k = 0; k < m && t0 < t1; ++k) {
    const Vec2 e = poly[(k + 1) % m] - poly[k];
    const Vec2 n{e.y, -e.x};  // outward
    const double num = dot(n, poly[k] - p), den = dot(n, d);  // inside: den t <= num
    if (den == 0.0) {
      if (num < 0.0) return 0.0;
    } else if (den > 0.0) {
      t1 = std::min(t1, num / den);
    } else {
      t0 = std::max(t0, num / den);
    }
  }
  return t1 > t0 ? (t1 - t0) * length(d) : 0.0;
}

bool point_in_convex(const std::vector<Vec2>& poly, Vec2 x) {
  const std::size_t m = poly.size();
  for (std::size_t k = 0; k < m; ++k)
    if (cross(poly[(k + 1) % m] - poly[k], x - poly[k]) < 0.0) return false;
  return true;
}

struct KeepOutPiece {
  std::vector<Vec2> polygon;  ///< convex, counter-clockwise, clipped to the domain
  Aabb box;
  std::size_t zone = 0;       ///< its keep-out zone, an index of FieldSpec::keep_out
};

struct Domain {
  Vec2 lo, hi;
  std::vector<KeepOutPiece> keep_out;
  double free_area = 0.0;
};

/// Convex pieces of the keep-out polygons inside the domain. Pieces of one polygon do not
/// overlap (a partition); pieces of different polygons are checked not to.
Domain make_domain(const FieldSpec& spec, bool check) {
  Domain d;
  d.lo = spec.origin;
  d.hi = spec.origin + Vec2{spec.width, spec.height};
  const std::vector<Vec2> rect{d.lo, {d.hi.x, d.lo.y}, d.hi, {d.lo.x, d.hi.y}};
  double covered = 0.0;
  std::vector<std::size_t> owner;
  for (std::size_t k = 0; k < spec.keep_out.size(); ++k) {
    std::vector<Vec2> poly = spec.keep_out[k];
    const std::string name = k < spec.keep_out_names.size() ? spec.keep_out_names[k] : "keep_out[" + std::to_string(k) + "]";
    auto name_of = [&](std::size_t j) {
      return j < spec.keep_out_names.size() ? spec.keep_out_names[j] : "keep_out[" + std::to_string(j) + "]";
    };
    if (check) {
      if (poly.size() < 3)
        throw FieldSpecError("keep_out[" + std::to_string(k) + "]", name + " has " + std::to_string(poly.size()) + " vertices; allowed at least 3");
      // Finite and within 1e7 m, as for bodies: far larger coordinates break the convex
      // partition's arithmetic (scenario.cpp, check_polygon).
      for (const Vec2 v : poly)
        if (!(std::abs(v.x) <= 1e7 && std::abs(v.y) <= 1e7))
          throw FieldSpecError("keep_out[" + std::to_string(k) + "]",
                               name + " has a vertex that is not a finite number within 1e7 m; allowed |x|, |y| <= 1e7 m");
      if (find_self_intersection(poly))
        throw FieldSpecError("keep_out[" + std::to_string(k) + "]", name + " is self-intersecting; allowed a simple polygon");
      if (!(std::abs(signed_area(poly)) > 0.0))
        throw FieldSpecError("keep_out[" + std::to_string(k) + "]", name + " has zero area");
    }
    if (signed_area(poly) < 0.0) std::reverse(poly.begin(), poly.end());
    for (std::vector<Vec2>& part : convex_partition(poly)) {
      // The part clipped to the domain (so that its area counts once).
      std::vector<Vec2> clipped = remove_collinear(clip_to_convex(part, rect), 1e-12);
      if (clipped.size() < 3) continue;
      const double area = area_moments(clipped).area;
      if (area <= 0.0) continue;
      if (check) {
        for (std::size_t j = 0; j < d.keep_out.size(); ++j) {
          if (owner[j] == k || !d.keep_out[j].box.overlaps(bounds_of(clipped))) continue;
          if (intersection_moments(clipped, d.keep_out[j].polygon).area > 1e-9 * area)
            throw FieldSpecError("keep_out[" + std::to_string(k) + "]",
                                 name + " overlaps " + name_of(owner[j]) +
                                     "; allowed keep-out zones that do not overlap each other");
        }
      }
      covered += area;
      d.keep_out.push_back({clipped, bounds_of(clipped), k});
      owner.push_back(k);
    }
  }
  d.free_area = spec.width * spec.height - covered;
  return d;
}

/// The power cells of all sites, clipped to the domain: free area (keep-out zones taken
/// out), free centroid, and the Newton matrix d(area_i)/d(w_j).
///
/// Cell i is the domain cut by the half-planes of its regular-triangulation neighbours j:
///   |x - s_i|^2 - w_i <= |x - s_j|^2 - w_j  <=>  2 y.(s_j - s_i) <= |s_j - s_i|^2 - w_j + w_i,
/// with y = x - s_i (local coordinates keep the round-off relative to the cell's size).
/// Moving the shared edge: d(area_i)/d(w_j) = -|e_ij| / (2 |s_j - s_i|) for j != i, and
/// d(area_i)/d(w_i) = sum_j |e_ij| / (2 |s_j - s_i|) (Aurenhammer, Hoffmann and Aronov 1998;
/// Kitagawa, Merigot and Thibert 2019, section 4): a graph Laplacian.
struct CellSet {
  std::vector<double> area;
  std::vector<Vec2> centroid;
  std::vector<Eigen::Triplet<double>> hessian;
  // Each block's matrix entries before they are joined (compute_cells): kept between passes,
  // so that the Newton steps' passes do not each take some 40 MB anew at 10^5 floes.
  std::vector<std::vector<Eigen::Triplet<double>>> block_entries;
};

void cell_block(const std::vector<Vec2>& sites, const std::vector<double>& w, const Domain& domain,
                const PowerAdjacency& adj, std::size_t begin, std::size_t end, CellSet& out,
                std::vector<Eigen::Triplet<double>>& hessian, std::vector<std::vector<Vec2>>* polygons);

void compute_cells(const std::vector<Vec2>& sites, const std::vector<double>& w, const Domain& domain,
                   CellSet& out, std::vector<std::vector<Vec2>>* polygons) {
  const std::size_t n = sites.size();
  const PowerAdjacency adj = power_adjacency(sites, w);
  out.area.assign(n, 0.0);
  out.centroid.assign(n, Vec2{});
  out.hessian.clear();
  if (polygons) polygons->assign(n, {});
  // Cells are independent: contiguous blocks of sites (fixed by n alone), each with its own
  // matrix entries, joined in block order, spread over the worker threads. The entries come
  // out in site order whatever the thread count, so the field does not depend on it.
  const std::size_t blocks = std::clamp<std::size_t>(n / 2048, 1, 64);
  std::vector<std::vector<Eigen::Triplet<double>>>& entries = out.block_entries;
  entries.resize(blocks);
  for (auto& e : entries) e.clear();
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t part; (part = next.fetch_add(1)) < blocks;)
      cell_block(sites, w, domain, adj, part * n / blocks, (part + 1) * n / blocks, out, entries[part], polygons);
  };
  const std::size_t threads = std::min<std::size_t>(worker_threads(), blocks);
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  std::size_t total = 0;
  for (const auto& e : entries) total += e.size();
  out.hessian.reserve(total);
  for (const auto& e : entries) out.hessian.insert(out.hessian.end(), e.begin(), e.end());
}

void cell_block(const std::vector<Vec2>& sites, const std::vector<double>& w, const Domain& domain,
                const PowerAdjacency& adj, std::size_t begin, std::size_t end, CellSet& out,
                std::vector<Eigen::Triplet<double>>& hessian, std::vector<std::vector<Vec2>>* polygons) {
  LabeledPolygon a, b;
  for (std::size_t i = begin; i < end; ++i) {
    const Vec2 s = sites[i];
    out.centroid[i] = s;
    if (adj.hidden[i]) continue;
    a.p = {domain.lo - s, Vec2{domain.hi.x, domain.lo.y} - s, domain.hi - s, Vec2{domain.lo.x, domain.hi.y} - s};
    a.label.assign(4, -1);
    for (std::int64_t k = adj.offsets[i]; k < adj.offsets[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(adj.neighbours[static_cast<std::size_t>(k)]);
      const Vec2 dj = sites[j] - s;
      clip(a, b, dj, 0.5 * (length_squared(dj) - w[j] + w[i]), static_cast<std::int32_t>(j));
      std::swap(a, b);
      if (a.p.empty()) break;
    }
    if (a.p.size() < 3) continue;
    const AreaMoments m = area_moments(a.p);
    double area = m.area;
    Vec2 first = m.area * (m.centroid + s);
    const std::size_t nv = a.p.size();
    // Keep-out pieces near this cell (their area is not the cell's, nor their edge length).
    std::vector<const KeepOutPiece*> near;
    if (!domain.keep_out.empty()) {
      Aabb box = bounds_of(a.p);
      box.lo += s;
      box.hi += s;
      for (const KeepOutPiece& piece : domain.keep_out)
        if (piece.box.overlaps(box)) near.push_back(&piece);
    }
    for (std::size_t k = 0; k < nv; ++k) {
      const std::int32_t j = a.label[k];
      if (j < 0) continue;
      double len = length(a.p[(k + 1) % nv] - a.p[k]);
      for (const KeepOutPiece* piece : near)
        len -= length_inside(a.p[k] + s, a.p[(k + 1) % nv] + s, piece->polygon);
      if (len <= 0.0) continue;
      const double c = 0.5 * len / length(sites[static_cast<std::size_t>(j)] - s);
      // Half from each side: both cells see the shared edge; the matrix comes out symmetric.
      hessian.emplace_back(static_cast<int>(i), static_cast<int>(i), 0.5 * c);
      hessian.emplace_back(j, j, 0.5 * c);
      hessian.emplace_back(static_cast<int>(i), j, -0.5 * c);
      hessian.emplace_back(j, static_cast<int>(i), -0.5 * c);
    }
    if (!near.empty()) {
      std::vector<Vec2> world(a.p.size());
      for (std::size_t k = 0; k < nv; ++k) world[k] = a.p[k] + s;
      for (const KeepOutPiece* piece : near) {
        const AreaMoments cut = intersection_moments(world, piece->polygon);
        area -= cut.area;
        first -= cut.area * cut.centroid;
      }
      area = std::max(area, 0.0);
    }
    out.area[i] = area;
    if (area > 0.0) out.centroid[i] = (1.0 / area) * first;
    if (polygons) {
      auto& poly = (*polygons)[i];
      poly.resize(nv);
      for (std::size_t k = 0; k < nv; ++k) poly[k] = a.p[k] + s;
    }
  }
}

struct WeightSolve {
  int iterations = 0;
  double max_relative_error = 0.0;
};

double max_relative_error(const std::vector<double>& area, const std::vector<double>& target) {
  double e = 0.0;
  for (std::size_t i = 0; i < area.size(); ++i) e = std::max(e, std::abs(area[i] - target[i]) / target[i]);
  return e;
}

double norm2(const std::vector<double>& area, const std::vector<double>& target) {
  double s = 0.0;
  for (std::size_t i = 0; i < area.size(); ++i) s += (area[i] - target[i]) * (area[i] - target[i]);
  return std::sqrt(s);
}

/// Damped Newton for the weights (Kitagawa, Merigot and Thibert 2019, algorithm 1): solve
/// L dw = target - area with the Laplacian L above, then halve the step until every cell keeps
/// at least eps of area and the error norm falls by a factor (1 - t/2). Converges globally;
/// quadratically near the solution. The Laplacian's null space (a common shift of all weights,
/// which changes nothing) is removed by a tiny diagonal term and a zero-mean right-hand side.
WeightSolve solve_weights(const std::vector<Vec2>& sites, std::vector<double>& w, const std::vector<double>& target,
                          const Domain& domain, CellSet& cells, double tolerance) {
  const std::size_t n = sites.size();
  WeightSolve result;
  const double min_target = *std::min_element(target.begin(), target.end());
  // A start with a (nearly) empty cell is a poor one: the area's derivative vanishes with the
  // cell and Newton's steps blow up. Zero weights (a Voronoi diagram: every cell holds its
  // site) are always a proper start; the solve falls back to them once if its line search fails.
  bool from_zero = std::all_of(w.begin(), w.end(), [](double x) { return x == 0.0; });
  compute_cells(sites, w, domain, cells, nullptr);
  if (!from_zero && *std::min_element(cells.area.begin(), cells.area.end()) < 1e-3 * min_target) {
    std::fill(w.begin(), w.end(), 0.0);
    from_zero = true;
    compute_cells(sites, w, domain, cells, nullptr);
  }
  double eps = 0.5 * std::min(*std::min_element(cells.area.begin(), cells.area.end()), min_target);
  CellSet trial;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  Eigen::VectorXd g(static_cast<Eigen::Index>(n));
  std::vector<double> w_trial(n);
  double last_step = 1.0;  // the step length starts at twice the last accepted one
  for (int it = 0; it < 100; ++it) {
    result.max_relative_error = max_relative_error(cells.area, target);
    if (result.max_relative_error <= tolerance || n == 1) break;
    Eigen::SparseMatrix<double> lap(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
    lap.setFromTriplets(cells.hessian.begin(), cells.hessian.end());
    double diag = 0.0;
    for (Eigen::Index i = 0; i < lap.rows(); ++i) diag += lap.coeff(i, i);
    diag /= static_cast<double>(n);
    for (Eigen::Index i = 0; i < lap.rows(); ++i) lap.coeffRef(i, i) += 1e-10 * diag;
    double mean = 0.0;
    for (std::size_t i = 0; i < n; ++i) mean += target[i] - cells.area[i];
    mean /= static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) g[static_cast<Eigen::Index>(i)] = target[i] - cells.area[i] - mean;
    solver.compute(lap);
    if (solver.info() != Eigen::Success) break;
    const Eigen::VectorXd dw = solver.solve(g);
    const double norm0 = norm2(cells.area, target);
    bool accepted = false;
    double t_used = 0.0;
    for (double t = std::min(1.0, 2.0 * last_step); t > 1e-6; t *= 0.5) {
      t_used = t;
      for (std::size_t i = 0; i < n; ++i) w_trial[i] = w[i] + t * dw[static_cast<Eigen::Index>(i)];
      compute_cells(sites, w_trial, domain, trial, nullptr);
      const double trial_min = *std::min_element(trial.area.begin(), trial.area.end());
      if (trial_min >= eps && norm2(trial.area, target) <= (1.0 - 0.5 * t) * norm0) {
        accepted = true;
        break;
      }
    }
    ++result.iterations;
    last_step = t_used;
    if (!accepted) {
      if (from_zero) break;
      std::fill(w.begin(), w.end(), 0.0);
      from_zero = true;
      compute_cells(sites, w, domain, cells, nullptr);
      eps = 0.5 * std::min(*std::min_element(cells.area.begin(), cells.area.end()), min_target);
      last_step = 1.0;
      continue;
    }
    w.swap(w_trial);
    std::swap(cells, trial);
  }
  result.max_relative_error = max_relative_error(cells.area, target);
  return result;
}

/// Drops vertices that make edges shorter than `min_edge` or turns that are straight: the
/// polygon stays convex and inside the original (it is the hull of a subset of its vertices).
std::vector<Vec2> clean_convex(std::vector<Vec2> p, double min_edge) {
  p = remove_collinear(p, 1e-9);
  while (p.size() > 3) {
    const std::size_t n = p.size();
    std::size_t shortest = 0;
    double len = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < n; ++k) {
      const double l = length(p[(k + 1) % n] - p[k]);
      if (l < len) {
        len = l;
        shortest = k;
      }
    }
    if (len >= min_edge) break;
    // Remove whichever end of the short edge cuts off the smaller triangle.
    auto loss = [&](std::size_t k) {
      return std::abs(cross(p[k] - p[(k + n - 1) % n], p[(k + 1) % n] - p[k]));
    };
    const std::size_t k0 = shortest, k1 = (shortest + 1) % n;
    p.erase(p.begin() + static_cast<std::ptrdiff_t>(loss(k0) <= loss(k1) ? k0 : k1));
  }
  return p;
}

double draw_thickness(const ThicknessDistribution& t, Random& rng) {
  switch (t.kind) {
    case ThicknessDistribution::Kind::constant:
      return t.value;
    case ThicknessDistribution::Kind::uniform:
      return t.min + rng.uniform() * (t.max - t.min);
    case ThicknessDistribution::Kind::lognormal: {
      // mean m and standard deviation s of the thickness: sigma^2 = ln(1 + s^2/m^2),
      // mu = ln m - sigma^2 / 2.
      const double s2 = std::log1p((t.std / t.mean) * (t.std / t.mean));
      return std::exp(std::log(t.mean) - 0.5 * s2 + std::sqrt(s2) * rng.normal());
    }
  }
  return t.value;
}

void check_range(const std::string& name, double v, double lo, double hi, bool lo_open, bool hi_open) {
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  if (!ok) {
    const std::string hi_text = std::isinf(hi) ? "inf" : num(hi);
    throw FieldSpecError(name, name + " is " + num(v) + "; allowed " + (lo_open ? "(" : "[") + num(lo) + ", " +
                                   hi_text + (hi_open ? ")" : "]"));
  }
}

/// Position of cell (x, y) of a 2^16 x 2^16 grid along the Hilbert curve: at each level the
/// quadrant's index (0..3 along the curve's U), then the coordinates turned and mirrored into
/// the quadrant's own frame (Hilbert 1891; the bitwise walk of Warren, "Hacker's Delight",
/// 2nd ed., sec. 16-2). Cells close on the curve are close in the plane.
std::uint64_t hilbert_index(std::uint32_t x, std::uint32_t y) {
  constexpr std::uint32_t n = 1u << 16;
  std::uint64_t d = 0;
  for (std::uint32_t s = n / 2; s > 0; s /= 2) {
    const std::uint32_t rx = (x & s) != 0 ? 1u : 0u;
    const std::uint32_t ry = (y & s) != 0 ? 1u : 0u;
    d += static_cast<std::uint64_t>(s) * s * ((3u * rx) ^ ry);
    if (ry == 0) {
      if (rx == 1) {
        x = n - 1 - x;
        y = n - 1 - y;
      }
      std::swap(x, y);
    }
  }
  return d;
}

/// Floes numbered along a Hilbert curve through their centroids: floes in contact are then
/// mostly near in number, so that the solver and the narrow phase, which go through contacts
/// in the order of the floes' numbers, find both floes' data close in memory. In the sites'
/// random order a floe's nearest neighbour lies some N/3 numbers away, and each contact's
/// second floe is a miss (docs/performance.md, why the code is as it is).
void number_along_hilbert_curve(const FieldSpec& spec, std::vector<std::vector<Vec2>>& floes) {
  const double extent = std::max(spec.width, spec.height);
  auto cell = [&](double v) { return static_cast<std::uint32_t>(std::clamp(v / extent, 0.0, 1.0) * 65535.0); };
  std::vector<std::pair<std::uint64_t, std::size_t>> key(floes.size());
  for (std::size_t i = 0; i < floes.size(); ++i) {
    const Vec2 c = area_moments(floes[i]).centroid - spec.origin;
    key[i] = {hilbert_index(cell(c.x), cell(c.y)), i};
  }
  std::sort(key.begin(), key.end());
  std::vector<std::vector<Vec2>> sorted(floes.size());
  for (std::size_t i = 0; i < key.size(); ++i) sorted[i] = std::move(floes[key[i].second]);
  floes = std::move(sorted);
}

}  // namespace

void check_field_spec(const FieldSpec& s) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  // Coordinates within 1e7 m, as for bodies (scenario.cpp, check_polygon).
  if (!(std::abs(s.origin.x) <= 1e7 && std::abs(s.origin.y) <= 1e7))
    throw FieldSpecError("origin", "origin is not a pair of finite numbers within 1e7 m; allowed |x|, |y| <= 1e7 m");
  check_range("width", s.width, 0.0, 1e7, true, false);
  check_range("height", s.height, 0.0, 1e7, true, false);
  check_range("concentration", s.concentration, 0.0, FieldSpec::max_concentration, true, false);
  check_range("alpha", s.alpha, 0.0, 10.0, true, false);
  check_range("d_min", s.d_min, 0.0, inf, true, true);
  check_range("d_max", s.d_max, s.d_min, inf, true, true);
  check_range("irregularity", s.irregularity, 0.0, 1.0, false, false);
  for (const auto& [name, side] : {std::pair{"width", s.width}, std::pair{"height", s.height}})
    if (side < s.d_max)
      throw FieldSpecError(name, std::string(name) + " is " + num(side) + " m, smaller than d_max = " + num(s.d_max) +
                                     " m; allowed a domain at least d_max across");
  const ThicknessDistribution& t = s.thickness;
  switch (t.kind) {
    case ThicknessDistribution::Kind::constant:
      check_range("thickness", t.value, 0.0, inf, true, true);
      break;
    case ThicknessDistribution::Kind::uniform:
      check_range("thickness.min", t.min, 0.0, inf, true, true);
      check_range("thickness.max", t.max, t.min, inf, true, true);
      break;
    case ThicknessDistribution::Kind::lognormal:
      check_range("thickness.mean", t.mean, 0.0, inf, true, true);
      check_range("thickness.std", t.std, 0.0, inf, false, true);
      break;
  }
  const Domain d = make_domain(s, true);
  const double domain_area = s.width * s.height;
  if (d.free_area <= 1e-9 * domain_area)
    throw FieldSpecError("keep_out", "keep_out zones cover the whole domain (" + num(domain_area) +
                                         " m^2); allowed zones that leave part of it free");
  const double largest_cell = area_of_diameter(s.d_max) / s.concentration;
  if (d.free_area < largest_cell)
    throw FieldSpecError(!s.keep_out.empty() ? "keep_out" : "d_max",
                         "the free area of the domain, " + num(d.free_area) +
                             " m^2, is smaller than the cell the largest floe needs at this concentration, "
                             "pi d_max^2 / (4 C) = " + num(largest_cell) + " m^2; allowed a larger domain, "
                             "smaller keep-out zones or a smaller d_max");
  // The ice, C times the free area, is now at least one floe of d_max, so at least one of d_min
  // (stratified_sizes' precondition): no check of its own.
  const TruncatedPowerLaw law{s.alpha, s.d_min, s.d_max};
  const double floes = s.concentration * d.free_area / law.mean_area();
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
  // A fuzzer's mutated chart may ask for a million pancakes: valid, and minutes to generate.
  constexpr double max_floes = 5000.0;
#else
  constexpr double max_floes = FieldSpec::max_floes;
#endif
  if (floes > max_floes)
    throw FieldSpecError("d_min", "d_min = " + num(s.d_min) + " m gives about " + num(floes) +
                                      " floes; allowed at most " + num(max_floes) +
                                      " (raise d_min or shrink the domain)");
}

namespace {

/// Each floe's area and its cell's target area. Cell areas: (sqrt(A_i) + g)^2, with g such that
/// they tile the free area F:
///   N g^2 + 2 g sum sqrt(A_i) + sum A_i - F = 0.
/// Shrinking cell i about its centroid to A_i then moves its edges in by about
/// (sqrt(a_i) - sqrt(A_i)) / sqrt(pi) = g / sqrt(pi) whatever its size: the open water lies
/// in leads of even width between the floes. (Cells of area A_i / C instead would surround
/// the largest floes with moats, the gap growing with the floe.)
struct CellTargets {
  std::vector<double> floe_area, target;
};
CellTargets cell_targets(std::span<const double> sizes, double free_area) {
  const std::size_t n = sizes.size();
  CellTargets t{std::vector<double>(n), std::vector<double>(n)};
  double sum_area = 0.0, sum_root = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    t.floe_area[i] = area_of_diameter(sizes[i]);
    sum_area += t.floe_area[i];
    sum_root += std::sqrt(t.floe_area[i]);
  }
  const double nn = static_cast<double>(n);
  const double gap = (-sum_root + std::sqrt(sum_root * sum_root + nn * (free_area - sum_area))) / nn;
  double target_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = std::sqrt(t.floe_area[i]) + gap;
    t.target[i] = r * r;
    target_sum += t.target[i];
  }
  for (double& x : t.target) x *= free_area / target_sum;  // exact tiling despite round-off
  return t;
}

bool in_keep_out(const Domain& domain, Vec2 p) {
  bool blocked = false;
  for (const KeepOutPiece& k : domain.keep_out)
    if (point_in_convex(k.polygon, p)) blocked = true;
  return blocked;
}

/// n sites, uniform in the free area.
std::vector<Vec2> place_sites(const Domain& domain, std::size_t n, Random& rng) {
  std::vector<Vec2> sites(n);
  const Vec2 span = domain.hi - domain.lo;
  for (Vec2& s : sites) {
    for (int tries = 0;; ++tries) {
      s = domain.lo + Vec2{rng.uniform() * span.x, rng.uniform() * span.y};
      if (!in_keep_out(domain, s) || tries > 10000) break;
    }
  }
  return sites;
}

/// Weights, then Lloyd steps towards the centroids with the weights re-solved after each. The
/// sites move after every solve but the last: those solves need the cells only roughly.
void relax_cells(const FieldSpec& spec, const Domain& domain, const std::vector<double>& target,
                 std::vector<Vec2>& sites, std::vector<double>& w, CellSet& cells, FieldStats& stats) {
  constexpr double tolerance = 1e-6, rough_tolerance = 1e-1;
  const int lloyd_steps = static_cast<int>(std::lround(4.0 * (1.0 - spec.irregularity)));
  const std::size_t n = sites.size();
  WeightSolve solve = solve_weights(sites, w, target, domain, cells, lloyd_steps > 0 ? rough_tolerance : tolerance);
  stats.newton_iterations += solve.iterations;
  for (int step = 0; step < lloyd_steps; ++step) {
    // Sites to their centroids c_i, weights w_i - |c_i - s_i|^2: the power function of the
    // moved site then matches the old one at the centroid, |x - c_i|^2 - w'_i = |x - s_i|^2 - w_i
    // at x = c_i, so the old diagram is kept to first order about each cell (solve_weights
    // falls back to zero weights where this start leaves a cell nearly empty).
    // A site stays where it is when its centroid falls inside a keep-out zone (a cell wrapped
    // round a zone's corner): there its cell could lose all free area, which Newton cannot
    // recover from (the area's derivative vanishes with it).
    for (std::size_t i = 0; i < n; ++i) {
      if (in_keep_out(domain, cells.centroid[i])) continue;
      w[i] -= length_squared(cells.centroid[i] - sites[i]);
      sites[i] = cells.centroid[i];
    }
    solve = solve_weights(sites, w, target, domain, cells, step + 1 < lloyd_steps ? rough_tolerance : tolerance);
    stats.newton_iterations += solve.iterations;
  }
  stats.lloyd_steps = lloyd_steps;
  stats.max_cell_area_error = solve.max_relative_error;
  // Unconverged weights would still give disjoint floes, but not the sizes asked for: refuse.
  // A keep-out zone across the domain's edge can close off a pocket of free water between its
  // outline and the edge; a cell there has no free boundary with the others, so its area has no
  // derivative in their weights and Newton cannot fill it (the towing case's iceberg, its notch
  // cut by the top edge, fails so for most seeds; keeping sites out of the pocket rescues half).
  // That is the scene's geometry, refused as such; any other failure is the generator's.
  if (!(solve.max_relative_error <= 1e-3)) {
    for (const KeepOutPiece& k : domain.keep_out)
      for (const Vec2 v : k.polygon)
        if (v.x <= domain.lo.x || v.y <= domain.lo.y || v.x >= domain.hi.x || v.y >= domain.hi.y) {
          const std::string name =
              k.zone < spec.keep_out_names.size() ? spec.keep_out_names[k.zone] : "keep_out[" + std::to_string(k.zone) + "]";
          throw FieldSpecError("keep_out[" + std::to_string(k.zone) + "]",
                               name + " crosses the domain's edge, which can close off pockets of water that the "
                               "floes' cells cannot fill (the cell areas did not converge); allowed a domain that "
                               "holds each keep-out zone whole or leaves it outside");
        }
    throw std::runtime_error("field generator: the cell areas did not converge (largest relative error " +
                             num(solve.max_relative_error) + " after " + std::to_string(solve.iterations) +
                             " Newton steps); please report the parameters and seed");
  }
}

/// A cell reaching into a keep-out zone keeps, for each zone it meets, the larger side of one
/// edge line of the zone (the part of the cell outside that edge is convex and clear of it).
std::vector<Vec2> cut_keep_out(std::vector<Vec2> cell, const Domain& domain) {
  const Aabb box = bounds_of(cell);
  for (const KeepOutPiece& piece : domain.keep_out) {
    if (!piece.box.overlaps(box) || intersection_moments(cell, piece.polygon).area <= 0.0) continue;
    const std::size_t m = piece.polygon.size();
    double best_area = -1.0;
    LabeledPolygon best, side, in{cell, std::vector<std::int32_t>(cell.size(), -1)};
    for (std::size_t k = 0; k < m; ++k) {
      const Vec2 e = piece.polygon[(k + 1) % m] - piece.polygon[k];
      const Vec2 inward{-e.y, e.x};
      clip(in, side, inward, dot(inward, piece.polygon[k]), -1);  // outside of edge k
      const double a = side.p.size() >= 3 ? area_moments(side.p).area : 0.0;
      if (a > best_area) {
        best_area = a;
        best = side;
      }
    }
    cell = best.p;
    if (cell.size() < 3) break;
  }
  return cell;
}

/// Floes: each cell (minus any keep-out zone) shrunk about its centroid to its floe area.
void shrink_cells(const FieldSpec& spec, const Domain& domain, const CellTargets& t,
                  std::vector<std::vector<Vec2>>& polygons, Field& field) {
  const double d_min_area = area_of_diameter(spec.d_min);
  const std::size_t n = polygons.size();
  field.floes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<Vec2> cell = std::move(polygons[i]);
    if (cell.size() < 3) continue;
    if (!domain.keep_out.empty()) {
      cell = cut_keep_out(std::move(cell), domain);
      if (cell.size() < 3) continue;
    }
    const AreaMoments m0 = area_moments(cell);
    cell = clean_convex(std::move(cell), 1e-4 * std::sqrt(m0.area));
    const AreaMoments m = area_moments(cell);
    // A sliver left by a keep-out cut can clean to a segment (no area): no floe, counted short
    // (shrinking it would divide 0 by 0; found by a 600 m x 400 m field round an iceberg).
    if (cell.size() < 3 || !(m.area > 0.0)) {
      ++field.stats.floes_short_of_area;
      continue;
    }
    double a = t.floe_area[i];
    if (m.area < a) {
      // Only a keep-out cut can leave a cell short of its floe (the weights are solved to 1e-6).
      a = m.area * t.floe_area[i] / t.target[i];
      // A corner left by the cut, smaller than the smallest floe asked for, is no floe of the
      // distribution: dropped. Kept, it was a body hundreds of times lighter than its
      // neighbours (a 0.6 m fragment of 289 kg wedged between the iceberg and 5e4 kg floes,
      // seed 2 of drift_in_field, squeezed out at 1.5 m/s), and it biased the fitted exponent.
      if (a < d_min_area) {
        ++field.stats.floes_dropped_below_d_min;
        continue;
      }
      ++field.stats.floes_short_of_area;
    }
    const double shrink = std::sqrt(a / m.area);
    std::vector<Vec2> floe(cell.size());
    for (std::size_t k = 0; k < cell.size(); ++k) floe[k] = m.centroid + shrink * (cell[k] - m.centroid);
    field.floes.push_back(std::move(floe));
  }
}

/// Statistics of what was made, measured on the polygons.
void measure_field(const FieldSpec& spec, const Domain& domain, Field& field) {
  FieldStats& st = field.stats;
  st.floes = field.floes.size();
  st.free_area = domain.free_area;
  std::vector<double> d;
  d.reserve(st.floes);
  for (const auto& f : field.floes) {
    const double a = signed_area(f);
    st.ice_area += a;
    d.push_back(std::sqrt(4.0 * a / std::numbers::pi));
  }
  st.concentration = st.ice_area / st.free_area;
  st.fit = fit_truncated_power_law(d, spec.d_min, spec.d_max);
}

}  // namespace

Field generate_field(const FieldSpec& spec) {
  check_field_spec(spec);
  const Domain domain = make_domain(spec, false);
  const TruncatedPowerLaw law{spec.alpha, spec.d_min, spec.d_max};
  Random rng(spec.seed);

  // 1. Sizes, shuffled: site k gets floe area A_k and cell area A_k / C.
  std::vector<double> sizes = stratified_sizes(law, spec.concentration * domain.free_area);
  const std::size_t n = sizes.size();
  for (std::size_t i = n; i > 1; --i) std::swap(sizes[i - 1], sizes[rng.below(i)]);  // Fisher-Yates
  const CellTargets targets = cell_targets(sizes, domain.free_area);
  // 2. Sites: uniform in the free area.
  std::vector<Vec2> sites = place_sites(domain, n, rng);
  // 3. Weights and Lloyd steps.
  std::vector<double> w(n, 0.0);
  CellSet cells;
  Field field;
  relax_cells(spec, domain, targets.target, sites, w, cells, field.stats);
  // 4. Floes.
  std::vector<std::vector<Vec2>> polygons;
  compute_cells(sites, w, domain, cells, &polygons);
  shrink_cells(spec, domain, targets, polygons, field);

  number_along_hilbert_curve(spec, field.floes);

  // Thickness, drawn in floe order after the geometry (so a thickness change leaves shapes alone).
  field.thickness.reserve(field.floes.size());
  Random thickness_rng(spec.seed ^ 0x9e3779b97f4a7c15ULL);
  for (std::size_t i = 0; i < field.floes.size(); ++i) field.thickness.push_back(draw_thickness(spec.thickness, thickness_rng));
  measure_field(spec, domain, field);
  return field;
}

}  // namespace floedem
