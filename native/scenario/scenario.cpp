#include "scenario/scenario.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "geometry/polygon.hpp"
#include "scenario/table_reader.hpp"
#include "scene/input_error.hpp"
#include "scene/overlap.hpp"

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
  r.reject_unknown();
}

void read_contact(TableReader& root, Scene& scene) {
  const toml::table* t = root.table("contact");
  if (!t) return;
  TableReader r(*t, scene.source_path, "contact");
  scene.contact.restitution = r.real("restitution", scene.contact.restitution, Range::closed(0.0, 1.0));
  scene.contact.friction = r.real("friction", scene.contact.friction, Range::non_negative());
  scene.contact.collision_threshold =
      r.real("collision_threshold", scene.contact.collision_threshold, Range::non_negative());
  r.reject_unknown();
}

void read_output(TableReader& root, Scene& scene) {
  const toml::table* t = root.table("output");
  if (!t) return;
  TableReader r(*t, scene.source_path, "output");
  const std::string c = r.string("contacts", "all", {"all", "collisions", "none"});
  scene.output.contacts = c == "all" ? ContactOutput::all : c == "collisions" ? ContactOutput::collisions
                                                                             : ContactOutput::none;
  r.reject_unknown();
}

void check_polygon(TableReader& r, BodySpec& b) {
  if (b.polygon.size() < 3)
    r.fail("polygon", "has " + std::to_string(b.polygon.size()) + " vertices; allowed at least 3");
  if (const auto hit = find_self_intersection(b.polygon)) {
    r.fail("polygon", "is self-intersecting (edges " + std::to_string(hit->first) + " and " +
                          std::to_string(hit->second) + " touch or cross, counting from 0); allowed a simple polygon");
  }
  const double a = signed_area(b.polygon);
  const Aabb box = bounds_of(b.polygon);
  const double box_area = (box.hi.x - box.lo.x) * (box.hi.y - box.lo.y);
  if (!(std::abs(a) > 1e-12 * box_area) || box_area == 0.0)
    r.fail("polygon", "has zero area; allowed a simple polygon of positive area");
  if (a < 0.0) {
    std::reverse(b.polygon.begin(), b.polygon.end());
    b.reversed_input = true;
  }
}

void read_bodies(TableReader& root, Scene& scene) {
  const auto tables = root.array_of_tables("body");
  std::set<std::string> names;
  for (std::size_t i = 0; i < tables.size(); ++i) {
    TableReader r(*tables[i], scene.source_path, "body[" + std::to_string(i) + "]");
    BodySpec b;
    b.name = r.string("name", "body-" + std::to_string(i));
    if (b.name.empty()) r.fail("name", "is empty; allowed a non-empty string");
    if (!names.insert(b.name).second) r.fail("name", "\"" + b.name + "\" is used by an earlier body; names must be unique");
    b.polygon = r.points("polygon");
    check_polygon(r, b);
    b.thickness = r.real("thickness", std::nullopt, Range::positive());
    b.density = r.real("density", b.density, Range::positive());
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
  if (scene.bodies.empty()) root.fail("body", "no [[body]] given; allowed at least one body");
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
  read_output(root, scene);
  read_bodies(root, scene);
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
