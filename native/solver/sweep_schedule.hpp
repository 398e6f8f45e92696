#pragma once
// The rules of the velocity sweeps' loop, written once for both orders that run it (pair order
// in contact_solver.cpp, coloured in coloured_sweeps.cpp): when the sweeps stop, and NNCG's
// Fletcher-Reeves step between two sweeps. Each order keeps its own arithmetic for the sweep and
// for applying the step; only the decisions live here.
#include <algorithm>

#include "solver/solver_types.hpp"

namespace floedem {

/// NNCG's step after a sweep (Silcowitz, Niebe and Erleben 2010, alg. 2; contact_solver.cpp
/// states it). With r the sweep's change of the impulses and p the direction:
///   start   (the first sweep)              p = r
///   step    (|r_k+1|^2 <= |r_k|^2)         P += beta p, then p = beta p + r,
///                                          beta = |r_k+1|^2 / |r_k|^2
///   restart (the merit rose)               p = 0
/// `none`: no step is due (no NNCG, or the sweeps stop).
struct ConjugateStep {
  enum class Kind { none, start, step, restart } kind = Kind::none;
  double beta = 0.0;  ///< for `step`; 0 otherwise
};

/// One solve's sweep count against its SweepLimits, and NNCG's merit from sweep to sweep:
///   while (schedule.next()) {
///     ...one sweep: its largest change, largest impulse and |r|^2...
///     if (schedule.done(change, impulse, shortfall)) break;
///     if (accelerate && !schedule.last()) ...apply schedule.conjugate_step(size)...
///   }
class SweepSchedule {
 public:
  explicit SweepSchedule(const SweepLimits& limits) : limits_(limits), max_sweeps_(limits.iterations) {}

  /// Counts another sweep if the limits allow one.
  bool next() {
    if (sweep_ >= max_sweeps_) return false;
    ++sweep_;
    return true;
  }

  /// After a sweep: whether the sweeps stop. They stop once no impulse changed by more than
  /// `tolerance` times the largest; past `iterations`, every check_every sweeps (up to
  /// `extra_iterations` more), they stop unless some point still approaches faster than its
  /// target by more than `closing_speed` (`shortfall()`, called only then, says by how much),
  /// and otherwise go on for check_every sweeps more.
  template <class Shortfall>
  bool done(double largest_change, double largest_impulse, Shortfall&& shortfall) {
    if (largest_change <= limits_.tolerance * largest_impulse) return true;
    if (sweep_ < limits_.iterations || (sweep_ - limits_.iterations) % SweepLimits::check_every != 0 ||
        limits_.extra_iterations <= 0)
      return false;
    if (shortfall() <= limits_.closing_speed) return true;
    max_sweeps_ = std::min(limits_.iterations + limits_.extra_iterations, sweep_ + SweepLimits::check_every);
    return false;
  }

  /// Whether the sweep just made is the last the limits allow (no NNCG step follows it).
  bool last() const { return sweep_ == max_sweeps_; }
  /// The sweeps made so far.
  int sweeps() const { return sweep_; }

  /// The Fletcher-Reeves rule after a sweep whose change r has |r|^2 = `size`.
  ConjugateStep conjugate_step(double size) {
    ConjugateStep c;
    if (previous_size_ <= 0.0)
      c.kind = ConjugateStep::Kind::start;
    else if (size > previous_size_)
      c.kind = ConjugateStep::Kind::restart;
    else
      c = {ConjugateStep::Kind::step, size / previous_size_};
    previous_size_ = size;
    return c;
  }

 private:
  const SweepLimits& limits_;
  int max_sweeps_;
  int sweep_ = 0;
  double previous_size_ = 0.0;  // |r_k|^2; 0 before the first sweep
};

}  // namespace floedem
