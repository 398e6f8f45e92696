#include "floedem/scenario/scenario.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <cmath>

#include "floedem/field/field_file.hpp"
#include "floedem/field/field_generator.hpp"
#include "floedem/field/ice_chart.hpp"
#include "geometry/polygon.hpp"
#include "floedem/io/output.hpp"
#include "floedem/scene/geo.hpp"
#include "scenario/input_file.hpp"
#include "scenario/met_ocean_input.hpp"
#include "scenario/table_reader.hpp"
#include "floedem/scene/input_error.hpp"
#include "collision/overlap.hpp"

namespace floedem {

namespace {

// ---- --set KEY=VALUE ---------------------------------------------------------------------

struct PathStep {
  std::string key;
  std::optional<std::size_t> index;
};

std::vector<PathStep> split_key(const std::string& key, const std::string& what) {
  std::vector<PathStep> steps;
  std::size_t i = 0;
  while (i < key.size()) {
    std::size_t j = i;
    while (j < key.size() && key[j] != '.' && key[j] != '[') ++j;
    PathStep s{key.substr(i, j - i), std::nullopt};
    if (s.key.empty()) throw InputError("--set " + what + ": empty name in key '" + key + "'");
    if (j < key.size() && key[j] == '[') {
      const std::size_t close = key.find(']', j);
      if (close == std::string::npos) throw InputError("--set " + what + ": missing ']' in key '" + key + "'");
      const std::string digits = key.substr(j + 1, close - j - 1);
      if (digits.empty() || !std::all_of(digits.begin(), digits.end(), ::isdigit))
        throw InputError("--set " + what + ": index '" + digits + "' is not a whole number");
      s.index = std::stoul(digits);
      j = close + 1;
    }
    steps.push_back(s);
    if (j < key.size() && key[j] != '.') throw InputError("--set " + what + ": expected '.' after ']' in '" + key + "'");
    i = j + 1;
  }
  if (steps.empty()) throw InputError("--set " + what + ": empty key");
  return steps;
}

void apply_override(toml::table& root, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos)
    throw InputError("--set " + assignment + ": expected KEY=VALUE, e.g. run.duration=60");
  const std::string key = assignment.substr(0, eq);
  const std::string value_text = assignment.substr(eq + 1);
  const auto steps = split_key(key, assignment);

  // The value: any TOML value; a bare word that is not one is taken as a string.
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value_text);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"v", value_text}};
  }
  const toml::node& value = *parsed.get("v");
  if (value.is_table() || (value.is_array() && value.as_array()->is_array_of_tables()))
    throw InputError("--set " + assignment + ": only scalars and small arrays can be set");

  toml::table* t = &root;
  for (std::size_t k = 0; k + 1 < steps.size(); ++k) {
    const PathStep& s = steps[k];
    toml::node* n = t->get(s.key);
    if (!n) {
      if (s.index) throw InputError("--set " + assignment + ": '" + s.key + "' is not in the scenario");
      t->insert(s.key, toml::table{});
      n = t->get(s.key);
    }
    if (s.index) {
      toml::array* a = n->as_array();
      if (!a || *s.index >= a->size() || !a->get(*s.index)->is_table())
        throw InputError("--set " + assignment + ": '" + s.key + "[" + std::to_string(*s.index) +
                         "]' is not in the scenario");
      t = a->get(*s.index)->as_table();
    } else {
      if (!n->is_table()) throw InputError("--set " + assignment + ": '" + s.key + "' is not a table");
      t = n->as_table();
    }
  }
  const PathStep& last = steps.back();
  if (last.index) throw InputError("--set " + assignment + ": the last part of the key cannot be indexed");
  if (const toml::node* old = t->get(last.key); old && (old->is_table() || old->is_array_of_tables()))
    throw InputError("--set " + assignment + ": '" + last.key + "' is a table, not a scalar");
  t->insert_or_assign(last.key, value);
}

// ---- sections ------------------------------------------------------------------------------

