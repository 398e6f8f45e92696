#pragma once
#include <cstdint>

#include "floedem/scene/scene.hpp"

namespace floedem {

/// [engine.native] settings; defaults and reasons in scenarios/README.md.
struct NativeSettings {
  int velocity_iterations = 50;      ///< most Gauss-Seidel sweeps per step, unless ...
  int extra_iterations = 450;        ///< ... a point is left closing by more than allowed_penetration in the step: up to this many more
  double tolerance = 1e-10;          ///< stop sweeping when max |dP| <= tolerance * max |P|
  bool warm_start = true;            ///< start from last step's resting impulses
  bool accelerate = true;            ///< conjugate-gradient step after each sweep (NNCG)
  /// Islands of at least this many manifolds are swept colour by colour (graph colouring, four
  /// at a time, their colours on every thread), smaller ones in pair order: measured on the
  /// report's scenes (docs/architecture.md). `coloured_sweeps = true` in a scene sets it to 0
  /// (every island), `false` to never.
  std::int64_t coloured_from = 1024;
  /// An island of at least `large_island_manifolds` manifolds (a packed pack) is swept at most
  /// `large_island_iterations` times (and the extra sweeps), smaller ones velocity_iterations:
  /// a pack needs its overlap held, not its impulses converged; a few bodies' impacts and
  /// pressed chains need them converged (scenarios/README.md).
  std::int64_t large_island_manifolds = 1024;
  int large_island_iterations = 3;
  int position_iterations = 10;      ///< most position-projection sweeps per step (0: none); they stop once the deepest overlap is within 1.5 allowed_penetration
  double position_correction = 0.2;  ///< fraction of the overlap removed per sweep
  double allowed_penetration = 1e-3; ///< m, overlap left alone (keeps contacts persistent)
  double max_correction = 0.2;       ///< m, largest push of one sweep at one point
  bool redetect = true;              ///< find the step's contacts again when impulses send a body beyond its reach
  bool direct_solve = true;          ///< heavy-light islands Gauss-Seidel cannot hold get their normals solved directly
  double direct_solve_mass_ratio = 300.0;  ///< ... islands whose heaviest body is at least this times their lightest
  /// Islands at rest sleep (no loads, solve or motion; their contacts held) until touched or
  /// their loads change: the rule and its tolerances in docs/model.md. false: every body
  /// is stepped every step (bit-for-bit studies against an older run or another engine).
  bool sleep = true;
  double sleep_speed = 1e-5;         ///< m/s, fastest point of a body that counts as at rest
  double sleep_time = 60.0;          ///< s, how long every body of an island must be at rest before it sleeps
};

/// Reads [engine.native] from the scene (defaults for what is absent); InputError if bad.
NativeSettings read_native_settings(const Scene& scene);

}  // namespace floedem
