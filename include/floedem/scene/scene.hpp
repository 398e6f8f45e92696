#pragma once
// The engine-neutral description of a scene: what the scenario file says, checked, with
// each body's geometry and mass properties derived once. Every engine builds itself from
// this and nothing else; nothing here knows about any engine.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "floedem/geometry/vec2.hpp"
#include "floedem/scene/geo.hpp"
#include "floedem/scene/met_ocean.hpp"

namespace floedem {

struct RunSettings {
  double duration = 0.0;        ///< s, model time to simulate (required, > 0)
  double dt = 0.0;              ///< s, time step (required, > 0)
  int output_every = 1;         ///< steps between recorded frames (>= 1)
  std::uint64_t seed = 1;       ///< random seed for anything stochastic in the scene
  std::string start;            ///< the instant t = 0 as given (ISO 8601, UTC), empty if not
  double start_unix = 0.0;      ///< ... in s since 1970-01-01T00:00:00Z (0 where not given)
  /// Number of steps: duration / dt rounded to the nearest integer (at least 1).
  std::int64_t steps() const;
};

struct ContactSettings {
  double restitution = 0.1;          ///< Newton's coefficient e in [0, 1] (docs/model.md 3: 0.1 for ice)
  double friction = 0.3;             ///< Coulomb coefficient mu >= 0
  double collision_threshold = 1e-3; ///< m/s: approach speeds above this are collisions
  /// C_tau, s kg^-1/2: a collision lasts tau = C_tau sqrt(m_eff) (docs/model.md 4). Default from the
  /// field figures of docs/model.md 4: a 1e10 kg multi-year floe stopped by Hans Island at 0.5 m/s
  /// (J = 5.5e9 N s with e = 0.1) peaks near 600 MN for tau = pi J / (2 F) = 14 s, C_tau =
  /// 1.4e-4; Weber's station floe (of order 1e10 kg, m_eff ~ 5e9) accelerated over 20-40 s,
  /// C_tau ~ 1.3e-4 to 5e-4. Equivalent linear contact stiffness k = (pi / C_tau)^2 = 4.4e8 N/m.
  double duration_coefficient = 1.5e-4;
  /// How a collision's duration and peak force are found from its impulse (docs/model.md 4):
  /// `linear` (the paper's: a half-sine of duration C_tau sqrt(m_eff)) or `pressure_area`
  /// (the same spring, its force capped by the ice's crushing pressure over the nominal contact
  /// area). Neither changes the impulses, so every motion is the same under both.
  enum class ForceModel : std::uint8_t { linear, pressure_area };
  ForceModel force_model = ForceModel::linear;
  /// pressure_area: the global crushing pressure of ISO 19906 (2010), A.8.2.4.3.3,
  ///   p = C_R (h / 1 m)^n (w / h)^m,   n = min(-0.3, 0.2 h / 1 m - 0.5)  (when not given),
  /// over the area w h (w: contact width, h: the thinner body's thickness). C_R: 2.5 MPa, the
  /// pressure Gagnon et al. (2008) measured in the pulverised ice that carried the load of bergy
  /// bits struck by CCGS Terry Fox; m = -0.16 (ISO 19906's width exponent).
  double crushing_coefficient = 2.5e6;     ///< C_R, Pa
  double crushing_width_exponent = -0.16;  ///< m
  double crushing_thickness_exponent = 0.0;///< n when given (has_crushing_thickness_exponent)
  bool has_crushing_thickness_exponent = false;
};

enum class ContactOutput : std::uint8_t { all, collisions, none };

struct OutputSettings {
  ContactOutput contacts = ContactOutput::all;  ///< which contact impulses are recorded
  int tow_every = 0;  ///< steps between rows of /tow (0: run.output_every, with the frames)
  std::vector<std::size_t> load_bodies;  ///< bodies whose contact load goes to /loads
  int load_every = 0;  ///< steps between rows of /loads (0: run.output_every)
};

/// Drag and radiation coefficients (docs/model.md section 2; Bigg et al. 1997 for icebergs).
struct DragCoefficients {
  double water_form = 0.9;      ///< C_w, keel form drag
  double water_skin = 5e-4;     ///< C_dw, bottom skin drag
  double air_form = 1.3;        ///< C_a, sail form drag
  double air_skin = 2.5e-4;     ///< C_da, top skin drag
  double wave_radiation = 0.3;  ///< C_r
};

enum class BodyKind : std::uint8_t { floe = 0, iceberg = 1 };

/// A depth slab of a body below the waterline, with the current it sits in.
struct KeelLayer {
  double top = 0.0;          ///< m below the waterline
  double bottom = 0.0;       ///< m below the waterline
  double width_scale = 1.0;  ///< the waterline polygon scaled about the centroid by this
};

/// One rigid body as the scenario gives it, plus what is derived from it.
struct BodySpec {
  std::string name;
  BodyKind kind = BodyKind::floe;
  std::vector<Vec2> polygon;     ///< m, world coordinates at t = 0, counter-clockwise
  double thickness = 0.0;        ///< m
  double density = 900.0;        ///< kg/m^3
  Vec2 velocity;                 ///< m/s of the centroid at t = 0
  double angular_velocity = 0.0; ///< rad/s at t = 0
  bool fixed = false;            ///< fixed bodies never move (infinite mass)
  Vec2 applied_force;            ///< N, constant, at the centroid
  double applied_torque = 0.0;   ///< N m, constant
  bool reversed_input = false;   ///< the file gave the polygon clockwise; it was reversed
  // Iceberg geometry (floes: draft = h rho_i / rho_w, freeboard = h - draft, one keel layer).
  double draft = 0.0;            ///< m below the waterline (derived for floes)
  double freeboard = 0.0;        ///< m above it: the sail height of an iceberg (derived for floes)
  std::vector<KeelLayer> keel;   ///< slabs from 0 to draft
  double given_mass = 0.0;       ///< kg, iceberg mass when the file gives it (0: computed)
  double shape_factor = 1.0;     ///< iceberg mass = rho_i A (draft + sail) shape_factor
  double added_mass_coefficient = 0.0;  ///< C_m: added mass m_a = C_m m (also on the moment)
  DragCoefficients drag;         ///< in force for this body (kind defaults, then the body's own)
  bool prescribed = false;       ///< moved on a prescribed velocity (towing, mode "velocity")

