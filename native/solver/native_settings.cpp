#include "solver/native_settings.hpp"

#include <limits>

#include "scenario/table_reader.hpp"

namespace floedem {

NativeSettings read_native_settings(const Scene& scene) {
  NativeSettings s;
  const auto it = scene.engine_settings.find("native");
  if (it == scene.engine_settings.end()) return s;
  TableReader r(it->second, scene.source_path, "engine.native");
  s.velocity_iterations = static_cast<int>(r.integer("velocity_iterations", s.velocity_iterations, 1, 1'000'000));
  s.extra_iterations = static_cast<int>(r.integer("extra_iterations", s.extra_iterations, 0, 1'000'000));
  s.tolerance = r.real("tolerance", s.tolerance, Range{0.0, 1.0, false, true});
  s.warm_start = r.boolean("warm_start", s.warm_start);
  s.accelerate = r.boolean("accelerate", s.accelerate);
  s.coloured_from = r.integer("coloured_from", s.coloured_from, 0, std::numeric_limits<std::int64_t>::max());
  if (r.has("coloured_sweeps"))  // the shorthand: every island (true) or none (false)
    s.coloured_from = r.boolean("coloured_sweeps", false) ? 0 : std::numeric_limits<std::int64_t>::max();
  s.large_island_manifolds =
      r.integer("large_island_manifolds", s.large_island_manifolds, 0, std::numeric_limits<std::int64_t>::max());
  s.large_island_iterations = static_cast<int>(r.integer("large_island_iterations", s.large_island_iterations, 1, 1'000'000));
  s.position_iterations = static_cast<int>(r.integer("position_iterations", s.position_iterations, 0, 1000));
  s.position_correction = r.real("position_correction", s.position_correction, Range{0.0, 1.0, true, false});
  s.allowed_penetration = r.real("allowed_penetration", s.allowed_penetration, Range::non_negative());
  s.max_correction = r.real("max_correction", s.max_correction, Range::positive());
  s.redetect = r.boolean("redetect", s.redetect);
  s.direct_solve = r.boolean("direct_solve", s.direct_solve);
  s.direct_solve_mass_ratio = r.real("direct_solve_mass_ratio", s.direct_solve_mass_ratio, Range{1.0, std::numeric_limits<double>::infinity(), false, true});
  s.sleep = r.boolean("sleep", s.sleep);
  s.sleep_speed = r.real("sleep_speed", s.sleep_speed, Range::positive());
  s.sleep_time = r.real("sleep_time", s.sleep_time, Range::positive());
  r.reject_unknown();
  return s;
}

}  // namespace floedem
