#pragma once
// HDF5 output of a run (layout in README.md, "Output"). Written as the run goes, under
// RESULT.h5.partial, in chunks fixed by the data (so the bytes do not depend on the run's
// speed), with HDF5 flushed at least once a second of wall time so that a killed run keeps
// what it wrote readable; renamed to RESULT.h5 by finish() only.
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "contacts/collision_forces.hpp"
#include "engine/engine.hpp"
#include "scene/scene.hpp"
#include "towing/tow.hpp"

namespace floedem {

/// Output could not be written (unwritable directory, disk full, ...). Exit code 3.
class OutputError : public std::runtime_error {
 public:
  explicit OutputError(const std::string& m) : std::runtime_error(m) {}
};

struct RunInfo {
  std::vector<std::string> forcing_terms;
  std::string floedem_version;
};

class Recorder {
 public:
  Recorder(const std::string& path, const Scene& scene, const EngineInfo& engine, const RunInfo& run);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  void write_frame(double time, const BodyStates& state);
  /// Contact rows (all, collisions only, or none, as the scene's [output] says).
  void write_contacts(double time, std::span<const ContactRecord> contacts);
  /// Collision events that ended (/contacts/collisions).
  void write_collisions(std::span<const CollisionRow> rows);
  /// /tow at a frame: force of the last step, mean force since the last frame, tug position.
  void write_tow(double time, const TowFrame& frame);
  /// A row of /loads: the mean contact force on each body of [output] loads.
  void write_loads(double time, std::span<const Vec2> forces);
  /// Rewrites /engine's attributes (engines report measured figures, e.g. out-of-plane drift).
  void update_engine_info(const EngineInfo& engine);
  /// Polygons as `name_vertices` [V, 2] and `name_offsets` [P + 1] in a group (created when
  /// missing): the layout of /bodies/polygon_vertices and polygon_offsets.
  void write_polygons(const std::string& group, const std::string& name, const std::vector<std::vector<Vec2>>& polygons);
  /// Writes what is buffered, marks the file complete, closes it and renames it to `path`.
  void finish(const std::vector<std::pair<std::string, double>>& summary);

  const std::string& partial_path() const { return partial_path_; }
  std::int64_t frames() const;
  std::int64_t contact_rows() const;
  std::int64_t collision_rows() const;

 private:
  /// OutputError when the file system cannot hold the frames the scene will record.
  void check_space(const Scene& scene) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string path_;
  std::string partial_path_;
};

}  // namespace floedem
