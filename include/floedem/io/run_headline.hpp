#pragma once
// The figures a run's summary leads with, read back from its finished output file: what an
// engineer asks of the run first. Read from the file rather than tallied during the run, so
// that a run continued with --resume (whose earlier rows are only in the file) gives the same
// figures as one never interrupted.
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "floedem/geometry/vec2.hpp"

namespace floedem {

/// A tow's outcome over its run (docs/towing.md): what a planner judges a tow by. The run
/// writes it with its summary (the root attributes summary_tow_*, docs/output.md).
struct TowOutcome {
  Vec2 direction;               ///< unit: the direction the tow is meant to go ([tow] path's first)
  double distance = 0.0;        ///< m, the towed body's displacement along `direction`
  double cross_track = 0.0;     ///< m, across it (positive to its left)
  double speed_made_good = 0.0; ///< m/s, distance over the run's time
  double stall_speed = 0.0;     ///< m/s, [tow] stall_speed
  double stalled_time = 0.0;    ///< s, the steps that ended with the body slower than stall_speed along `direction`
  bool parted = false;          ///< the rope parted (modes rope and tug)
  double parted_at = 0.0;       ///< s, the start of the step it parted in (NaN when it held)
  double tension_max = 0.0;     ///< N, the rope's largest tension while whole (rope, tug; 0 otherwise)
  double tension_p99 = 0.0;     ///< N, its 99th percentile over the steps while whole, within 0.6 %
  /// As the summary's attributes, without their "summary_" prefix.
  std::vector<std::pair<std::string, double>> attributes() const;
};

struct RunHeadline {
  /// s: the tow and load means are over the rows from here to the end (the second half of
  /// the run, where a towing or a pressed pack has settled: the rows whose interval starts at
  /// or after half the run's time).
  double window_start = 0.0;
  double window_end = 0.0;
  struct Tow {
    std::string body;
    Vec2 force;      ///< N, mean towing force
    Vec2 ice_force;  ///< N, its ice part (minus the contact force on the towed body)
  };
  std::optional<Tow> tow;
  std::optional<TowOutcome> tow_outcome;  ///< from the summary (a file written before it has none)
  struct Load {
    std::string body;
    Vec2 force;  ///< N, mean contact force on the body
  };
  std::vector<Load> loads;  ///< the bodies of [output] loads
  struct Collision {
    double peak_force = 0.0;  ///< N
    double time = 0.0;        ///< s, end of the impact step
    std::string body_a, body_b;
  };
  std::optional<Collision> largest_collision;  ///< the collision event of the largest peak force
};

/// Reads the headline figures of a complete run's output. Throws InputError naming the file.
RunHeadline read_run_headline(const std::string& path);

/// The headline as summary lines (empty when the run has none of them).
std::string format_run_headline(const RunHeadline& h);

}  // namespace floedem
