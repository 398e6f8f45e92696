#pragma once
// The native solver's shared types: the bodies as the solver sees them, the contact impulse
// helpers every path uses, the sweeps' rows and work space, their limits and options, and the
// position projection's memory. What the solver does with them is in contact_solver.hpp.
#include <cstdint>
#include <span>
#include <vector>

#include "collision/manifold.hpp"
#include "engine/line_vector.hpp"
#include "solver/native_settings.hpp"
#include "solver/sweep_bundle.hpp"

namespace floedem {

/// Body data the solver reads and writes every step (structure of arrays). The engine's
/// published state is this object itself: position, angle and velocities are BodyStates'.
struct BodyArrays : BodyStates {
  std::vector<Rot> rotation;
  std::vector<double> inv_mass;
  std::vector<double> inv_inertia;
};

/// Relative velocity of the contact point of b with respect to a.
inline Vec2 relative_velocity(const BodyArrays& s, int a, int b, Vec2 ra, Vec2 rb) {
  return (s.velocity[b] + cross(s.angular_velocity[b], rb)) - (s.velocity[a] + cross(s.angular_velocity[a], ra));
}

/// A point's Delassus block W_nn = n.M^-1 n, W_nt = n.M^-1 t, W_tt = t.M^-1 t (t = perp(n)):
/// W = (m_a + m_b) I + i_a (r_a x .)^2 + i_b (r_b x .)^2 for inverse masses m and inertias i
/// and lever arms r (contact_solver.cpp). One definition for prepare_contact (doubles) and the
/// coloured sweeps (four lanes, coloured_sweeps.cpp), so that both make the same values to the
/// bit: the same operations in the same order.
template <class T>
struct DelassusBlock {
  T wnn, wnt, wtt;
};
template <class T>
[[gnu::always_inline]] inline DelassusBlock<T> delassus_block(T ma, T ia, T mb, T ib, T rax, T ray, T rbx, T rby, T nx,
                                                              T ny) {
  const T rna = rax * ny - ray * nx, rnb = rbx * ny - rby * nx;    // cross(r, n)
  const T rta = rax * nx - ray * -ny, rtb = rbx * nx - rby * -ny;  // cross(r, t), t = (-n_y, n_x)
  return {ma + mb + ia * rna * rna + ib * rnb * rnb, ia * rna * rta + ib * rnb * rtb,
          ma + mb + ia * rta * rta + ib * rtb * rtb};
}

/// Applies `impulse` (on b; its opposite on a) at the contact point of lever arms ra, rb. A
/// fixed or prescribed body (inv_mass = inv_inertia = 0) keeps its given velocity and is not
/// written: the islands that share it are solved on several threads.
inline void apply_impulse(BodyArrays& s, int a, int b, Vec2 ra, Vec2 rb, Vec2 impulse) {
  if (s.inv_mass[a] != 0.0) {
    s.velocity[a] -= s.inv_mass[a] * impulse;
    s.angular_velocity[a] -= s.inv_inertia[a] * cross(ra, impulse);
  }
  if (s.inv_mass[b] != 0.0) {
    s.velocity[b] += s.inv_mass[b] * impulse;
    s.angular_velocity[b] += s.inv_inertia[b] * cross(rb, impulse);
  }
}
inline void apply_impulse(BodyArrays& s, const Manifold& m, const ManifoldPoint& p, Vec2 impulse) {
  apply_impulse(s, m.body_a, m.body_b, p.ra, p.rb, impulse);
}

/// One contact point as the sweeps read and write it: what its local solve needs, copied out of
/// its manifold in sweep order (as Box2D v3's contact constraints). A manifold is 384 bytes, of
/// which a point's solve reads about 100 over up to six cache lines; a row is 112 bytes, read in
/// order, and the warm start is made while the rows are copied instead of in a pass of its own.
struct SweepRow {
  std::int32_t body_a = 0, body_b = 0;
  Vec2 normal;                             ///< world, unit, from a to b
  Vec2 ra, rb;                             ///< lever arms from the centroids
  double wnn = 0.0, wnt = 0.0, wtt = 0.0;  ///< Delassus block
  double target_velocity = 0.0;            ///< m/s
  double friction = 0.0;
  double normal_impulse = 0.0, tangent_impulse = 0.0;  ///< accumulated, N s
};

/// Where a solve works: room for its rows (two per manifold at most) and, for the accelerated
/// sweeps, per row (n, t) pairs (four per manifold). Not owned: slices of a SweepWork, so that
/// the islands solved side by side share one buffer the size of the step's contacts (a buffer
/// per block of islands grew, on the 100k field, to a copy of the largest island each).
struct SweepSpace {
  std::span<SweepRow> rows;
  std::span<double> change;     ///< per row (n, t): the impulse change of the last sweep
  std::span<double> direction;  ///< per row (n, t): the conjugate direction p
  std::span<double> step;       ///< per row (n, t): beta p, the impulse the step adds
  /// For the coloured sweeps (SweepOptions::colour, coloured_sweeps.hpp): room for the
  /// solve's bundles (bundles_for(manifolds) at most); per manifold, room for the list of those
  /// beyond the 63 colours, swept as rows (in `rows`); and per body (the whole scene's, by body
  /// id) the colours its manifolds took so far, all zero between solves: islands share no
  /// moving body, so islands solved side by side write disjoint entries of it. Its NNCG arrays
  /// are per bundle (kBundleNncg doubles: point, n or t, lane), in the bundles' order, so that
  /// the sweep reads and stores a bundle's values as vectors; per manifold, room for the list
  /// of the solve's moving bodies (two each at most); and per body (the scene's, by body id,
  /// shared as body_colours) the velocities NNCG's step works on.
  std::span<SweepBundle> bundles;
  std::span<std::int32_t> overflow;
  std::span<std::uint64_t> body_colours;
  std::span<double> bundle_change, bundle_direction;
  std::span<std::int32_t> moving_bodies;
  std::span<BodyStep> body_steps;
  bool colours_given = false;  ///< overflow holds each manifold's colour (colour_manifolds); a solve overwrites them
};

/// The storage behind SweepSpaces, kept by the caller (no allocation per step once sized).
class SweepWork {
 public:
  /// Makes room for `manifolds` manifolds (rows; the accelerated sweeps' arrays too with
  /// `accelerate`), keeping what is there: a slice handed out before stays valid until the next call.
  /// With `colour_bodies` > 0, room for the coloured sweeps too, for a scene of that many
  /// bodies, with `bundles` bundles in all (bundles_for(manifolds) for one solve of them all).
  void reserve(std::size_t manifolds, bool accelerate, std::size_t colour_bodies = 0, std::size_t bundles = 0);
  /// The space of the manifolds [first, first + count) of what reserve() made room for, with
  /// the bundles [bundle_first, bundle_first + bundle_count).
  SweepSpace slice(std::size_t first, std::size_t count, std::size_t bundle_first = 0, std::size_t bundle_count = 0);
  /// Room for one solve of `manifolds` manifolds, and the whole of it.
  SweepSpace space(std::size_t manifolds, bool accelerate, std::size_t colour_bodies = 0) {
    const std::size_t bundles = colour_bodies > 0 ? bundles_for(manifolds) : 0;
    reserve(manifolds, accelerate, colour_bodies, bundles);
    return slice(0, manifolds, 0, bundles);
  }