void read_run(TableReader& root, Scene& scene) {
  const toml::table* t = root.table("run");
  if (!t) root.fail("run", "missing (required): a [run] table with duration and dt");
  TableReader r(*t, scene.source_path, "run");
  scene.run.duration = r.real("duration", std::nullopt, Range::positive());
  scene.run.dt = r.real("dt", std::nullopt, Range::positive());
  if (scene.run.dt > scene.run.duration)
    r.fail("dt", "must not exceed run.duration; allowed (0, " + std::to_string(scene.run.duration) + "]");
  scene.run.output_every = static_cast<int>(r.integer("output_every", 1, 1, 1'000'000'000));
  scene.run.seed = static_cast<std::uint64_t>(r.integer("seed", 1, 0, std::numeric_limits<std::int64_t>::max()));
  if (r.has("start")) {
    scene.run.start_unix = read_utc_instant(r, "start");
    scene.run.start = r.string("start", std::nullopt);
  }
  r.reject_unknown();
}

/// [geo]: the scene's origin on the earth and its projection (floedem/scene/geo.hpp). Returns
/// the projection, or null for a scene in plain metres.
std::unique_ptr<GeoProjection> read_geo(TableReader& root, Scene& scene) {
  const toml::table* t = root.table("geo");
  if (!t) return nullptr;
  TableReader r(*t, scene.source_path, "geo");
  const Vec2 origin = r.vec2("origin", std::nullopt);
  if (!(origin.x >= -180.0 && origin.x <= 180.0))
    r.fail("origin", "longitude " + std::to_string(origin.x) + " deg; allowed [-180, 180]");
  if (!(origin.y > -90.0 && origin.y < 90.0))
    r.fail("origin", "latitude " + std::to_string(origin.y) + " deg; allowed (-90, 90)");
  GeoSpec& geo = scene.geo;
  geo.present = true;
  geo.origin_lon = origin.x;
  geo.origin_lat = origin.y;
  geo.projection_given = r.string("projection", "");
  geo.projection = geo.projection_given.empty() ? GeoSpec::default_projection(origin.x, origin.y) : geo.projection_given;
  std::unique_ptr<GeoProjection> projection;
  try {
    projection = std::make_unique<GeoProjection>(geo);
  } catch (const InputError& e) {
    r.fail(geo.projection_given.empty() ? "origin" : "projection", e.what());
  }
  r.reject_unknown();
  return projection;
}

/// A point or polygon given in longitude and latitude (degrees), on the scene's plane.
Vec2 lonlat_point(TableReader& r, std::string_view key, Vec2 p, const GeoProjection* geo, const std::string& which) {
  if (!(p.x >= -180.0 && p.x <= 360.0 && p.y >= -90.0 && p.y <= 90.0))
    r.fail(key, which + "(" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                    ") is not a longitude and latitude; allowed [-180, 360] and [-90, 90] deg");
  try {
    return geo->to_plane({p.x, p.y});
  } catch (const InputError& e) {
    r.fail(key, which + e.what());
  }
}

void need_geo(TableReader& r, std::string_view key, const GeoProjection* geo) {
  if (!geo) r.fail(key, "needs a [geo] table (the scene's origin on the earth) to place longitudes and latitudes");
}

/// `key` in metres, or `key`_lonlat in degrees of a geographic scene, one of them.
std::vector<Vec2> read_polygon(TableReader& r, const std::string& key, const GeoProjection* geo) {
  const std::string geo_key = key + "_lonlat";
  if (!r.has(geo_key)) return r.points(key);
  need_geo(r, geo_key, geo);
  if (r.has(key)) r.fail(geo_key, "give " + key + " (m) or " + geo_key + " (deg), not both");
  std::vector<Vec2> out = r.points(geo_key);
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = lonlat_point(r, geo_key, out[k], geo, "vertex " + std::to_string(k) + " ");
  return out;
}

/// A position in metres (`key`, or `fallback` where neither is given) or in degrees.
Vec2 read_position(TableReader& r, const std::string& key, Vec2 fallback, const GeoProjection* geo) {
  const std::string geo_key = key + "_lonlat";
  if (!r.has(geo_key)) return r.vec2(key, fallback);
  need_geo(r, geo_key, geo);
  if (r.has(key)) r.fail(geo_key, "give " + key + " (m) or " + geo_key + " (deg), not both");
  return lonlat_point(r, geo_key, r.vec2(geo_key, std::nullopt), geo, "");
}

void read_contact(TableReader& root, Scene& scene) {
  const toml::table* t = root.table("contact");
  if (!t) return;
  TableReader r(*t, scene.source_path, "contact");
  scene.contact.restitution = r.real("restitution", scene.contact.restitution, Range::closed(0.0, 1.0));
  scene.contact.friction = r.real("friction", scene.contact.friction, Range::non_negative());
  scene.contact.collision_threshold =
      r.real("collision_threshold", scene.contact.collision_threshold, Range::non_negative());
  // The collision duration: C_tau directly, or a linear contact stiffness k (C_tau = pi / sqrt(k)).
  if (r.has("duration_coefficient") && r.has("stiffness"))
    r.fail("stiffness", "give duration_coefficient or stiffness, not both (C_tau = pi / sqrt(k))");
  scene.contact.duration_coefficient =
      r.real("duration_coefficient", scene.contact.duration_coefficient, Range::positive());
  if (r.has("stiffness"))
    scene.contact.duration_coefficient = M_PI / std::sqrt(r.real("stiffness", std::nullopt, Range::positive()));
  // The collision force model (docs/model.md 4) and the crushing law's constants, which only
  // the pressure-area model reads: given beside the linear model they would do nothing.
  const bool crushing = r.string("force_model", "linear", {"linear", "pressure_area"}) == "pressure_area";
  scene.contact.force_model = crushing ? ContactSettings::ForceModel::pressure_area : ContactSettings::ForceModel::linear;
  for (const char* key : {"crushing_coefficient", "crushing_width_exponent", "crushing_thickness_exponent"})
    if (!crushing && r.has(key)) r.fail(key, "only read with force_model = \"pressure_area\"");
  // C_R from 0.1 to 50 MPa: from soft, warm sub-Arctic ice to the 25-50 MPa peaks Gagnon and
  // Gammon (1997) measured on iceberg ice in the laboratory.
  scene.contact.crushing_coefficient =
      r.real("crushing_coefficient", scene.contact.crushing_coefficient, Range::closed(1e5, 5e7));
  // Exponents in (-1, 0]: pressure that falls with area, but a force that still grows with it.
  scene.contact.crushing_width_exponent =
      r.real("crushing_width_exponent", scene.contact.crushing_width_exponent, Range::closed(-0.95, 0.0));
  if (r.has("crushing_thickness_exponent")) {
    scene.contact.crushing_thickness_exponent =
        r.real("crushing_thickness_exponent", std::nullopt, Range::closed(-0.95, 0.0));
    scene.contact.has_crushing_thickness_exponent = true;
  }
  r.reject_unknown();
}

void read_output(TableReader& root, Scene& scene) {
  const toml::table* t = root.table("output");
  if (!t) return;
  TableReader r(*t, scene.source_path, "output");
  const std::string c = r.string("contacts", "all", {"all", "collisions", "none"});
  scene.output.contacts = c == "all" ? ContactOutput::all : c == "collisions" ? ContactOutput::collisions
                                                                             : ContactOutput::none;
  scene.output.tow_every = static_cast<int>(r.integer("tow_every", 0, 1, 1'000'000'000));
  for (const std::string& name : r.strings("loads")) {
    std::size_t i = 0;
    while (i < scene.bodies.size() && scene.bodies[i].name != name) ++i;
    if (i == scene.bodies.size()) r.fail("loads", "no body is named \"" + name + "\"; allowed the names of bodies");
    scene.output.load_bodies.push_back(i);
  }
  scene.output.load_every = static_cast<int>(r.integer("load_every", 0, 1, 1'000'000'000));
  r.reject_unknown();
}

void check_polygon(TableReader& r, BodySpec& b) {
  if (const auto problem = polygon_problem(b.polygon)) r.fail(r.has("polygon_lonlat") ? "polygon_lonlat" : "polygon", *problem);
  const double a = signed_area(b.polygon);
  if (a < 0.0) {
    std::reverse(b.polygon.begin(), b.polygon.end());
    b.reversed_input = true;
  }
}

void read_drag(TableReader& r, DragCoefficients& d) {
  d.water_form = r.real("water_form", d.water_form, Range::non_negative());
  d.water_skin = r.real("water_skin", d.water_skin, Range::non_negative());
  d.air_form = r.real("air_form", d.air_form, Range::non_negative());
  d.air_skin = r.real("air_skin", d.air_skin, Range::non_negative());
  d.wave_radiation = r.real("wave_radiation", d.wave_radiation, Range::non_negative());
}

struct EnvironmentDefaults {
  double ice_density = 900.0;
  DragCoefficients floe, iceberg;
};

EnvironmentDefaults read_environment(TableReader& root, Scene& scene) {
  EnvironmentDefaults defaults;
  const toml::table* t = root.table("environment");
  if (!t) return defaults;
  scene.has_environment = true;
  EnvironmentSpec& env = scene.environment;
  TableReader r(*t, scene.source_path, "environment");
  if (r.has("current_profile") && r.has("current")) r.fail("current_profile", "give current or current_profile, not both");
  env.current = r.vec2("current", Vec2{});
  if (r.has("current_profile")) {
    const auto rows = r.rows("current_profile", 3);
    for (std::size_t k = 0; k < rows.size(); ++k) {
      if (k == 0 && rows[k][0] != 0.0) r.fail("current_profile", "the first layer must start at depth 0; allowed [[0, u, v], ...]");
      if (k > 0 && !(rows[k][0] > rows[k - 1][0]))
        r.fail("current_profile", "depths must increase (row " + std::to_string(k) + ")");
      env.current_profile.push_back({rows[k][0], {rows[k][1], rows[k][2]}});
    }
    env.current = env.current_profile.front().velocity;
  }
  env.wind = r.vec2("wind", Vec2{});
  if (r.has("current_file") && (r.has("current") || r.has("current_profile")))
    r.fail("current_file", "give current, current_profile or current_file, one of them");
  if (r.has("wind_file") && r.has("wind")) r.fail("wind_file", "give wind or wind_file, not both");
  read_velocity_file(r, "current_file", scene, env.current_series, env.current_grid);
  read_velocity_file(r, "wind_file", scene, env.wind_series, env.wind_grid);
  read_tides(r, scene);
  env.water_density = r.real("water_density", env.water_density, Range::positive());
  env.air_density = r.real("air_density", env.air_density, Range::non_negative());
  env.gravity = r.real("gravity", env.gravity, Range::non_negative());
  defaults.ice_density = r.real("ice_density", defaults.ice_density, Range::positive());
  if (scene.geo.present) {  // f follows each body's latitude (forcing/coriolis_field.hpp)
    if (r.has("latitude"))
      r.fail("latitude", "a geographic scene takes each body's latitude from [geo]; remove environment.latitude");
    env.coriolis = true;
    env.latitude = scene.geo.origin_lat * M_PI / 180.0;
    env.coriolis_parameter = coriolis_parameter(scene.geo.origin_lat);
  } else if (r.has("latitude")) {
    const double degrees = r.real("latitude", 0.0, Range::closed(-90.0, 90.0));
    env.coriolis = true;
    env.latitude = degrees * M_PI / 180.0;
    env.coriolis_parameter = coriolis_parameter(degrees);
  }
  const bool current_flows = env.current != Vec2{} || !env.current_profile.empty() || env.current_varies();
  env.sea_surface_tilt = r.boolean("sea_surface_tilt", env.coriolis && current_flows);
  if (env.sea_surface_tilt && !env.coriolis)
    r.fail("sea_surface_tilt", "needs a latitude (the tilt balances the Coriolis force of the current)");
  env.rotational_damping = r.boolean("rotational_damping", env.rotational_damping);
  env.drag_reference_speed = r.real("drag_reference_speed", 0.0, Range::non_negative());
  env.added_mass_in_contacts = r.boolean("added_mass_in_contacts", env.added_mass_in_contacts);
  if (const toml::table* w = r.table("waves")) {
    TableReader wr(*w, scene.source_path, "environment.waves");
    env.waves.present = true;
    env.waves.amplitude = wr.real("amplitude", std::nullopt, Range::non_negative());
    if (wr.has("period") && wr.has("wavelength")) wr.fail("wavelength", "give period or wavelength, not both");
    env.waves.period = wr.real("period", 0.0, Range::non_negative());
    env.waves.wavelength = wr.real("wavelength", 0.0, Range::non_negative());
    if (env.waves.period > 0.0)  // deep water: L = g T^2 / (2 pi)
      env.waves.wavelength = env.gravity * env.waves.period * env.waves.period / (2.0 * M_PI);
    else if (env.waves.wavelength > 0.0)
      env.waves.period = std::sqrt(2.0 * M_PI * env.waves.wavelength / env.gravity);
    env.waves.direction = wr.real("direction", 0.0, Range::closed(-360.0, 360.0)) * M_PI / 180.0;
    wr.reject_unknown();
  }
  if (const toml::table* d = r.table("drag")) {
    TableReader dr(*d, scene.source_path, "environment.drag");
    DragCoefficients common;
    read_drag(dr, common);
    defaults.floe = defaults.iceberg = common;
    if (const toml::table* f = dr.table("floe")) {
      TableReader fr(*f, scene.source_path, "environment.drag.floe");
      read_drag(fr, defaults.floe);
      fr.reject_unknown();
    }
    if (const toml::table* i = dr.table("iceberg")) {
      TableReader ir(*i, scene.source_path, "environment.drag.iceberg");
      read_drag(ir, defaults.iceberg);
      ir.reject_unknown();
    }
    dr.reject_unknown();
  }
  r.reject_unknown();
  return defaults;
}

std::vector<std::pair<double, Vec2>> read_path(TableReader& r, const char* constant_key, const char* path_key) {
  if (r.has(constant_key) && r.has(path_key)) r.fail(path_key, std::string("give ") + constant_key + " or " + path_key + ", not both");
  if (!r.has(path_key)) return {{0.0, r.vec2(constant_key, std::nullopt)}};
  const auto rows = r.rows(path_key, 3);
  std::vector<std::pair<double, Vec2>> path;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (rows[k][0] < 0.0) r.fail(path_key, "times must be >= 0 s (row " + std::to_string(k) + ")");
    if (k > 0 && !(rows[k][0] > rows[k - 1][0])) r.fail(path_key, "times must increase (row " + std::to_string(k) + ")");
    path.push_back({rows[k][0], {rows[k][1], rows[k][2]}});
  }
  return path;
}

void read_tow(TableReader& root, Scene& scene, const GeoProjection* geo) {
  const toml::table* t = root.table("tow");
  if (!t) return;
  TableReader r(*t, scene.source_path, "tow");
  TowSpec& tow = scene.tow;
  const std::string mode = r.string("mode", std::nullopt, {"velocity", "rope", "tug"});
  const std::string name = r.string("body", std::nullopt);
  bool found = false;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    if (scene.bodies[i].name == name) {
      tow.body = i;
      found = true;
    }
  if (!found) r.fail("body", "no body is named \"" + name + "\"");
  BodySpec& b = scene.bodies[tow.body];
  if (b.fixed) r.fail("body", "\"" + name + "\" is fixed and cannot be towed");
  tow.stall_speed = r.real("stall_speed", 0.1, Range::closed(0.0, 10.0));
  if (mode == "velocity") {
    tow.mode = TowSpec::Mode::velocity;
    tow.path = read_path(r, "velocity", "path");
    b.prescribed = true;
    b.velocity = tow.velocity_at(0.0);  // the towed body starts on its path, heading held
    b.angular_velocity = 0.0;
    r.reject_unknown();
    return;
  }
  if (mode == "rope") {
    tow.mode = TowSpec::Mode::rope;
    tow.path = read_path(r, "tug_velocity", "tug_path");
  } else {
    tow.mode = TowSpec::Mode::tug;
    tow.path = read_path(r, "direction", "direction_path");
    for (std::size_t k = 0; k < tow.path.size(); ++k) {
      const Vec2 h = tow.path[k].second;
      const char* key = r.has("direction_path") ? "direction_path" : "direction";
      if (!(length(h) > 0.0)) r.fail(key, "a heading must be a nonzero vector (row " + std::to_string(k) + ")");
      // The heading between two rows is the direction of the interpolated vector: two that
      // point nearly opposite ways would swing it through zero.
      if (k > 0 && dot(normalized(h), normalized(tow.path[k - 1].second)) < -0.9)
        r.fail(key, "consecutive headings must differ by less than 154 deg (rows " + std::to_string(k - 1) + " and " +
                        std::to_string(k) + "); add a row between them");
    }
    // The thrust of a fixed-pitch propeller falls about linearly from the bollard pull at rest
    // to the hull's resistance at the free-running speed (docs/towing.md).
    tow.bollard_pull = r.real("bollard_pull", std::nullopt, Range{0.0, 1e8, true, false});
    tow.free_running_speed = r.real("free_running_speed", std::nullopt, Range{0.0, 20.0, true, false});
    // Default displacement: 2 kg per newton of bollard pull, about 20 t per tonne-force (between
    // a harbour tug's 10 and an anchor handler's 40; docs/towing.md).
    tow.tug_mass = r.real("tug_mass", 2.0 * tow.bollard_pull, Range{0.0, 1e10, true, false});
    tow.pull_ramp = r.real("pull_ramp", 0.0, Range::closed(0.0, 1e6));
  }
  tow.stiffness = r.real("stiffness", std::nullopt, Range::positive());
  tow.length = r.real("length", std::nullopt, Range::positive());
  tow.damping = r.real("damping", 0.0, Range::non_negative());
  tow.attachment = r.vec2("attachment", Vec2{});
  tow.breaking_load = r.real("breaking_load", 0.0, Range::non_negative());
  // Default tug start: the rope's length ahead of the attachment, along the tug's first
  // velocity or heading.
  const Vec2 heading = tow.direction();
  const AreaMoments m = area_moments(b.polygon);
  tow.tug_start = read_position(r, "tug_start", m.centroid + tow.attachment + tow.length * heading, geo);
  r.reject_unknown();
}

std::vector<KeelLayer> read_keel(TableReader& r, double draft) {
  if (!r.has("keel_layers")) return {KeelLayer{0.0, draft, 1.0}};
  const auto pairs = r.rows("keel_layers", 2);  // [thickness, width_scale] rows
  std::vector<Vec2> rows;
  for (const auto& p : pairs) rows.push_back({p[0], p[1]});
  std::vector<KeelLayer> keel;
  double depth = 0.0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (!(rows[k].x > 0.0)) r.fail("keel_layers", "layer " + std::to_string(k) + " thickness must be > 0 m");
    if (!(rows[k].y > 0.0 && rows[k].y <= 10.0))
      r.fail("keel_layers", "layer " + std::to_string(k) + " width_scale must be in (0, 10]");
    keel.push_back({depth, depth + rows[k].x, rows[k].y});
    depth += rows[k].x;
  }
  if (keel.empty() || std::abs(depth - draft) > 1e-6 * draft)
    r.fail("keel_layers", "layer thicknesses add up to " + std::to_string(depth) + " m; they must add up to the draft, " +
                              std::to_string(draft) + " m");
  keel.back().bottom = draft;
  return keel;
}

void read_bodies(TableReader& root, Scene& scene, double ice_density, const DragCoefficients& drag_floe,
                 const DragCoefficients& drag_iceberg, const GeoProjection* geo) {
  const auto tables = root.array_of_tables("body");
  std::set<std::string> names;
  for (std::size_t i = 0; i < tables.size(); ++i) {
    TableReader r(*tables[i], scene.source_path, "body[" + std::to_string(i) + "]");
    BodySpec b;
    b.name = r.string("name", "body-" + std::to_string(i));
    if (b.name.empty()) r.fail("name", "is empty; allowed a non-empty string");
    if (!names.insert(b.name).second) r.fail("name", "\"" + b.name + "\" is used by an earlier body; names must be unique");
    b.polygon = read_polygon(r, "polygon", geo);
    if (r.has("position_lonlat")) {  // the polygon (m) about its centroid, placed there
      need_geo(r, "position_lonlat", geo);
      if (r.has("polygon_lonlat")) r.fail("position_lonlat", "places a polygon given in metres; polygon_lonlat is placed already");
      const Vec2 at = lonlat_point(r, "position_lonlat", r.vec2("position_lonlat", std::nullopt), geo, "");
      if (const auto problem = polygon_problem(b.polygon)) r.fail("polygon", *problem);
      const Vec2 shift = at - area_moments(b.polygon).centroid;
      for (Vec2& v : b.polygon) v += shift;
    }
    check_polygon(r, b);
    const std::string kind = r.string("kind", "floe", {"floe", "iceberg"});
    b.kind = kind == "iceberg" ? BodyKind::iceberg : BodyKind::floe;
    b.density = r.real("density", ice_density, Range::positive());
    if (b.kind == BodyKind::floe) {
      b.thickness = r.real("thickness", std::nullopt, Range::positive());
      for (const char* k : {"draft", "sail_height", "keel_layers", "mass", "shape_factor"})
        if (r.has(k)) r.fail(k, "is for kind = \"iceberg\" only; a floe has a thickness");
      b.added_mass_coefficient = r.real("added_mass_coefficient", 0.0, Range::closed(0.0, 10.0));
      b.drag = drag_floe;
    } else {
      if (r.has("thickness")) r.fail("thickness", "an iceberg is given by draft and sail_height, not thickness");
      b.draft = r.real("draft", std::nullopt, Range::positive());
      b.freeboard = r.real("sail_height", std::nullopt, Range::non_negative());
      b.thickness = b.draft + b.freeboard;
      b.given_mass = r.real("mass", 0.0, Range::non_negative());
      b.shape_factor = r.real("shape_factor", 1.0, Range{0.0, 1.0, true, false});
      b.added_mass_coefficient = r.real("added_mass_coefficient", 0.5, Range::closed(0.0, 10.0));
      b.keel = read_keel(r, b.draft);
      b.drag = drag_iceberg;
    }
    if (const toml::table* d = r.table("drag")) {
      TableReader dr(*d, scene.source_path, r.field_name("drag"));
      read_drag(dr, b.drag);
      dr.reject_unknown();
    }
    b.velocity = r.vec2("velocity", Vec2{});
    b.angular_velocity = r.real("angular_velocity", 0.0, Range::any());
    b.fixed = r.boolean("fixed", false);
    b.applied_force = r.vec2("applied_force", Vec2{});
    b.applied_torque = r.real("applied_torque", 0.0, Range::any());
    if (b.fixed && (b.velocity != Vec2{} || b.angular_velocity != 0.0))
      r.fail("velocity", "a fixed body cannot move; allowed [0, 0] and angular_velocity = 0 when fixed = true");
    r.reject_unknown();
    scene.bodies.push_back(std::move(b));
  }
}

/// The generator's rectangle, exponent, shape and seed, and what it keeps free of ice: the
/// [[field.keep_out]] zones and the scenario's own bodies. Shared by a field of one
/// concentration and a field from an ice chart.
FieldSpec read_generator_region(TableReader& r, const Scene& scene, const GeoProjection* geo) {
  FieldSpec spec;
  spec.width = r.real("width", std::nullopt, Range::positive());
  spec.height = r.real("height", std::nullopt, Range::positive());
  spec.origin = read_position(r, "origin", Vec2{}, geo);
  spec.alpha = r.real("alpha", std::nullopt, Range{0.0, 10.0, true, false});
  spec.irregularity = r.real("irregularity", spec.irregularity, Range::closed(0.0, 1.0));
  spec.seed = static_cast<std::uint64_t>(r.integer("seed", static_cast<std::int64_t>(scene.run.seed), 0,
                                                   std::numeric_limits<std::int64_t>::max()));
  const auto zones = r.array_of_tables("keep_out");
  for (std::size_t k = 0; k < zones.size(); ++k) {
    TableReader zr(*zones[k], scene.source_path, "field.keep_out[" + std::to_string(k) + "]");
    BodySpec zone;
    zone.polygon = read_polygon(zr, "polygon", geo);
    check_polygon(zr, zone);
    zr.reject_unknown();
    spec.keep_out.push_back(zone.polygon);
    spec.keep_out_names.push_back("field.keep_out[" + std::to_string(k) + "]");
  }
  for (const BodySpec& b : scene.bodies) {
    spec.keep_out.push_back(b.polygon);
    spec.keep_out_names.push_back("body '" + b.name + "'");
  }
  return spec;
}

/// [field]: floes generated by the field generator (field/field_generator.hpp), or read from
/// a field file or a run's output. The scenario's own bodies are kept out of a generated field.
void read_field(TableReader& root, Scene& scene, double ice_density, const DragCoefficients& drag_floe,
                const GeoProjection* geo) {
  const toml::table* t = root.table("field");
  if (!t) return;
  TableReader r(*t, scene.source_path, "field");
  const double density = r.real("density", ice_density, Range::positive());
  const std::string prefix = r.string("name_prefix", "floe-");
  std::vector<BodySpec> floes;
  if (r.has("file")) {
    for (const char* k : {"width", "height", "origin", "origin_lonlat", "concentration", "alpha", "d_min", "d_max", "thickness",
                          "irregularity", "seed", "keep_out", "velocity", "chart", "layer"})
      if (r.has(k)) r.fail(k, "is for a generated field; with field.file the floes are read as they are");
    std::filesystem::path file = r.string("file", std::nullopt);
    if (file.is_relative()) file = std::filesystem::path(scene.source_path).parent_path() / file;
    const std::int64_t frame = r.integer("frame", -1, std::numeric_limits<std::int64_t>::min(),
                                         std::numeric_limits<std::int64_t>::max());
    BodyFrame bodies;
    try {
      bodies = read_body_frame(file.string(), frame);
    } catch (const InputError& e) {
      r.fail("file", e.what());
    }
    record_input_file(scene, "field.file", file.string());
    for (std::size_t i = 0; i < bodies.polygons.size(); ++i) {
      if (bodies.fixed[i]) continue;  // structures of a run's output stay behind
      BodySpec b;
      b.name = prefix + std::to_string(floes.size());
      b.polygon = bodies.polygons[i];
      b.thickness = bodies.thickness[i];
      b.density = bodies.density[i];
      b.velocity = bodies.velocity[i];
      b.angular_velocity = bodies.angular_velocity[i];
      floes.push_back(std::move(b));
    }
  } else if (r.has("chart")) {
    for (const char* k : {"concentration", "d_min", "d_max", "thickness"})
      if (r.has(k)) r.fail(k, "is set by the chart's codes (CT, FA, SA); with field.chart leave it out");
    need_geo(r, "chart", geo);
    FieldSpec spec = read_generator_region(r, scene, geo);
    std::filesystem::path file = r.string("chart", std::nullopt);
    if (file.is_relative()) file = std::filesystem::path(scene.source_path).parent_path() / file;
    const std::string layer = r.string("layer", "");
    IceChart chart;
    std::vector<ChartPolygonStats> stats;
    Field field;
    try {
      chart = read_ice_chart(file.string(), layer, *geo);
      field = generate_chart_field(chart, spec, stats);
    } catch (const InputError& e) {
      r.fail("chart", e.what());
    } catch (const FieldSpecError& e) {
      r.fail("chart", e.what());
    }
    record_input_file(scene, "field.chart", file.string());
    floes = field_floes(field, density, prefix);
    for (Provenance& p : chart_provenance(field, chart, stats, spec, density, scene.bodies.size()))
      scene.provenance.push_back(std::move(p));
    const Vec2 velocity = r.vec2("velocity", Vec2{});
    for (BodySpec& b : floes) b.velocity = velocity;
  } else {
    if (r.has("layer")) r.fail("layer", "names a layer of field.chart; give field.chart with it");
    FieldSpec spec = read_generator_region(r, scene, geo);
    spec.concentration = r.real("concentration", std::nullopt, Range{0.0, FieldSpec::max_concentration, true, false});
    spec.d_min = r.real("d_min", std::nullopt, Range::positive());
    spec.d_max = r.real("d_max", std::nullopt, Range::positive());
    if (const toml::node* n = t->get("thickness"); n && n->is_table()) {
      TableReader tr(*r.table("thickness"), scene.source_path, "field.thickness");
      ThicknessDistribution& d = spec.thickness;
      if (tr.has("min") || tr.has("max")) {
        d.kind = ThicknessDistribution::Kind::uniform;
        d.min = tr.real("min", std::nullopt, Range::positive());
        d.max = tr.real("max", std::nullopt, Range::positive());
      } else {
        d.kind = ThicknessDistribution::Kind::lognormal;
        d.mean = tr.real("mean", std::nullopt, Range::positive());
        d.std = tr.real("std", std::nullopt, Range::non_negative());
      }
      tr.reject_unknown();
    } else {
      spec.thickness.value = r.real("thickness", std::nullopt, Range::positive());
    }
    Field field;
    try {
      field = generate_field(spec);
    } catch (const FieldSpecError& e) {
      const std::string& p = e.parameter();
      r.fail(p.starts_with("keep_out") ? "keep_out" : p.starts_with("thickness") ? "thickness" : p, e.what());
    }
    floes = field_floes(field, density, prefix);
    scene.provenance.push_back(field_provenance(field, spec, density, scene.bodies.size()));
    const Vec2 velocity = r.vec2("velocity", Vec2{});
    for (BodySpec& b : floes) b.velocity = velocity;
  }
  std::set<std::string> names;
  for (const BodySpec& b : scene.bodies) names.insert(b.name);
  for (BodySpec& b : floes) {
    if (names.contains(b.name))
      r.fail("name_prefix", "floe name '" + b.name + "' is taken by a [[body]]; allowed a prefix no body name starts with");
    b.drag = drag_floe;
    scene.bodies.push_back(std::move(b));
  }
  r.reject_unknown();
}

void read_engines(TableReader& root, Scene& scene) {
  const toml::table* t = root.table("engine");
  if (!t) return;
  for (auto&& [k, v] : *t) {
    if (!v.is_table())
      throw InputError(input_message(scene.source_path, v.source().begin.line, "engine." + std::string(k.str()),
                                     "expected a table [engine." + std::string(k.str()) + "] of engine settings"));
    scene.engine_settings.emplace(std::string(k.str()), *v.as_table());
  }
}

}  // namespace

Scene parse_scenario(const std::string& text, const std::string& path, const std::vector<std::string>& overrides) {
  toml::table doc;
  try {
    doc = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw InputError(input_message(path, e.source().begin.line, "",
                                   "not valid TOML: " + std::string(e.description())));
  }
  Scene scene;
  scene.source_path = path;
  scene.source_text = text;
  scene.overrides = overrides;
  for (const std::string& o : overrides) apply_override(doc, o);

  TableReader root(doc, path, "");
  read_run(root, scene);
  read_contact(root, scene);
  const std::unique_ptr<GeoProjection> geo = read_geo(root, scene);
  const EnvironmentDefaults defaults = read_environment(root, scene);
  read_bodies(root, scene, defaults.ice_density, defaults.floe, defaults.iceberg, geo.get());
  read_field(root, scene, defaults.ice_density, defaults.floe, geo.get());
  read_output(root, scene);  // after the bodies: [output] loads names them
  place_lonlat_grids(scene);
  check_grid_coverage(scene);
  if (scene.bodies.empty()) root.fail("body", "no [[body]] and no [field] given; allowed at least one body");
  read_tow(root, scene, geo.get());
  read_engines(root, scene);
  root.reject_unknown();

  scene.derive();
  if (const auto hit = find_overlap(scene)) {
    throw InputError(input_message(path, 0, "body",
                                   "bodies '" + scene.bodies[hit->a].name + "' and '" + scene.bodies[hit->b].name +
                                       "' overlap at t = 0 (by " + std::to_string(hit->depth) +
                                       " m); allowed touching, not overlapping"));
  }
  return scene;
}

Scene load_scenario(const std::string& path, const std::vector<std::string>& overrides) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw InputError(path + ": cannot read scenario file: not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open scenario file: " + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read scenario file: " + std::strerror(errno));
  return parse_scenario(s.str(), path, overrides);
}

}  // namespace floedem
