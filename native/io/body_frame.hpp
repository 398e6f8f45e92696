#pragma once
// Reads the bodies of one recorded frame from a floedem HDF5 file: a run's output or a field
// file (which is the same /bodies layout with one frame). One reader serves both.
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/vec2.hpp"

namespace floedem {

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

/// frame < 0 counts from the end (-1: the last). Throws InputError naming the file and what is
/// missing or wrong (not a floedem file, incomplete, frame out of range).
BodyFrame read_body_frame(const std::string& path, std::int64_t frame = -1);

}  // namespace floedem
