#include "solver/island_solve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "solver/contact_solver.hpp"

// Why: projected Gauss-Seidel hands a wall's reaction on by one contact per sweep, and through a
// light floe pressed by a heavy body only the fraction m_light / m_heavy of what the heavy body
// needs: an iceberg of mass M pressing floes of mass m against a wall needs of the order of M/m
// sweeps (Erleben 2007, "Velocity-based shock propagation for multibody dynamics animation",
// ACM TOG 26(2), sec. 2; measured here: 5 mm of overlap at M/m = 1e3 after 50 sweeps, bodies
// through the wall at 1e6). The normal problem of such an island is small and sparse; solved
// directly it holds whatever the mass ratio.
//
// The problem (contact_solver.cpp has the single-point form), for the points i of the islands,
// normal n_i from body a_i to b_i, tangent t_i = k x n_i:
//
//   u_n = u_free + A P_n,   P_n >= 0,   u_n - u* >= 0,   P_n . (u_n - u*) = 0,
//
// u_free: the normal velocities with the islands' normal impulses taken away (friction held as
// Gauss-Seidel left it, or taken away too); u*: each point's target (Newton's law for a collision, -gap/dt at
// rest); A = W_nn = J_n M^-1 J_n^T, for points i and j sharing body c (s = -1 if c is the
// point's a, +1 if its b; r the lever arms):
//
//   A_ij += s_ic s_jc (1/m_c n_i.n_j + 1/I_c (r_ic x n_i)(r_jc x n_j)),   A_ii = wnn_i.
//
// Method: block principal pivoting (Judice and Pires 1994, Computers & Operations Research
// 21(5)): guess the pressing set, solve its equalities u_n = u*, move every point with P_n < 0
// out of it and every point outside that still approaches into it, repeat; when the count of
// wrong points stops falling, one point at a time (Murty's rule), which ends for a positive
// definite A. Redundant contacts (boxes touching along a face at two points each side) make A
// singular: A + eps diag(A) is factorised (eps = 1e-10 after Jacobi scaling) and the
// equalities solved to the velocity tolerance by iterative refinement on A itself.
//
// Ordering: each round factorises the pressing set's A anew, and a fill-reducing order
// (approximate minimum degree, Amestoy, Davis and Duff 1996, SIAM J. Matrix Anal. Appl. 17(4))
// found for each was half the factorisation's cost in a jammed pack (some 2 200 pressing of
// 2 600 points, five rounds a solve). It is found once for the matrix of all the islands'
// points and each pressing set eliminated in the order it induces: the fill of a principal
// submatrix in the induced order is within that of the whole (a fill edge of the submatrix is
// a path through earlier vertices of its graph, which is a path in the whole graph too; Rose,
// Tarjan and Lueker 1976, SIAM J. Comput. 5(2), lemma 4). The order is kept while the points
// join the same bodies (the solves of one step, and of a pack that holds still).
//
// The engine solves first without friction (the sweeps' friction was found against their wrong
// normals: held, it throws light floes sideways), then alternates this solve with Gauss-Seidel
// sweeps, which bring friction back to its law (stick or slide) for the new normals, and ends
// with it: normals exact; friction then cut back to the cone where a normal impulse fell (a
// small cut: the sweeps had it right for nearly these normals; where a point lets go, its
// friction goes with it).

