#pragma once
// A direct solve of the normal contact impulses of the islands that Gauss-Seidel cannot hold:
// heavy-light chains (an iceberg pressing light floes against a wall).
// The equations and the method are in island_solve.cpp.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "solver/contact_islands.hpp"
#include "solver/solver_types.hpp"

namespace floedem {

class IslandSolver {
 public:
  /// When a point needs the direct solve, and how far it solves (m/s, m, s). A point needs it
  /// when it is left approaching faster than its target by more than `creep`, and either by
  /// more than `closing` or by enough to end the step of `dt` deeper than `allowed_overlap`
  /// (its overlap now plus the shortfall times dt). The solve leaves every normal velocity
  /// within `tolerance` of its law.
  struct Trigger {
    double creep = 0.0, closing = 0.0, dt = 0.0, allowed_overlap = 0.0, tolerance = 0.0;
  };

  /// Whether the heaviest of these moving bodies is at least `mass_ratio` times the lightest.
  static bool heavy_light(std::span<const std::int32_t> bodies, const BodyArrays& s, double mass_ratio);

  /// Chooses the islands to solve: those holding a point that needs it (Trigger) and whose
  /// heaviest body is at least `mass_ratio` times their lightest. Islands: bodies joined by
  /// contacts; fixed and prescribed bodies (infinite mass) join nothing. Returns whether there
  /// is any.
  bool select(std::span<const Manifold> manifolds, const BodyArrays& bodies, const Trigger& trigger, double mass_ratio);

  /// Solves the normal impulses of the chosen islands directly, friction held as it is (or
  /// taken off, without_friction), and updates impulses and velocities; returns false and
  /// leaves everything as it was when the pressing set does not settle.
  bool solve(std::span<Manifold> manifolds, BodyArrays& bodies, bool without_friction);

  /// The manifolds of the chosen islands (indices, ascending).
  std::span<const std::int32_t> island_manifolds() const { return manifolds_; }

 private:
  struct Point {
    std::int32_t manifold;
    std::int32_t index;  ///< 0 or 1 within the manifold
    std::int32_t a, b;   ///< bodies
  };
  const ManifoldPoint& point(std::span<const Manifold> manifolds, std::size_t i) const {
    return manifolds[points_[i].manifold].points[points_[i].index];
  }
  static double normal_velocity(const Manifold& m, const ManifoldPoint& q, const BodyArrays& bodies);
  static double shortfall(const Manifold& m, const ManifoldPoint& q, const BodyArrays& bodies);  ///< u* - u_n
  bool needs_solve(const Manifold& m, const ManifoldPoint& q, const BodyArrays& bodies) const;  ///< Trigger
  void apply(std::span<const Manifold> manifolds, BodyArrays& bodies, std::size_t i, double pn, double pt) const;
  /// Velocities: the free ones plus every point's normal_ impulse.
  void apply_normals(std::span<const Manifold> manifolds, BodyArrays& bodies) const;
  /// Point i (not pressing) approaches faster than its target by more than tolerance.
  bool approaching(std::span<const Manifold> manifolds, const BodyArrays& bodies, std::size_t i, double tolerance) const;
  bool solve_active(std::span<const Manifold> manifolds, const BodyArrays& bodies);
  /// order_: the points in an elimination order of the matrix of all of them (a fill-reducing
  /// one, found again only when the points join other bodies than last time).
  void order_points(const BodyArrays& bodies);
  /// body_start_, body_row_: the rows_ of each body (CSR), for `bodies` bodies.
  void group_by_body(std::size_t bodies);
  bool solve_by_descent(std::span<const Manifold> manifolds, BodyArrays& bodies);

  std::vector<Point> points_;               // the islands' points
  std::vector<std::int32_t> manifolds_;     // the islands' manifolds
  std::vector<std::uint8_t> active_;        // per point: in the pressing set
  std::vector<double> normal_;              // per point: normal impulse being solved for
  std::vector<double> start_;               // per point: Gauss-Seidel's normal impulse (the descent's start)
  std::vector<double> free_velocity_;       // per point: u_n without the islands' impulses
  std::vector<std::int32_t> rows_;          // per row: its point (in the order of order_)
  std::vector<std::int32_t> order_;         // the points in elimination order (order_points)
  std::vector<std::int32_t> ordered_for_;   // the bodies a, b of each point order_ was found for
  std::vector<std::int32_t> wrong_;         // points whose answer breaks their conditions
  ContactIslands islands_;                  // of the manifolds select() was given
  std::vector<std::uint8_t> chosen_;        // per island: solved
  std::vector<std::int32_t> body_start_;    // per body + 1: where its rows begin in body_row_
  std::vector<std::int32_t> body_row_;      // rows grouped by body (each row under a and b)
  std::vector<std::int32_t> fill_;          // per body: fill cursor into body_row_
  std::vector<Vec2> free_linear_, saved_linear_;  // body velocities without the islands' impulses; as found
  std::vector<double> free_angular_, saved_angular_;
  std::vector<Eigen::Triplet<double>> triplets_;
  Eigen::SparseMatrix<double> a_;
  Eigen::SparseMatrix<double> pattern_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper, Eigen::NaturalOrdering<int>> ldlt_;
  double refine_to_ = 0.0;  // m/s: the velocity residual the refinement stops at
  Trigger trigger_;
};

}  // namespace floedem