 private:
  // Swept ten times a step and more: on huge pages once large (line_vector.hpp).
  LineVector<SweepRow> rows_;
  LineVector<double> change_, direction_, step_;
  LineVector<SweepBundle> bundles_;
  LineVector<double> bundle_change_, bundle_direction_;
  std::vector<std::int32_t> overflow_, moving_bodies_;
  std::vector<std::uint64_t> body_colours_;
  std::vector<BodyStep> body_steps_;
};

/// How long the sweeps go on.
struct SweepLimits {
  static constexpr int check_every = 10;  ///< past `iterations`, sweeps between looks at what is left closing
  int iterations = 50;         ///< sweeps made at most, unless a point is left closing (below)
  double tolerance = 1e-10;    ///< stop once no impulse changes by more than this times the largest
  int extra_iterations = 0;    ///< more sweeps, made only while ...
  double closing_speed = 0.0;  ///< ... a point approaches faster than its target by more than this (m/s)
};

/// How solve_velocities sweeps (contact_solver.hpp).
struct SweepOptions {
  bool warm_start = false;
  bool accelerate = false;
  /// Sweep the manifolds colour by colour, four at a time (coloured_sweeps.hpp), instead of in
  /// the order given: another Gauss-Seidel order, so other impulses after a given number of
  /// sweeps. Needs the space's coloured arrays.
  bool colour = false;
  /// Coloured: each colour large enough swept on the pool's threads, the same to the bit. Not
  /// from inside a loop of the pool. (The sweeps in pair order are one thread's.)
  bool threads = false;
  /// Coloured, without `accelerate`: place each colour's manifolds in the order given, not
  /// those of two points first (coloured_sweeps.cpp: the same impulses to the bit; the tests
  /// compare the two).
  bool given_order = false;
};
/// What solve_positions keeps between its sweeps and between steps (grown with headroom: no
/// allocation per step in the steady state).
struct ProjectionWork {
  std::uint64_t clock = 0;               ///< evaluations of a manifold so far (never reset)
  std::int64_t sweeps = 0;               ///< projection sweeps made so far (a work count, not state)
  std::vector<std::uint64_t> moved;      ///< per body: the evaluation that last changed its pose
  std::vector<std::uint64_t> evaluated;  ///< per manifold: the evaluation that last measured its gaps
  std::vector<double> depth;             ///< ... and the deepest of those gaps then (m, >= 0)
  // After the first sweep (solve_positions): the manifolds to measure again, as bits, and each
  // body's manifolds (CSR), so a sweep visits only those and not every manifold.
  std::vector<std::uint64_t> stale;       ///< per manifold, a bit: a body moved since it was measured
  std::vector<std::int32_t> body_first;   ///< body b's manifolds are body_manifolds[body_first[b] ...
  std::vector<std::int32_t> body_manifolds;  ///< ... body_first[b + 1])
  std::vector<std::int32_t> moved_bodies;  ///< the bodies the first sweep moved (each once)
  std::vector<std::int32_t> ends;          ///< per manifold, its two bodies (taken by the first sweep)
  std::vector<std::uint8_t> corrects;      ///< per manifold: a point corrects at the first sweep's start poses
};

/// An impulse (Pn, Pt) of one contact point: solve_single_contact's answer.
struct LocalImpulse {
  double normal = 0.0;
  double tangent = 0.0;
};
}  // namespace floedem