namespace floedem {

namespace {

constexpr double regularisation = 1e-10;  // of each diagonal entry (Jacobi-scaled)
constexpr int max_rounds = 100;
constexpr int max_refinements = 12;

}  // namespace

double IslandSolver::normal_velocity(const Manifold& m, const ManifoldPoint& q, const BodyArrays& s) {
  return dot(relative_velocity(s, m.body_a, m.body_b, q.ra, q.rb), m.normal);
}

double IslandSolver::shortfall(const Manifold& m, const ManifoldPoint& q, const BodyArrays& s) {
  return q.target_velocity - normal_velocity(m, q, s);
}

void IslandSolver::apply(std::span<const Manifold> manifolds, BodyArrays& s, std::size_t i, double pn,
                         double pt) const {
  if (pn == 0.0 && pt == 0.0) return;
  const Manifold& m = manifolds[points_[i].manifold];
  apply_impulse(s, m, m.points[points_[i].index], pn * m.normal + pt * perp(m.normal));
}

void IslandSolver::apply_normals(std::span<const Manifold> manifolds, BodyArrays& s) const {
  s.velocity = free_linear_;
  s.angular_velocity = free_angular_;
  for (std::size_t i = 0; i < points_.size(); ++i) apply(manifolds, s, i, normal_[i], 0.0);
}

bool IslandSolver::approaching(std::span<const Manifold> manifolds, const BodyArrays& s, std::size_t i,
                               double tolerance) const {
  const ManifoldPoint& q = point(manifolds, i);
  return normal_velocity(manifolds[points_[i].manifold], q, s) < q.target_velocity - tolerance;
}

bool IslandSolver::heavy_light(std::span<const std::int32_t> bodies, const BodyArrays& s, double mass_ratio) {
  double largest_inv_mass = 0.0, smallest_inv_mass = std::numeric_limits<double>::infinity();
  for (const std::int32_t body : bodies) {
    largest_inv_mass = std::max(largest_inv_mass, s.inv_mass[body]);
    smallest_inv_mass = std::min(smallest_inv_mass, s.inv_mass[body]);
  }
  return largest_inv_mass >= mass_ratio * smallest_inv_mass;
}

bool IslandSolver::needs_solve(const Manifold& m, const ManifoldPoint& q, const BodyArrays& s) const {
  const double f = shortfall(m, q, s);
  return f > trigger_.creep &&
         (f > trigger_.closing || std::max(-q.separation, 0.0) + f * trigger_.dt > trigger_.allowed_overlap);
}

bool IslandSolver::select(std::span<const Manifold> manifolds, const BodyArrays& s, const Trigger& trigger,
                          double mass_ratio) {
  trigger_ = trigger;
  // 1. Is there a point left approaching beyond its target by more than the creep?
  points_.clear();
  if (largest_shortfall(manifolds, s) <= trigger.creep) return false;

  // 2. Islands (contact_islands.hpp); the points of those holding such a point whose heaviest
  // body is at least mass_ratio times their lightest.
  islands_.build(manifolds, s);
  chosen_.assign(islands_.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < islands_.size(); ++i) {
    if (!heavy_light(islands_.bodies(i), s, mass_ratio)) continue;
    for (const std::int32_t k : islands_.manifolds(i)) {
      const Manifold& m = manifolds[static_cast<std::size_t>(k)];
      for (int q = 0; q < m.point_count; ++q) chosen_[i] = chosen_[i] || needs_solve(m, m.points[q], s);
    }
    any = any || chosen_[i];
  }
  if (!any) return false;
  manifolds_.clear();
  for (std::size_t mi = 0; mi < manifolds.size(); ++mi) {
    const Manifold& m = manifolds[mi];
    const std::int32_t island = islands_.island_of_manifold(mi);
    if (island < 0 || !chosen_[static_cast<std::size_t>(island)]) continue;
    manifolds_.push_back(static_cast<std::int32_t>(mi));
    for (int k = 0; k < m.point_count; ++k) points_.push_back({static_cast<std::int32_t>(mi), k, m.body_a, m.body_b});
  }
  order_points(s);
  return true;
}

void IslandSolver::group_by_body(std::size_t bodies) {
  body_start_.assign(bodies + 1, 0);
  for (const std::int32_t i : rows_) {
    ++body_start_[points_[i].a + 1];
    ++body_start_[points_[i].b + 1];
  }
  std::partial_sum(body_start_.begin(), body_start_.end(), body_start_.begin());
  body_row_.resize(static_cast<std::size_t>(body_start_[bodies]));
  fill_.assign(body_start_.begin(), body_start_.end() - 1);
  for (std::int32_t r = 0; r < static_cast<std::int32_t>(rows_.size()); ++r) {
    body_row_[fill_[points_[rows_[r]].a]++] = r;
    body_row_[fill_[points_[rows_[r]].b]++] = r;
  }
}

void IslandSolver::order_points(const BodyArrays& s) {
  const std::size_t np = points_.size();
  bool same = ordered_for_.size() == 2 * np;
  for (std::size_t i = 0; same && i < np; ++i)
    same = ordered_for_[2 * i] == points_[i].a && ordered_for_[2 * i + 1] == points_[i].b;
  if (same) return;
  ordered_for_.resize(2 * np);
  for (std::size_t i = 0; i < np; ++i) {
    ordered_for_[2 * i] = points_[i].a;
    ordered_for_[2 * i + 1] = points_[i].b;
  }
  // The pattern of A with every point pressing: points i, j are coupled where they share a
  // moving body (the lower triangle; the ordering reads it as symmetric).
  rows_.resize(np);
  std::iota(rows_.begin(), rows_.end(), 0);
  const std::size_t nb = s.position.size();
  group_by_body(nb);
  triplets_.clear();
  for (std::size_t c = 0; c < nb; ++c) {
    if (s.inv_mass[c] == 0.0) continue;
    for (std::int32_t x = body_start_[c]; x < body_start_[c + 1]; ++x)
      for (std::int32_t y = body_start_[c]; y < x; ++y) triplets_.emplace_back(body_row_[x], body_row_[y], 1.0);
  }
  for (std::size_t i = 0; i < np; ++i) triplets_.emplace_back(static_cast<int>(i), static_cast<int>(i), 1.0);
  pattern_.resize(static_cast<Eigen::Index>(np), static_cast<Eigen::Index>(np));
  pattern_.setFromTriplets(triplets_.begin(), triplets_.end(),
                           [](double a, double b) { return std::max(a, b); });  // only the pattern counts
  // Both triangles: a point pair met at two bodies lands once in each.
  Eigen::SparseMatrix<double> whole = pattern_.selfadjointView<Eigen::Lower>();
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> elimination;  // position -> point
  Eigen::AMDOrdering<int>()(whole, elimination);
  order_.assign(elimination.indices().data(), elimination.indices().data() + np);
}

bool IslandSolver::solve(std::span<Manifold> manifolds, BodyArrays& s, bool without_friction) {
  const std::size_t np = points_.size();
  if (np == 0) return false;

  // 3. The first pressing set (pressed by Gauss-Seidel, or still approaching); then the
  // velocities without the islands' normal impulses (and friction, if asked).
  saved_linear_ = s.velocity;
  saved_angular_ = s.angular_velocity;
  active_.assign(np, 0);
  normal_.resize(np);
  start_.resize(np);
  for (std::size_t i = 0; i < np; ++i) {
    const Manifold& m = manifolds[points_[i].manifold];
    const ManifoldPoint& q = m.points[points_[i].index];
    active_[i] = q.normal_impulse > 0.0 || shortfall(m, q, s) > 0.0;
    start_[i] = q.normal_impulse;
    apply(manifolds, s, i, -q.normal_impulse, without_friction ? -q.tangent_impulse : 0.0);
  }
  free_linear_ = s.velocity;
  free_angular_ = s.angular_velocity;
  free_velocity_.resize(np);
  for (std::size_t i = 0; i < np; ++i)
    free_velocity_[i] = normal_velocity(manifolds[points_[i].manifold], point(manifolds, i), s);

  // 4. Block principal pivoting.
  const double tolerance = trigger_.tolerance;  // m/s, left as solved
  refine_to_ = 1e-2 * tolerance;
  std::size_t best_wrong = np + 1;
  int rounds_without_progress = 0;
  bool settled = false;
  for (int round = 0; round < max_rounds && !settled; ++round) {
    if (!solve_active(manifolds, s)) break;
    apply_normals(manifolds, s);
    // A pulling point: below -1e-9 of the largest impulse (redundant points share their load
    // arbitrarily, and their rounding noise must not read as pulling).
    double largest = 0.0;
    for (std::size_t i = 0; i < np; ++i) largest = std::max(largest, std::abs(normal_[i]));
    wrong_.clear();
    for (std::size_t i = 0; i < np; ++i) {
      if (active_[i] ? normal_[i] < -1e-9 * largest : approaching(manifolds, s, i, tolerance))
        wrong_.push_back(static_cast<std::int32_t>(i));
    }
    if (wrong_.empty()) {
      settled = true;
      break;
    }
    if (wrong_.size() < best_wrong) {
      best_wrong = wrong_.size();
      rounds_without_progress = 0;
    } else {
      ++rounds_without_progress;
    }
    if (rounds_without_progress >= 3)
      active_[static_cast<std::size_t>(wrong_.back())] ^= 1;  // Murty's rule
    else
      for (const std::int32_t i : wrong_) active_[static_cast<std::size_t>(i)] ^= 1;
  }
  if (!settled) settled = solve_by_descent(manifolds, s);
  if (!settled) {  // Gauss-Seidel's answer stays
    s.velocity = saved_linear_;
    s.angular_velocity = saved_angular_;
    return false;
  }
  for (std::size_t i = 0; i < np; ++i) {
    ManifoldPoint& q = manifolds[points_[i].manifold].points[points_[i].index];
    q.normal_impulse = normal_[i];
    if (without_friction) q.tangent_impulse = 0.0;
  }
  return true;
}

bool IslandSolver::solve_by_descent(std::span<const Manifold> manifolds, BodyArrays& s) {
  // When the pivoting does not settle (it can wander where redundant points make A nearly
  // singular): the same problem as the convex program min 1/2 P'AP + P'(u_free - u*), P >= 0,
  // by the active-set method of Lawson and Hanson (1974, "Solving least squares problems",
  // ch. 23), from Gauss-Seidel's impulses: solve the equalities of the pressing set; where that
  // would make an impulse negative, step only as far as keeps every impulse >= 0 and let go of
  // those at 0; then take in the point approaching most. Each step lowers the objective, so
  // it does not cycle as pivoting can.
  const std::size_t np = points_.size();
  const double tolerance = trigger_.tolerance;
  std::vector<double>& now = start_;  // feasible impulses, Gauss-Seidel's to begin with
  for (std::size_t i = 0; i < np; ++i) active_[i] = now[i] > 0.0;
  const int limit = 4 * static_cast<int>(np) + 10;
  for (int round = 0; round < limit; ++round) {
    if (!solve_active(manifolds, s)) return false;
    for (int inner = 0; inner < limit; ++inner) {
      double alpha = 1.0;
      for (std::size_t i = 0; i < np; ++i)
        if (active_[i] && normal_[i] <= 0.0) alpha = std::min(alpha, now[i] / (now[i] - normal_[i]));
      if (alpha >= 1.0) break;
      for (std::size_t i = 0; i < np; ++i) {
        now[i] = active_[i] ? now[i] + alpha * (normal_[i] - now[i]) : 0.0;
        if (active_[i] && now[i] <= 0.0) {
          active_[i] = 0;
          now[i] = 0.0;
        }
      }
      if (!solve_active(manifolds, s)) return false;
    }
    for (std::size_t i = 0; i < np; ++i) now[i] = active_[i] ? std::max(normal_[i], 0.0) : 0.0;
    normal_ = now;
    apply_normals(manifolds, s);
    // One point taken in per round, the one approaching most (Lawson and Hanson's rule: with it
    // the new point's impulse comes out positive, so the objective falls). Taking in every
    // approaching point at once cycled where the pressing sets are nearly singular: the 5 m/s
    // impact, 254 of 523 points pressing, the same sets for 2 000 rounds, and the pack driven
    // 9 cm into itself by Gauss-Seidel's answer, which was then kept.
    std::size_t most = np;
    double most_shortfall = tolerance;
    for (std::size_t i = 0; i < np; ++i)
      if (!active_[i]) {
        const double f = shortfall(manifolds[points_[i].manifold], point(manifolds, i), s);
        if (f > most_shortfall) {
          most_shortfall = f;
          most = i;
        }
      }
    if (most == np) return true;
    active_[most] = 1;
  }
  return false;
}

bool IslandSolver::solve_active(std::span<const Manifold> manifolds, const BodyArrays& s) {
  // Rows: the pressing points, in the elimination order (order_points); each body's rows
  // grouped (CSR).
  const std::size_t nb = s.position.size();
  std::fill(normal_.begin(), normal_.end(), 0.0);
  rows_.clear();
  for (const std::int32_t i : order_)
    if (active_[static_cast<std::size_t>(i)]) rows_.push_back(i);
  const auto nr = static_cast<std::int32_t>(rows_.size());
  if (nr == 0) return true;
  group_by_body(nb);
  auto lever = [&](std::int32_t r, std::size_t body) {
    const Point& p = points_[rows_[r]];
    const ManifoldPoint& q = manifolds[p.manifold].points[p.index];
    return static_cast<std::int32_t>(body) == p.a ? q.ra : q.rb;
  };
  auto sign = [&](std::int32_t r, std::size_t body) {
    return static_cast<std::int32_t>(body) == points_[rows_[r]].a ? -1.0 : 1.0;
  };
  auto normal = [&](std::int32_t r) { return manifolds[points_[rows_[r]].manifold].normal; };
  auto diagonal = [&](std::int32_t r) { return point(manifolds, static_cast<std::size_t>(rows_[r])).wnn; };
  // Jacobi scaling: A_ij / sqrt(A_ii A_jj), so that the scaled diagonal is 1; the upper
  // triangle (column-major: the factorisation reads it without a copy).
  triplets_.clear();
  for (std::size_t c = 0; c < nb; ++c) {
    if (s.inv_mass[c] == 0.0) continue;  // infinite mass couples nothing
    const double im = s.inv_mass[c], ii = s.inv_inertia[c];
    for (std::int32_t x = body_start_[c]; x < body_start_[c + 1]; ++x) {
      const std::int32_t i = body_row_[x];
      const Vec2 ni = normal(i);
      const double ri = cross(lever(i, c), ni);
      const double si = sign(i, c) / std::sqrt(diagonal(i));
      for (std::int32_t y = body_start_[c]; y < body_start_[c + 1]; ++y) {
        const std::int32_t j = body_row_[y];
        if (j >= i) continue;  // strict triangle; the diagonal is set below, whole
        const Vec2 dj = normal(j);
        const double rj = cross(lever(j, c), dj);
        const double sj = sign(j, c) / std::sqrt(diagonal(j));
        triplets_.emplace_back(j, i, si * sj * (im * dot(ni, dj) + ii * ri * rj));
      }
    }
  }
  for (std::int32_t r = 0; r < nr; ++r) triplets_.emplace_back(r, r, 1.0 + regularisation);
  a_.resize(nr, nr);
  a_.setFromTriplets(triplets_.begin(), triplets_.end());
  ldlt_.compute(a_);
  if (ldlt_.info() != Eigen::Success) return false;

  // x += (A + eps I)^-1 (b - A x) until the velocity residual is below refine_to_.
  Eigen::VectorXd b(nr), x(nr), residual(nr);
  for (std::int32_t r = 0; r < nr; ++r) {
    const auto i = static_cast<std::size_t>(rows_[r]);
    b[r] = (point(manifolds, i).target_velocity - free_velocity_[i]) / std::sqrt(diagonal(r));
  }
  x = ldlt_.solve(b);
  // Stops too when the residual no longer halves: the equalities are then inconsistent (more
  // pressing points than the bodies have freedoms, with targets no motion meets), and further
  // steps would only grow the impulses along the null space of A.
  double previous = std::numeric_limits<double>::infinity();
  for (int k = 0; k < max_refinements; ++k) {
    residual = b - (a_.selfadjointView<Eigen::Upper>() * x - regularisation * x);
    double worst = 0.0;
    for (std::int32_t r = 0; r < nr; ++r) worst = std::max(worst, std::abs(residual[r]) * std::sqrt(diagonal(r)));
    if (worst <= refine_to_ || worst > 0.5 * previous) break;
    previous = worst;
    x += ldlt_.solve(residual);
  }
  for (std::int32_t r = 0; r < nr; ++r) normal_[static_cast<std::size_t>(rows_[r])] = x[r] / std::sqrt(diagonal(r));
  return true;
}

}  // namespace floedem
