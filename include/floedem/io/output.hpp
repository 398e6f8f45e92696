#pragma once
// Reading the files floedem writes (layout in docs/output.md): a run's output, a field file
// (the same /bodies layout with one frame), and a run's checkpoint. Every reader checks what it
// reads as the scenario loader checks a scenario: each dataset present, of its shape and type,
// offsets rising from 0 to the vertex count, values finite and within the ranges of the
// scenario keys they stand for. Anything else is an InputError of one line naming the file,
// the dataset and what was expected.
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "floedem/geometry/vec2.hpp"

namespace floedem {

/// Output could not be written (unwritable directory, disk full, ...). `floedem` exits 3.
class OutputError : public std::runtime_error {
 public:
  explicit OutputError(const std::string& m) : std::runtime_error(m) {}
};

/// The bodies of one recorded frame.
struct BodyFrame {
  std::vector<std::string> names;
  std::vector<std::vector<Vec2>> polygons;  ///< world coordinates at the frame, counter-clockwise
  std::vector<double> thickness;            ///< m
  std::vector<double> density;              ///< kg/m^3
  std::vector<std::uint8_t> fixed;
  std::vector<Vec2> velocity;               ///< m/s at the frame
  std::vector<double> angular_velocity;     ///< rad/s at the frame
  double time = 0.0;                        ///< s
  std::int64_t frame = 0;                   ///< the frame read (counted from 0)
};

/// One frame of a complete run's output or field file; frame < 0 counts from the end (-1: the
/// last). InputError for a file that is missing, not floedem's, of another format_version,
/// incomplete, damaged, or has no such frame.
BodyFrame read_body_frame(const std::string& path, std::int64_t frame = -1);

/// A checkpoint read back from a run's file: the newest of the two slots whose checksum holds.
struct StoredCheckpoint {
  std::int64_t step = 0;
  std::vector<std::uint8_t> state;
};

/// What `floedem run --resume` needs from a run's file (root attributes and checkpoint).
struct StoredRun {
  std::string status, engine, floedem_version, scenario, scenario_path;
  std::vector<std::string> overrides;
  double duration = 0.0;     ///< s, run.duration of the run as written
  std::vector<double> mass;  ///< /bodies/mass: the scene rebuilt must have the same bodies
  std::optional<StoredCheckpoint> checkpoint;
  int damaged_slots = 0;     ///< checkpoint slots with a wrong checksum (cut short by a kill)
  std::map<std::string, std::string> inputs;  ///< /inputs: scenario key -> InputFile::text()
};

/// Reads a run's file, complete or not (RESULT.h5.partial); InputError as read_body_frame's.
StoredRun read_stored_run(const std::string& path);

}  // namespace floedem