  // Derived at load time (Scene::derive): the same for every engine.
  Vec2 centroid;                               ///< m, world position at t = 0 (the reference point)
  double area = 0.0;                           ///< m^2
  double mass = 0.0;                           ///< kg, density * area * thickness (floe)
  double inertia = 0.0;                        ///< kg m^2, polar moment about the centroid
  std::vector<Vec2> local_polygon;             ///< relative to the centroid, angle 0
  std::vector<std::vector<Vec2>> local_parts;  ///< convex parts of local_polygon (one if convex)
};

/// A layer of the current: from `depth` (m below the surface) down to the next layer's depth.
struct CurrentLayer {
  double depth = 0.0;
  Vec2 velocity;
};

struct WaveSpec {
  bool present = false;
  double amplitude = 0.0;   ///< m
  double period = 0.0;      ///< s (0: not given)
  double wavelength = 0.0;  ///< m (deep-water L = g T^2 / (2 pi) when only the period is given)
  double direction = 0.0;   ///< rad, direction the waves travel to, counter-clockwise from +x
};

/// A file a scenario reads, as it was when read.
struct InputFile {
  std::string key;           ///< the scenario key naming it ("environment.current_file.file")
  std::string path;          ///< as opened (a relative path joined to the scenario's folder)
  std::uint64_t bytes = 0;
  std::uint64_t digest = 0;  ///< FNV-1a, 64 bits, of its bytes (engine/state_io.hpp)
  /// "fnv1a64 0123456789abcdef, 1234 bytes, PATH": the output's record of it.
  std::string text() const;
};

/// [environment]: the water, the air and the earth the bodies move in.
struct EnvironmentSpec {
  Vec2 current;                             ///< m/s, uniform (used when there is no profile)
  std::vector<CurrentLayer> current_profile;///< by depth, first layer at depth 0
  Vec2 wind;                                ///< m/s, at sail height
  bool coriolis = false;                    ///< a latitude was given, or the scene is geographic
  double latitude = 0.0;                    ///< rad (a geographic scene: its origin's)
  double coriolis_parameter = 0.0;          ///< f = 2 Omega sin(latitude), 1/s (at the origin
                                            ///< of a geographic scene, where each body has its own)
  bool sea_surface_tilt = false;            ///< m f k x V_w (geostrophic current)
  WaveSpec waves;
  double water_density = 1025.0;            ///< kg/m^3
  double air_density = 1.25;                ///< kg/m^3
  double gravity = 9.81;                    ///< m/s^2
  bool rotational_damping = true;           ///< drag integrated over the polygon (gives torque)
  double drag_reference_speed = 0.0;        ///< m/s; > 0: drag linearised, |u| replaced by this
  bool added_mass_in_contacts = false;      ///< true: contacts see m + m_a too
  bool water_drag = false, air_drag = false;///< which drag terms any body needs
  // Forcing that changes in time (met_ocean.hpp, docs/forcing.md). A current series takes the
  // place of `current` (which is then zero); the tides add to the current at every depth (a
  // tidal current is barotropic: the same from surface to keel); a wind series takes the place
  // of `wind`.
  std::vector<TidalConstituent> tides;
  VelocitySeries current_series, wind_series;
  /// A current or wind on a grid (a CF-NetCDF file): it takes the place of the steady current
  /// (or wind) at each point of each body; the tides add to it.
  FlowGridSpec current_grid, wind_grid;

