#pragma once
// One Gauss-Seidel update of one contact row: the exact local solve of its 2x2 problem
// (contact_solver.cpp states the conditions) and the impulse change applied to its bodies.
// The sweeps in pair order (contact_solver.cpp), and the coloured sweeps' rows beyond their 63
// colours (coloured_sweeps.cpp), sweep with it.
#include <algorithm>
#include <cmath>
#include <span>

#include "solver/solver_types.hpp"
#include "solver/local_law.hpp"

namespace floedem {

/// Applies `impulse` (on the row's body b; its opposite on a) at the row's contact point.
inline void apply_row_impulse(BodyArrays& s, const SweepRow& r, Vec2 impulse) {
  apply_impulse(s, r.body_a, r.body_b, r.ra, r.rb, impulse);
}

/// largest_shortfall over rows (the same points in the same order): the largest amount by
/// which a point approaches faster than its target (m/s, >= 0).
inline double largest_shortfall_of(std::span<const SweepRow> rows, const BodyArrays& s) {
  double worst = 0.0;
  for (const SweepRow& r : rows)
    worst = std::max(worst, r.target_velocity - dot(relative_velocity(s, r.body_a, r.body_b, r.ra, r.rb), r.normal));
  return worst;
}

/// The row's impulse change of one sweep (N s).
struct RowChange {
  double normal = 0.0, tangent = 0.0;
};

/// Solves row p against the bodies' current velocities, applies the change of its impulses to
/// its bodies (none if it did not change) and stores the new impulses in p.
[[gnu::always_inline]] inline RowChange sweep_row(SweepRow& p, BodyArrays& s) {
  const Vec2 n = p.normal;
  const Vec2 t = perp(n);
  const Vec2 u = relative_velocity(s, p.body_a, p.body_b, p.ra, p.rb);
  const double pn0 = p.normal_impulse, pt0 = p.tangent_impulse;
  // Velocity without this point's own impulse.
  const double ufn = dot(u, n) - (p.wnn * pn0 + p.wnt * pt0);
  const double uft = dot(u, t) - (p.wnt * pn0 + p.wtt * pt0);
  LocalImpulse r;
  local_law<ScalarOps>(ufn, uft, p.target_velocity, p.friction, p.wnn, p.wnt, p.wtt, r.normal, r.tangent);
  const double dpn = r.normal - pn0, dpt = r.tangent - pt0;
  if (dpn != 0.0 || dpt != 0.0) apply_row_impulse(s, p, dpn * n + dpt * t);
  p.normal_impulse = r.normal;
  p.tangent_impulse = r.tangent;
  return {dpn, dpt};
}

}  // namespace floedem
