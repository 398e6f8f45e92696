#pragma once
// HDF5 output of a run (layout in docs/output.md). Written as the run goes, under
// RESULT.h5.partial, in chunks fixed by the data (so the bytes do not depend on the run's
// speed), HDF5 flushed whenever a buffer is written, so that a killed run keeps what it wrote
// readable; renamed to RESULT.h5 by finish() only. Checkpoints (/checkpoint, two slots
// written in turn, each with its checksum) let `floedem run --resume` continue the run.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "contacts/collision_forces.hpp"
#include "floedem/engine/engine.hpp"
#include "floedem/io/output.hpp"
#include "io/output_lock.hpp"
#include "floedem/scene/scene.hpp"
#include "towing/tow.hpp"

namespace floedem {

struct RunInfo {
  std::vector<std::string> forcing_terms;
  std::string floedem_version;
};

/// Rows of each growing table: what a checkpoint records, and what a resumed run cuts the
/// file back to (rows written after the checkpoint are written again).
struct RecordedRows {
  std::int64_t frames = 0, contacts = 0, collisions = 0, tow = 0, loads = 0;
};

/// The checkpoint datasets: the two regular ones, written in turn, and the one a run stopped
/// on request (SIGTERM) writes at the step it stops after. That third one is dropped once a
/// regular checkpoint follows it and when the run ends, so a run stopped and continued ends
/// with the datasets of a run never stopped.
inline constexpr const char* kCheckpointSlots[3] = {"/checkpoint/slot_a", "/checkpoint/slot_b",
                                                    "/checkpoint/stopped"};

/// The checksum of a checkpoint slot: its bytes and its step (a slot whose step attribute
/// was written without its bytes, or the reverse, fails it).
std::uint64_t slot_checksum(std::int64_t step, const std::vector<std::uint8_t>& state);

class Recorder {
 public:
  Recorder(const std::string& path, const Scene& scene, const EngineInfo& engine, const RunInfo& run);
  /// Reopens `path`.partial (a run under way or killed; a finished run is renamed to it first)
  /// to continue the run: the tables are cut back to `rows`, the status is "running" again,
  /// the summary goes, and the run's attributes are rewritten for `scene` (its duration may
  /// be longer than the first run's).
  Recorder(const std::string& path, const Scene& scene, const RunInfo& run, const RecordedRows& rows);
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
  /// Closes and removes the .partial file: for bad input found before the first step was
  /// made, where there is nothing a run could continue.
  void discard();
  /// Writes what is buffered, marks the file complete, closes it and renames it to `path`.
  void finish(const std::vector<std::pair<std::string, double>>& summary);

  /// Writes every buffered row, then `state` into checkpoint slot `index` % 2 with its step
  /// and checksum, and flushes: the file then holds a whole checkpoint even if the process
  /// is killed while the next one is written (the other slot).
  void write_checkpoint(std::int64_t index, std::int64_t step, const std::vector<std::uint8_t>& state);
  /// Writes every buffered row, then `state` into the stopped run's slot (kCheckpointSlots[2]),
  /// and flushes; the regular slots are left as they are.
  void write_stop_checkpoint(std::int64_t step, const std::vector<std::uint8_t>& state);
  /// Rows so far, buffered included.
  RecordedRows rows() const;
  /// Frames per chunk of the frame tables (a checkpoint follows each full chunk).
  std::int64_t frame_chunk() const;

  const std::string& partial_path() const { return partial_path_; }
  std::int64_t frames() const;
  std::int64_t contact_rows() const;
  std::int64_t collision_rows() const;

 private:
  /// OutputError when the file system cannot hold the frames the scene will record.
  void check_space(const Scene& scene) const;
  /// InputError, before anything is changed, when a run's file to continue lacks a table of
  /// the scene's layout, or has one of another type or shape, or fewer rows than `rows`.
  /// Returns the file's format_version (a format 1 run is continued in format 1).
  std::int64_t check_tables(const std::string& file, const Scene& scene, const RecordedRows& rows) const;
  void write_run_attributes(const Scene& scene, const RunInfo& run);
  void write_slot(const char* name, std::int64_t step, const std::vector<std::uint8_t>& state);
  /// Removes the stopped run's checkpoint, if there is one.
  void drop_stop_checkpoint();
  struct Impl;
  std::unique_ptr<OutputLock> lock_;  // first: taken before the file is touched, given up last
  std::unique_ptr<Impl> impl_;
  std::string path_;
  std::string partial_path_;
};

}  // namespace floedem