  /// The current at a depth (m below the surface), without what changes in time.
  Vec2 current_at(double depth) const;
  /// Whether the current or the wind changes in time.
  bool current_varies() const { return !tides.empty() || !current_series.empty() || !current_grid.empty(); }
  bool wind_varies() const { return !wind_series.empty() || !wind_grid.empty(); }
  /// What the current at time t (s) adds to current_at(depth) at every depth and every point:
  /// the tides and the current series (not a grid's field); and its rate of change.
  Vec2 current_change(double t) const;
  Vec2 current_change_rate(double t) const;
  /// What the wind at time t adds to `wind`: the wind series.
  Vec2 wind_change(double t) const { return wind_series.empty() ? Vec2{} : wind_series.at(t); }
};

/// [tow]: an iceberg moved on a prescribed velocity, pulled by a rope from a tug on a given
/// path, or pulled by a tug that has only so much pull (docs/towing.md).
struct TowSpec {
  enum class Mode : std::uint8_t { none, velocity, rope, tug };
  Mode mode = Mode::none;
  std::size_t body = 0;
  /// Piecewise-linear velocity against time [(t, v)], held after the last point. The towed
  /// body's (mode velocity), the tug's (mode rope) or, mode tug, the tug's heading (a
  /// direction: the interpolated vector's direction, heading_at).
  std::vector<std::pair<double, Vec2>> path;
  double stiffness = 0.0;          ///< N/m (rope, tug)
  double length = 0.0;             ///< m, unstretched (rope, tug)
  double damping = 0.0;            ///< N s/m (rope, tug)
  Vec2 attachment;                 ///< m, in the body's frame from its centroid (rope, tug)
  Vec2 tug_start;                  ///< m, world (rope, tug)
  /// N: the rope parts at the start of the first step whose tension exceeds it (rope, tug;
  /// 0: it never parts).
  double breaking_load = 0.0;
  // Mode tug: the pull available at speed V through the water along the heading is
  // bollard_pull (1 - V / free_running_speed), bollard_pull itself at V <= 0.
  double bollard_pull = 0.0;       ///< N
  double free_running_speed = 0.0; ///< m/s
  double tug_mass = 0.0;           ///< kg
  double pull_ramp = 0.0;          ///< s: the pull rises in proportion to t over this time (0: at once)
  /// m/s: the towing outcome counts the time the towed body makes less than this along the
  /// tow's direction as stalled.
  double stall_speed = 0.1;
  Vec2 velocity_at(double t) const;
  Vec2 acceleration_at(double t) const;
  Vec2 displacement(double t0, double t1) const;  ///< integral of the path velocity
  /// Mode tug: the unit heading at time t.
  Vec2 heading_at(double t) const;
  /// The direction the tow is meant to go, for its outcome: the first nonzero vector of the
  /// path (the towed body's or the tug's velocity, or the tug's heading); +x when none is.
  Vec2 direction() const;
  bool has_rope() const { return mode == Mode::rope || mode == Mode::tug; }
  /// The mode as the scenario and /tow's attribute `mode` spell it.
  const char* mode_name() const {
    return mode == Mode::velocity ? "velocity" : mode == Mode::rope ? "rope" : mode == Mode::tug ? "tug" : "none";
  }
};

/// Where part of a scene came from, for the output: attributes of one group (a generated
/// field's parameters and what it achieved, /field). The recorder writes them as they are.
struct Provenance {
  std::string group;
  std::vector<std::pair<std::string, std::string>> text;
  std::vector<std::pair<std::string, double>> numbers;
};

struct Scene {
  std::string source_path;   ///< the scenario file, for messages
  std::string source_text;   ///< its text verbatim (stored in the output)
  std::vector<std::string> overrides;  ///< --set KEY=VALUE applied on top, in order

  RunSettings run;
  GeoSpec geo;  ///< [geo]: where the plane lies on the earth (geo.present), docs/geography.md
  ContactSettings contact;
  OutputSettings output;
  std::vector<BodySpec> bodies;
  bool has_environment = false;
  EnvironmentSpec environment;
  TowSpec tow;
  std::vector<Provenance> provenance;
  /// The files the scenario reads (forcing files, a field, a chart), each with its digest: the
  /// output records them, and `floedem run --resume` refuses a file that has changed.
  std::vector<InputFile> input_files;

  /// [engine.NAME] tables, kept as written: each engine reads and checks its own.
  std::map<std::string, toml::table> engine_settings;

  /// Fills each body's derived fields. Throws InputError for a degenerate polygon.
  void derive();
  /// Mass the engines move: m, plus the added mass when it enters contacts too.
  double engine_mass(std::size_t body) const;
  double engine_inertia(std::size_t body) const;
  /// Steps between rows of /tow and of /loads: the [output] setting, or with the frames.
  int tow_every() const { return output.tow_every > 0 ? output.tow_every : run.output_every; }
  int load_every() const { return output.load_every > 0 ? output.load_every : run.output_every; }
  /// 1 / engine_mass and 1 / engine_inertia, 0 for a fixed or prescribed body (infinite mass
  /// in contacts).
  double engine_inverse_mass(std::size_t body) const;
  double engine_inverse_inertia(std::size_t body) const;
};

}  // namespace floedem
