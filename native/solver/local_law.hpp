#pragma once
// The local contact law: the exact solution of one contact point's 2x2 problem, Newton
// restitution with Coulomb friction, written once for every sweep of the native solver. The
// sweeps in pair order (sweep_row.hpp) call it on doubles; the coloured
// sweeps (coloured_sweeps.cpp) on four lanes at once. One body of arithmetic for both, so a
// lane holds the scalar result to the bit and a change to the law is made in one place.
//
// The problem (contact_solver.cpp states the Delassus block W and the complementarity
// conditions; Moreau 1988, Jean 1999, Glocker and Pfeiffer 1995): given the relative velocity
// (u_n, u_t) without this point's own impulse and the target normal velocity u*, find
// (P_n, P_t) with
//     u_n+ = u_n + W_nn P_n + W_nt P_t,   u_t+ = u_t + W_nt P_n + W_tt P_t,
//     P_n >= 0,  u_n+ >= u*,  P_n (u_n+ - u*) = 0,
//     |P_t| <= mu P_n,  |P_t| < mu P_n => u_t+ = 0,  u_t+ != 0 => P_t = -mu P_n sign(u_t+).
// Its cases, in the order the first that holds is taken:
//   apart         need = u* - u_n <= 0                 P = 0
//   frictionless  mu <= 0                               P_n = need / W_nn, P_t = 0
//   stick         W (P_n, P_t) = (need, -u_t), P_n >= 0 and |P_t| <= mu P_n
//   slide s       P_t = -s mu P_n, (W_nn - s mu W_nt) P_n = need, consistent when the divisor
//                 is positive and s u_t+ >= 0 (to 1e-14 of |u_t| + |need|); tried first with
//                 the sign stick wanted to exceed (s = -1 where stick's P_t > 0), then the other
//   neither       (Painleve-like strong coupling) the frictionless normal impulse with friction
//                 clamped to the cone: P_n = need / W_nn, P_t = clamp(-(u_t + W_nt P_n) / W_tt)
// Each case's formula is written once below. On one point the cases are tried in order and
// the first that holds returned; on lanes every case is computed and the first that holds
// selected, lane by lane (no branch). The arithmetic of a case is the same either way, so a
// lane holds the one-point result to the bit. Divisions are multiplications by correctly
// rounded reciprocals; a slide whose divisor is not positive gets a NaN reciprocal, so its
// consistency test fails.
//
// An Ops type gives the arithmetic on T (double or four lanes): lanes (whether T holds several
// points), mask (the comparisons' type), select(m, a, b) = a where m holds else b,
// both(m1, m2), absolute(x), splat(x), less, less_equal.
#include <cmath>
#include <limits>

#include "geometry/lane_inline.hpp"

