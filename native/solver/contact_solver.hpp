#pragma once
// Velocity-level contact impulses (sequential impulses / projected Gauss-Seidel with an exact
// local solve per contact) and the energy-free position projection: the solver's entry points.
// Their types are in solver_types.hpp.
#include <cstdint>
#include <span>

#include "solver/solver_types.hpp"

namespace floedem {

/// Classifies each point of m (collision or resting) from its approach velocity and gap, sets
/// its target normal velocity, and fills the Delassus block. A collision's impulses start from
/// zero (Newton's law fixes them; a warm start's guess would be a resting impulse's).
/// `held`: the same pair's manifold as the step's first pass classified it, when the step's
/// contacts are found again (a redetection); a point it holds keeps the approach velocity it
/// was classified on there, measured before the loads, so it is classified as it was.
void prepare_contact(Manifold& m, const BodyArrays& bodies, double dt, double collision_threshold,
                     const Manifold* held = nullptr);

/// Applies the accumulated impulses times `sign`: +1 for a warm start (solve_velocities makes its
/// own), -1 to take a solve's impulses off again (they are all it applied).
void apply_accumulated_impulses(std::span<const Manifold> manifolds, BodyArrays& bodies, double sign);

/// Gauss-Seidel sweeps until the largest impulse change is below tolerance times the largest
/// impulse, or the limits' sweeps are spent. With `warm_start`, each point's accumulated impulse
/// is applied first (as apply_accumulated_impulses with +1, in the same order); with
/// `accelerate`, each sweep but the last is followed by the nonsmooth nonlinear conjugate
/// gradient step (see contact_solver.cpp). The manifolds' impulses are read at the start and
/// written back at the end. Returns the number of sweeps made.
/// `space` must hold manifolds.size() manifolds (and their accelerated arrays with `accelerate`).
int solve_velocities(std::span<Manifold> manifolds, BodyArrays& bodies, const SweepLimits& limits, SweepSpace space,
                     SweepOptions options = {});
/// The same over one island's manifolds (indices into `manifolds`, swept in that order):
/// the sweeps stop on that island's own changes and impulses.
int solve_velocities(std::span<Manifold> manifolds, std::span<const std::int32_t> island, BodyArrays& bodies,
                     const SweepLimits& limits, SweepSpace space, SweepOptions options = {});

/// The largest amount by which a point approaches faster than its target (m/s, >= 0).
double largest_shortfall(std::span<const Manifold> manifolds, const BodyArrays& bodies);

/// Cuts every friction impulse back to its cone |P_t| <= mu P_n (after the normals changed),
/// applying the difference to the bodies. Returns how many were cut.
int clamp_friction(std::span<Manifold> manifolds, BodyArrays& bodies);

/// Nonlinear Gauss-Seidel on positions (Box2D v2.4's position solver): pushes overlapping
/// bodies apart beyond `allowed_penetration`, touching positions only, never velocities, so
/// that drift correction adds no kinetic energy. Returns the deepest penetration found (m, >= 0).
double solve_positions(std::span<const Manifold> manifolds, BodyArrays& bodies, const NativeSettings& settings,
                       ProjectionWork& work);

/// The exact solution of the single-contact problem (Newton restitution with Coulomb
/// friction, see contact_solver.cpp). u_free: relative velocity (n, t) without this
/// contact's impulse; returns the impulse (Pn, Pt).
LocalImpulse solve_single_contact(double ufn, double uft, double target, double mu, double wnn, double wnt, double wtt);

}  // namespace floedem
