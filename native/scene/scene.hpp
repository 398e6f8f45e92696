#pragma once
// The engine-neutral description of a scene: what the scenario file says, checked, with
// each body's geometry and mass properties derived once. Every engine builds itself from
// this and nothing else; nothing here knows about any engine.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "geometry/vec2.hpp"

namespace floedem {

struct RunSettings {
  double duration = 0.0;        ///< s, model time to simulate (required, > 0)
  double dt = 0.0;              ///< s, time step (required, > 0)
  int output_every = 1;         ///< steps between recorded frames (>= 1)
  std::uint64_t seed = 1;       ///< random seed for anything stochastic in the scene
  /// Number of steps: duration / dt rounded to the nearest integer (at least 1).
  std::int64_t steps() const;
};

struct ContactSettings {
  double restitution = 0.1;          ///< Newton's coefficient e in [0, 1] (MODEL.md 3: 0.1 for ice)
  double friction = 0.3;             ///< Coulomb coefficient mu >= 0
  double collision_threshold = 1e-3; ///< m/s: approach speeds above this are collisions
};

enum class ContactOutput : std::uint8_t { all, collisions, none };

struct OutputSettings {
  ContactOutput contacts = ContactOutput::all;  ///< which contact impulses are recorded
};

/// One rigid body as the scenario gives it, plus what is derived from it.
struct BodySpec {
  std::string name;
  std::vector<Vec2> polygon;     ///< m, world coordinates at t = 0, counter-clockwise
  double thickness = 0.0;        ///< m
  double density = 900.0;        ///< kg/m^3
  Vec2 velocity;                 ///< m/s of the centroid at t = 0
  double angular_velocity = 0.0; ///< rad/s at t = 0
  bool fixed = false;            ///< fixed bodies never move (infinite mass)
  Vec2 applied_force;            ///< N, constant, at the centroid
  double applied_torque = 0.0;   ///< N m, constant
  bool reversed_input = false;   ///< the file gave the polygon clockwise; it was reversed

  // Derived at load time (Scene::derive): the same for every engine.
  Vec2 centroid;                               ///< m, world position at t = 0 (the reference point)
  double area = 0.0;                           ///< m^2
  double mass = 0.0;                           ///< kg, density * area * thickness
  double inertia = 0.0;                        ///< kg m^2, polar moment about the centroid
  std::vector<Vec2> local_polygon;             ///< relative to the centroid, angle 0
  std::vector<std::vector<Vec2>> local_parts;  ///< convex parts of local_polygon (one if convex)
};

struct Scene {
  std::string source_path;   ///< the scenario file, for messages
  std::string source_text;   ///< its text verbatim (stored in the output)
  std::vector<std::string> overrides;  ///< --set KEY=VALUE applied on top, in order

  RunSettings run;
  ContactSettings contact;
  OutputSettings output;
  std::vector<BodySpec> bodies;

  /// [engine.NAME] tables, kept as written: each engine reads and checks its own.
  std::map<std::string, toml::table> engine_settings;

  /// Fills each body's derived fields. Throws InputError for a degenerate polygon.
  void derive();
};

}  // namespace floedem
