#pragma once
// One Gauss-Seidel update of one contact row: the exact local solve of its 2x2 problem
// (contact_solver.cpp states the conditions) and the impulse change applied to its bodies.
// Shared by the serial sweeps (contact_solver.cpp) and the pipelined ones (sweep_pipeline.cpp),
// so that both make the same arithmetic in the same order: the same impulses to the bit.
#include <algorithm>
#include <cmath>
#include <span>

#include "solver/contact_solver.hpp"

namespace floedem {

// Inlined into the sweep (called once per point per sweep; inlined, the towing case's sweeps
// take about 3 % fewer instructions); the same arithmetic as a call, so the same impulses to the bit.
[[gnu::always_inline]] inline LocalImpulse local_impulse(double ufn, double uft, double target, double mu, double wnn,
                                                        double wnt, double wtt) {
  const double need = target - ufn;  // normal velocity change wanted
  if (need <= 0.0) return {};        // separating (or already fast enough): no impulse
  if (mu <= 0.0) return {need / wnn, 0.0};

  // Stick: u_n+ = u*, u_t+ = 0  =>  W (P_n, P_t) = (need, -u_t).
  const double det = wnn * wtt - wnt * wnt;
  const double pn_stick = (wtt * need + wnt * uft) / det;
  const double pt_stick = (-wnn * uft - wnt * need) / det;
  if (pn_stick >= 0.0 && std::abs(pt_stick) <= mu * pn_stick) return {pn_stick, pt_stick};

  // Slide with final slip direction s (= sign u_t+): P_t = -s mu P_n, and
  // (W_nn - s mu W_nt) P_n = need; consistent if P_n >= 0 and s u_t+ >= 0.
  const double first = pt_stick > 0.0 ? -1.0 : 1.0;  // friction saturates on the side stick wanted
  const double scale = std::abs(uft) + std::abs(need);
  for (const double s : {first, -first}) {
    const double denom = wnn - s * mu * wnt;
    if (denom <= 0.0) continue;
    const double pn = need / denom;
    const double ut = uft + (wnt - s * mu * wtt) * pn;
    if (s * ut >= -1e-14 * scale) return {pn, -s * mu * pn};
  }
  // No consistent case (Painleve-like configurations with strong coupling): the frictionless
  // normal impulse with friction clamped to the cone.
  const double pn = need / wnn;
  const double pt = std::clamp(-(uft + wnt * pn) / wtt, -mu * pn, mu * pn);
  return {pn, pt};
}

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
  const LocalImpulse r = local_impulse(ufn, uft, p.target_velocity, p.friction, p.wnn, p.wnt, p.wtt);
  const double dpn = r.normal - pn0, dpt = r.tangent - pt0;
  if (dpn != 0.0 || dpt != 0.0) apply_row_impulse(s, p, dpn * n + dpt * t);
  p.normal_impulse = r.normal;
  p.tangent_impulse = r.tangent;
  return {dpn, dpt};
}

}  // namespace floedem
