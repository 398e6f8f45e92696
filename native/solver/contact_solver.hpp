#pragma once
// Velocity-level contact impulses (sequential impulses / projected Gauss-Seidel with an exact
// local solve per contact) and the energy-free position projection.
#include <cstdint>
#include <span>
#include <vector>

#include "solver/contact_types.hpp"
#include "solver/native_settings.hpp"

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

/// Classifies each point of m (collision or resting) from its approach velocity and gap, sets
/// its target normal velocity, and fills the Delassus block. A collision's impulses start from
/// zero (Newton's law fixes them; a warm start's guess would be a resting impulse's).
void prepare_contact(Manifold& m, const BodyArrays& bodies, double dt, double collision_threshold);

/// Applies `impulse` (on b; its opposite on a) at point p of manifold m. A fixed or prescribed
/// body (inv_mass = inv_inertia = 0) keeps its given velocity and is not written: the islands
/// that share it are solved on several threads.
inline void apply_impulse(BodyArrays& s, const Manifold& m, const ManifoldPoint& p, Vec2 impulse) {
  const int a = m.body_a, b = m.body_b;
  if (s.inv_mass[a] != 0.0) {
    s.velocity[a] -= s.inv_mass[a] * impulse;
    s.angular_velocity[a] -= s.inv_inertia[a] * cross(p.ra, impulse);
  }
  if (s.inv_mass[b] != 0.0) {
    s.velocity[b] += s.inv_mass[b] * impulse;
    s.angular_velocity[b] += s.inv_inertia[b] * cross(p.rb, impulse);
  }
}

/// Applies the accumulated impulses times `sign`: +1 for the warm start, -1 to take a solve's
/// impulses off again (they are all it applied).
void apply_accumulated_impulses(std::span<const Manifold> manifolds, BodyArrays& bodies, double sign);
/// The same for one island's manifolds (indices into `manifolds`, in that order).
void apply_accumulated_impulses(std::span<const Manifold> manifolds, std::span<const std::int32_t> island,
                                BodyArrays& bodies, double sign);
inline void warm_start(std::span<const Manifold> manifolds, BodyArrays& bodies) {
  apply_accumulated_impulses(manifolds, bodies, 1.0);
}

/// Per-point work arrays of the accelerated sweeps (kept by the caller: no allocation per step).
struct SweepMomentum {
  std::vector<double> change;     ///< per point (n, t): the impulse change of the last sweep
  std::vector<double> direction;  ///< per point (n, t): the conjugate direction p
  std::vector<double> step;       ///< per point (n, t): beta p, the impulse the step adds
};

/// How long the sweeps go on.
struct SweepLimits {
  int iterations = 50;         ///< sweeps made at most, unless a point is left closing (below)
  double tolerance = 1e-10;    ///< stop once no impulse changes by more than this times the largest
  int extra_iterations = 0;    ///< more sweeps, made only while ...
  double closing_speed = 0.0;  ///< ... a point approaches faster than its target by more than this (m/s)
};

/// Gauss-Seidel sweeps until the largest impulse change is below tolerance times the largest
/// impulse, or the limits' sweeps are spent. With `momentum`, each sweep but the last is
/// followed by the nonsmooth nonlinear conjugate gradient step (see contact_solver.cpp).
/// Returns the number of sweeps made.
int solve_velocities(std::span<Manifold> manifolds, BodyArrays& bodies, const SweepLimits& limits,
                     SweepMomentum* momentum = nullptr);
/// The same over one island's manifolds (indices into `manifolds`, swept in that order):
/// the sweeps stop on that island's own changes and impulses.
int solve_velocities(std::span<Manifold> manifolds, std::span<const std::int32_t> island, BodyArrays& bodies,
                     const SweepLimits& limits, SweepMomentum* momentum = nullptr);

/// The largest amount by which a point approaches faster than its target (m/s, >= 0).
double largest_shortfall(std::span<const Manifold> manifolds, const BodyArrays& bodies);

/// Cuts every friction impulse back to its cone |P_t| <= mu P_n (after the normals changed),
/// applying the difference to the bodies. Returns how many were cut.
int clamp_friction(std::span<Manifold> manifolds, BodyArrays& bodies);

/// Nonlinear Gauss-Seidel on positions (Box2D v2.4's position solver): pushes overlapping
/// bodies apart beyond `allowed_penetration`, touching positions only, never velocities, so
/// that drift correction adds no kinetic energy. Returns the deepest penetration found (m, >= 0).
double solve_positions(std::span<const Manifold> manifolds, BodyArrays& bodies, const NativeSettings& settings);

/// The exact solution of the single-contact problem (Newton restitution with Coulomb
/// friction, see contact_solver.cpp). u_free: relative velocity (n, t) without this
/// contact's impulse; returns the impulse (Pn, Pt).
struct LocalImpulse {
  double normal = 0.0;
  double tangent = 0.0;
};
LocalImpulse solve_single_contact(double ufn, double uft, double target, double mu, double wnn, double wnt, double wtt);

}  // namespace floedem