namespace floedem {

/// The operations local_law needs, on one double.
struct ScalarOps {
  using value = double;
  using mask = bool;
  static constexpr bool lanes = false;
  [[gnu::always_inline]] static double select(bool m, double a, double b) { return m ? a : b; }
  [[gnu::always_inline]] static bool both(bool a, bool b) { return a && b; }
  [[gnu::always_inline]] static double absolute(double x) { return std::abs(x); }
  [[gnu::always_inline]] static double splat(double x) { return x; }
  [[gnu::always_inline]] static bool less(double a, double b) { return a < b; }
  [[gnu::always_inline]] static bool less_equal(double a, double b) { return a <= b; }
};

/// The point's new impulses (P_n, P_t) from its velocity without them (u_n, u_t), its target
/// normal velocity, friction coefficient and Delassus block: the law above.
template <class Ops, class T = typename Ops::value>
[[gnu::always_inline]] inline void local_law(T ufn, T uft, T target, T mu, T wnn, T wnt, T wtt, T& pn, T& pt) {
  const T zero = Ops::splat(0.0), one = Ops::splat(1.0);
  const T need = target - ufn;
  // Each case's impulse and test, written once; the two evaluation orders below take them.
  const auto frictionless_normal = [&]() FLOEDEM_LANES_LAMBDA { return need * (one / wnn); };
  const auto neither = [&](T pn_free) FLOEDEM_LANES_LAMBDA {  // friction clamped to the cone (std::clamp)
    const T want = -(uft + wnt * pn_free) * (one / wtt);
    const T cone = mu * pn_free;
    return Ops::select(Ops::less(want, -cone), -cone, Ops::select(Ops::less(cone, want), cone, want));
  };
  const auto inverse_det = [&]() FLOEDEM_LANES_LAMBDA { return one / (wnn * wtt - wnt * wnt); };
  const auto stick_tangent = [&](T inv_det) FLOEDEM_LANES_LAMBDA { return (-wnn * uft - wnt * need) * inv_det; };
  const auto stick_normal = [&](T inv_det) FLOEDEM_LANES_LAMBDA { return (wtt * need + wnt * uft) * inv_det; };
  const auto stick_holds = [&](T stick_pn, T stick_pt) FLOEDEM_LANES_LAMBDA {
    return Ops::both(Ops::less_equal(zero, stick_pn), Ops::less_equal(Ops::absolute(stick_pt), mu * stick_pn));
  };
  // Slide s: 1 / (W_nn - s mu W_nt), NaN where that is not positive (the slide never holds).
  const auto slide_inverse = [&](T s) FLOEDEM_LANES_LAMBDA {
    const T divisor = wnn - s * mu * wnt;
    return Ops::select(Ops::less(zero, divisor), one / divisor, Ops::splat(std::numeric_limits<double>::quiet_NaN()));
  };
  const auto slide_holds = [&](T s, T slide_pn) FLOEDEM_LANES_LAMBDA {
    const T slack = Ops::splat(-1e-14) * (Ops::absolute(uft) + Ops::absolute(need));
    return Ops::less_equal(slack, s * (uft + (wnt - s * mu * wtt) * slide_pn));
  };

  if constexpr (!Ops::lanes) {
    // One point: the first case that holds, taken in order (the cases fall at random from
    // point to point; a branch skips the others' arithmetic).
    pn = pt = zero;
    if (need <= zero) return;
    if (mu <= zero) {
      pn = frictionless_normal();
      return;
    }
    const T inv_det = inverse_det();
    pn = stick_normal(inv_det);
    pt = stick_tangent(inv_det);
    if (stick_holds(pn, pt)) return;
    const T first = zero < pt ? -one : one;  // friction saturates on the side stick wanted
    for (const T s : {first, -first}) {
      pn = need * slide_inverse(s);
      pt = -s * mu * pn;
      if (slide_holds(s, pn)) return;
    }
    pn = frictionless_normal();
    pt = neither(pn);
  } else {
    // Lanes: every case computed, from the last to the first, each selected where it holds,
    // so that the first case that holds is the one left (few values live at once: the sweep's
    // velocities and maxima hold most of AVX2's sixteen registers).
    pn = frictionless_normal();
    pt = neither(pn);
    const T inv_det = inverse_det();
    const T pt_stick = stick_tangent(inv_det);
    const auto minus_first = Ops::less(zero, pt_stick);
    const T first = Ops::select(minus_first, -one, one);
    for (const T s : {-first, first}) {
      const T slide_pn = need * slide_inverse(s);
      const auto holds = slide_holds(s, slide_pn);
      pn = Ops::select(holds, slide_pn, pn);
      pt = Ops::select(holds, -s * mu * slide_pn, pt);
    }
    const T pn_stick = stick_normal(inv_det);
    const auto stick = stick_holds(pn_stick, pt_stick);
    pn = Ops::select(stick, pn_stick, pn);
    pt = Ops::select(stick, pt_stick, pt);
    const auto frictionless = Ops::less_equal(mu, zero);
    pn = Ops::select(frictionless, frictionless_normal(), pn);
    pt = Ops::select(frictionless, zero, pt);
    const auto apart = Ops::less_equal(need, zero);
    pn = Ops::select(apart, zero, pn);
    pt = Ops::select(apart, zero, pt);
  }
}

}  // namespace floedem
