#include "floedem/scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "geometry/convex_partition.hpp"
#include "geometry/polygon.hpp"
#include "floedem/scene/input_error.hpp"

namespace floedem {

namespace {

/// A byte as \xNN (two lowercase hex digits).
void append_escaped(std::string& out, unsigned char c) {
  static constexpr char kHex[] = "0123456789abcdef";
  out += "\\x";
  out.push_back(kHex[c >> 4]);
  out.push_back(kHex[c & 15]);
}

}  // namespace

std::string printable(std::string_view text, std::size_t max) {
  std::string out;
  for (std::size_t k = 0; k < text.size(); ++k) {
    if (k == max) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(text[k]);
    if (c >= 0x20 && c < 0x7f)
      out.push_back(static_cast<char>(c));
    else
      append_escaped(out, c);
  }
  return out;
}

std::string one_line(const std::string& message) {
  const auto control = [](char ch) {
    const auto c = static_cast<unsigned char>(ch);
    return c < 0x20 || c == 0x7f;
  };
  if (std::none_of(message.begin(), message.end(), control)) return message;
  std::string out;
  for (char ch : message) {
    if (control(ch))
      append_escaped(out, static_cast<unsigned char>(ch));
    else
      out.push_back(ch);
  }
  return out;
}

std::string input_message(const std::string& file, std::uint32_t line, const std::string& field,
                          const std::string& what) {
  std::string m = file;
  if (line > 0) {
    m.push_back(':');
    m.append(std::to_string(line));
  }
  m.append(": ");
  if (!field.empty()) {
    m.append("field '");
    m.append(field);
    m.append("': ");
  }
  m.append(what);
  return m;
}

std::int64_t RunSettings::steps() const {
  const double n = std::round(duration / dt);
  // At least one step, also for a NaN (a scene with no run, as a field file's: 0 / 0), and no
  // more than an int64 holds: a cast of either to an integer is undefined.
  if (!(n >= 1.0)) return 1;
  return n < 0x1p63 ? static_cast<std::int64_t>(n) : std::numeric_limits<std::int64_t>::max();
}

void Scene::derive() {
  for (BodySpec& b : bodies) {
    const AreaMoments m = area_moments(b.polygon);
    b.area = m.area;
    b.centroid = m.centroid;
    if (b.kind == BodyKind::floe) {
      // Floating floe (docs/model.md 2): draft = h rho_i / rho_w, freeboard = h - draft.
      b.mass = b.density * b.thickness * m.area;
      b.draft = b.thickness * b.density / environment.water_density;
      b.freeboard = b.thickness - b.draft;
      b.keel = {KeelLayer{0.0, b.draft, 1.0}};
    } else {
      // Iceberg (docs/model.md 1): mass given, or rho_i A (draft + sail) times a shape factor.
      b.mass = b.given_mass > 0.0 ? b.given_mass : b.density * m.area * b.thickness * b.shape_factor;
    }
    // Polar moment of a uniform prism: I = m J / A, J the polygon's polar moment of area.
    b.inertia = b.mass * m.polar_moment / m.area;
    b.local_polygon.clear();
    for (const Vec2 p : b.polygon) b.local_polygon.push_back(p - m.centroid);
    b.local_parts = convex_partition(remove_collinear(b.local_polygon));
    if (b.local_parts.empty())
      throw InputError(input_message(source_path, 0, "body '" + b.name + "'.polygon",
                                     "could not be split into convex parts"));
  }
}

}  // namespace floedem

namespace floedem {

double Scene::engine_mass(std::size_t i) const {
  const BodySpec& b = bodies[i];
  return b.mass * (environment.added_mass_in_contacts ? 1.0 + b.added_mass_coefficient : 1.0);
}

double Scene::engine_inertia(std::size_t i) const {
  const BodySpec& b = bodies[i];
  return b.inertia * (environment.added_mass_in_contacts ? 1.0 + b.added_mass_coefficient : 1.0);
}

double Scene::engine_inverse_mass(std::size_t i) const {
  return bodies[i].fixed || bodies[i].prescribed ? 0.0 : 1.0 / engine_mass(i);
}

double Scene::engine_inverse_inertia(std::size_t i) const {
  return bodies[i].fixed || bodies[i].prescribed ? 0.0 : 1.0 / engine_inertia(i);
}

Vec2 EnvironmentSpec::current_at(double depth) const {
  if (current_profile.empty()) return current;
  Vec2 v = current_profile.front().velocity;
  for (const CurrentLayer& l : current_profile)
    if (depth >= l.depth) v = l.velocity;
  return v;
}

Vec2 TowSpec::velocity_at(double t) const {
  if (path.empty()) return {};
  if (t <= path.front().first) return path.front().second;
  for (std::size_t k = 1; k < path.size(); ++k) {
    if (t <= path[k].first) {
      const double w = (t - path[k - 1].first) / (path[k].first - path[k - 1].first);
      return (1.0 - w) * path[k - 1].second + w * path[k].second;
    }
  }
  return path.back().second;
}

Vec2 TowSpec::acceleration_at(double t) const {
  for (std::size_t k = 1; k < path.size(); ++k)
    if (t >= path[k - 1].first && t < path[k].first)
      return (1.0 / (path[k].first - path[k - 1].first)) * (path[k].second - path[k - 1].second);
  return {};
}

Vec2 TowSpec::displacement(double t0, double t1) const {
  // Exact for a piecewise-linear velocity: trapezoids between the path's corners inside
  // (t0, t1). No list of cuts is built: called every step, it allocates nothing.
  Vec2 d;
  double from = t0;
  auto trapezoid = [&](double to) {
    d += (0.5 * (to - from)) * (velocity_at(from) + velocity_at(to));
    from = to;
  };
  for (const auto& [t, v] : path)
    if (t > t0 && t < t1) trapezoid(t);
  trapezoid(t1);
  return d;
}

Vec2 TowSpec::heading_at(double t) const {
  const Vec2 h = velocity_at(t);
  const double n = floedem::length(h);
  // The interpolated vector passes near zero only between two headings that point nearly
  // opposite ways, which the scenario reader refuses.
  return n > 0.0 ? (1.0 / n) * h : direction();
}

Vec2 TowSpec::direction() const {
  for (const auto& [t, v] : path)
    if (floedem::length(v) > 0.0) return normalized(v);
  return {1.0, 0.0};
}

}  // namespace floedem
