#include "forcing/drag.hpp"

#include <cmath>

namespace floedem {

std::vector<EdgePoint> edge_points(const std::vector<Vec2>& poly) {
  std::vector<EdgePoint> out;
  const std::size_t n = poly.size();
  const double g = 0.5 / std::sqrt(3.0);  // Gauss points at 1/2 -+ 1/(2 sqrt 3)
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 a = poly[k], b = poly[(k + 1) % n];
    const double len = length(b - a);
    if (len == 0.0) continue;
    const Vec2 normal{(b - a).y / len, -(b - a).x / len};
    out.push_back({a + (0.5 - g) * (b - a), normal, 0.5 * len});
    out.push_back({a + (0.5 + g) * (b - a), normal, 0.5 * len});
  }
  return out;
}

std::vector<AreaPoint> area_points(const std::vector<Vec2>& poly) {
  std::vector<AreaPoint> out;
  const std::size_t n = poly.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 a = poly[k], b = poly[(k + 1) % n];
    const double third = cross(a, b) / 6.0;  // a third of the triangle (0, a, b)
    out.push_back({0.5 * a, third});
    out.push_back({0.5 * b, third});
    out.push_back({0.5 * (a + b), third});
  }
  return out;
}

void add_form_drag(BodySum& sum, const std::vector<EdgePoint>& edges, double scale, double c,
                   Vec2 flow, Vec2 v, double w, Rot rot, const DragSettings& s) {
  for (const EdgePoint& e : edges) {
    const Vec2 r = rot.apply(scale * e.r);
    const Vec2 n = rot.apply(e.normal);
    const Vec2 u = flow - (s.rotational ? v + cross(w, r) : v);
    const double un = dot(u, n);
    if (un >= 0.0) continue;  // the flow leaves this edge: no pressure on it
    const double k = c * scale * e.length;
    std::array<double, 4> a;
    Vec2 f;
    if (s.reference_speed > 0.0) {
      // Linearised: |u| -> U_ref, so dF = k U_ref cos(theta) u with cos(theta) = -u.n / |u|.
      const double cos_theta = -un / length(u);
      f = (k * s.reference_speed * cos_theta) * u;
      a = {k * s.reference_speed * cos_theta, 0.0, 0.0, k * s.reference_speed * cos_theta};
    } else {
      // dF = k (-u.n) u,  dF/du = k ((-u.n) I - u n^T).
      f = (-k * un) * u;
      a = {k * (-un - u.x * n.x), -k * u.x * n.y, -k * u.y * n.x, k * (-un - u.y * n.y)};
    }
    sum.add_point_force(r, f, a, s.rotational);
  }
}

void add_skin_drag(BodySum& sum, const std::vector<AreaPoint>& points, double scale, double c,
                   Vec2 flow, Vec2 v, double w, Rot rot, const DragSettings& s) {
  for (const AreaPoint& p : points) {
    const Vec2 r = rot.apply(scale * p.r);
    const Vec2 u = flow - (s.rotational ? v + cross(w, r) : v);
    const double k = c * scale * scale * p.area;
    std::array<double, 4> a;
    Vec2 f;
    if (s.reference_speed > 0.0) {
      f = (k * s.reference_speed) * u;
      a = {k * s.reference_speed, 0.0, 0.0, k * s.reference_speed};
    } else {
      // dF = k |u| u,  dF/du = k (|u| I + u u^T / |u|).
      const double m = length(u);
      f = (k * m) * u;
      const double inv = m > 0.0 ? 1.0 / m : 0.0;
      a = {k * (m + u.x * u.x * inv), k * u.x * u.y * inv, k * u.x * u.y * inv, k * (m + u.y * u.y * inv)};
    }
    sum.add_point_force(r, f, a, s.rotational);
  }
}

DistributedDrag::DistributedDrag(std::string_view name, Kind kind, const EnvironmentSpec& environment)
    : name_(name), kind_(kind), settings_{environment.rotational_damping, environment.drag_reference_speed} {}

void DistributedDrag::add_body(std::size_t body, const std::vector<Vec2>& local_polygon, std::vector<DragSlab> slabs) {
  Entry e{body, {}, {}, std::move(slabs)};
  if (kind_ == Kind::form)
    e.edges = edge_points(local_polygon);
  else
    e.points = area_points(local_polygon);
  entries_.push_back(std::move(e));
}

bool DistributedDrag::adds_nothing(const Entry& e, Vec2 v, double w) const {
  // A body moving with the flow of every slab, without spin, feels no quadratic drag: u = 0 at
  // every quadrature point, so each point adds exactly zero force and Jacobian (a form-drag
  // point is skipped at u.n = 0; a skin point adds k |u| u = 0). Skipping it is exact, so a
  // field of floes at rest in calm water costs nothing here. Linearised skin drag keeps its
  // Jacobian k U_ref I at u = 0, so it is never skipped.
  if (w != 0.0 || (kind_ == Kind::skin && settings_.reference_speed > 0.0)) return false;
  for (const DragSlab& slab : e.slabs)
    if (slab.flow.x != v.x || slab.flow.y != v.y) return false;
  return true;
}

void DistributedDrag::add(const BodyStates& s, double, ForceSums& sums) const {
  for (const Entry& e : entries_) {
    const Vec2 v = s.velocity[e.body];
    const double w = s.angular_velocity[e.body];
    if (adds_nothing(e, v, w)) continue;
    const Rot rot = Rot::from_angle(s.angle[e.body]);
    BodySum sum = sums.load(e.body);
    for (const DragSlab& slab : e.slabs) {
      if (kind_ == Kind::form)
        add_form_drag(sum, e.edges, slab.scale, slab.c, slab.flow, v, w, rot, settings_);
      else
        add_skin_drag(sum, e.points, slab.scale, slab.c, slab.flow, v, w, rot, settings_);
    }
    sums.store(e.body, sum);
  }
}

}  // namespace floedem
