#include "forcing/drag.hpp"

#include <atomic>
#include <cmath>

#include "parallel/thread_pool.hpp"

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

void add_form_drag(BodySum& sum, const std::vector<EdgePoint>& edges, double scale, double c, Vec2 flow, Vec2 v,
                   double w, Rot rot, const DragSettings& s, bool jacobian) {
  for (const EdgePoint& e : edges) {
    const Vec2 r = rot.apply(scale * e.r);
    const Vec2 n = rot.apply(e.normal);
    const Vec2 u = flow - (s.rotational ? v + cross(w, r) : v);
    const double un = dot(u, n);
    if (un >= 0.0) continue;  // the flow leaves this edge: no pressure on it
    const double k = c * scale * e.length;
    std::array<double, 4> a{};  // dF/du, computed only when the body needs its Jacobian
    Vec2 f;
    if (s.reference_speed > 0.0) {
      // Linearised: |u| -> U_ref, so dF = k U_ref cos(theta) u with cos(theta) = -u.n / |u|.
      const double cos_theta = -un / length(u);
      f = (k * s.reference_speed * cos_theta) * u;
      if (jacobian) a = {k * s.reference_speed * cos_theta, 0.0, 0.0, k * s.reference_speed * cos_theta};
    } else {
      // dF = k (-u.n) u,  dF/du = k ((-u.n) I - u n^T).
      f = (-k * un) * u;
      if (jacobian) a = {k * (-un - u.x * n.x), -k * u.x * n.y, -k * u.y * n.x, k * (-un - u.y * n.y)};
    }
    if (jacobian)
      sum.add_point_force(r, f, a, s.rotational);
    else
      sum.add_point_force(r, f, s.rotational);
  }
}

void add_skin_drag(BodySum& sum, const std::vector<AreaPoint>& points, double scale, double c, Vec2 flow, Vec2 v,
                   double w, Rot rot, const DragSettings& s, bool jacobian) {
  for (const AreaPoint& p : points) {
    const Vec2 r = rot.apply(scale * p.r);
    const Vec2 u = flow - (s.rotational ? v + cross(w, r) : v);
    const double k = c * scale * scale * p.area;
    std::array<double, 4> a{};  // dF/du, computed only when the body needs its Jacobian
    Vec2 f;
    if (s.reference_speed > 0.0) {
      f = (k * s.reference_speed) * u;
      if (jacobian) a = {k * s.reference_speed, 0.0, 0.0, k * s.reference_speed};
    } else {
      // dF = k |u| u,  dF/du = k (|u| I + u u^T / |u|).
      const double m = length(u);
      f = (k * m) * u;
      if (jacobian) {
        const double inv = m > 0.0 ? 1.0 / m : 0.0;
        a = {k * (m + u.x * u.x * inv), k * u.x * u.y * inv, k * u.x * u.y * inv, k * (m + u.y * u.y * inv)};
      }
    }
    if (jacobian)
      sum.add_point_force(r, f, a, s.rotational);
    else
      sum.add_point_force(r, f, s.rotational);
  }
}

DistributedDrag::DistributedDrag(std::string_view name, Kind kind, const EnvironmentSpec& environment)
    : name_(name), kind_(kind), settings_{environment.rotational_damping, environment.drag_reference_speed} {}

void DistributedDrag::add_body(std::size_t body, const std::vector<Vec2>& local_polygon, std::vector<DragSlab> slabs) {
  Entry e{body, {}, {}, std::move(slabs), {}};
  if (kind_ == Kind::form)
    e.edges = edge_points(local_polygon);
  else
    e.points = area_points(local_polygon);
  // Moments sum |k_p| |r_p|^j (j = 0..3) of each slab's quadrature weights, for the rate bound.
  for (const DragSlab& slab : e.slabs) {
    std::array<double, 4> m{};
    auto add = [&](double k, Vec2 r) {
      const double d = length(slab.scale * r);
      m[0] += std::abs(k);
      m[1] += std::abs(k) * d;
      m[2] += std::abs(k) * d * d;
      m[3] += std::abs(k) * d * d * d;
    };
    for (const EdgePoint& p : e.edges) add(slab.c * slab.scale * p.length, p.r);
    for (const AreaPoint& p : e.points) add(slab.c * slab.scale * slab.scale * p.area, p.r);
    e.moments.push_back(m);
  }
  // What the rest test reads, packed: one flow when every slab shares it (a floe's one slab).
  Quiet q{body, e.slabs.empty() ? Vec2{} : e.slabs.front().flow, true, e.slabs.size() == 1,
          e.moments.empty() ? std::array<double, 4>{} : e.moments.front()};
  for (const DragSlab& slab : e.slabs) q.one_flow = q.one_flow && slab.flow.x == q.flow.x && slab.flow.y == q.flow.y;
  quiet_.push_back(q);
  for (const DragSlab& slab : e.slabs) calm_ = calm_ && slab.flow.x == 0.0 && slab.flow.y == 0.0;
  if (kind_ == Kind::skin && settings_.reference_speed > 0.0) calm_ = false;
  if (entry_of_body_.size() <= body) entry_of_body_.resize(body + 1, -1);
  entry_of_body_[body] = static_cast<std::int32_t>(entries_.size());
  entries_.push_back(std::move(e));
}

template <class F>
void DistributedDrag::for_entries(const ForceSums& sums, std::size_t grain, F&& f) const {
  if (!calm_) {
    thread_pool().for_blocks(entries_.size(), grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) f(i);
    });
    return;
  }
  // Still water and air: an entry whose body is at rest is one adds_nothing skips, so visiting
  // the moving bodies alone gives the same sums to the bit (each entry writes its own body).
  thread_pool().for_blocks(sums.stirred.size(), grain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const auto body = static_cast<std::size_t>(sums.stirred[k]);
      if (body < entry_of_body_.size() && entry_of_body_[body] >= 0) f(static_cast<std::size_t>(entry_of_body_[body]));
    }
  });
}

bool DistributedDrag::add_rate_bound(const BodyStates& s, ForceSums& sums) const {
  for_entries(sums, 4096, [&](std::size_t i) { add_entry_bound(i, s, sums); });
  return true;
}

void DistributedDrag::add_entry_bound(std::size_t i, const BodyStates& s, ForceSums& sums) const {
  // Per quadrature point, with m = |u| <= |V - v| + |w| |r| and k its weight (MODEL.md 2):
  //   skin  a = k (m I + u u^T / m):    |a_00| + |a_01| <= (1 + sqrt 2) |k| m,  g^T a g <= 2 |k| m |r|^2
  //   form  a = k (-(u.n) I - u n^T):   the same two bounds (|u.n| <= m, |n_x| + |n_y| <= sqrt 2)
  //   linearised (m -> U_ref):          |k| U_ref and |k| U_ref |r|^2
  // where g = k x r maps the spin to the point's velocity, so summing over the points bounds
  // the row sums of D's translational block and |D_ww| (forcing.cpp's stiffness test).
  constexpr double kRow = 1.0 + 1.4142135623730951;
  const std::size_t body = quiet_[i].body;
  const Vec2 v = s.velocity[body];
  if (adds_nothing(i, v, s.angular_velocity[body])) return;  // adds nothing to D either
  const double w = std::abs(s.angular_velocity[body]);
  std::array<double, 2>& b = sums.rate_bound[body];
  auto add_slab = [&](const std::array<double, 4>& m, Vec2 flow) {
    if (settings_.reference_speed > 0.0) {
      b[0] += settings_.reference_speed * m[0];
      b[1] += settings_.rotational ? settings_.reference_speed * m[2] : 0.0;
      return;
    }
    const double du = length(flow - v);
    const double spin = settings_.rotational ? w : 0.0;
    b[0] += kRow * (du * m[0] + spin * m[1]);
    b[1] += settings_.rotational ? 2.0 * (du * m[2] + spin * m[3]) : 0.0;
  };
  const Quiet& q = quiet_[i];
  if (q.single) {  // one slab (a floe): all from the packed record, no trip to the entry
    add_slab(q.moments, q.flow);
    return;
  }
  const Entry& e = entries_[i];
  for (std::size_t k = 0; k < e.slabs.size(); ++k) add_slab(e.moments[k], e.slabs[k].flow);
}

bool DistributedDrag::adds_nothing(std::size_t i, Vec2 v, double w) const {
  // A body moving with the flow of every slab, without spin, feels no quadratic drag: u = 0 at
  // every quadrature point, so each point adds exactly zero force and Jacobian (a form-drag
  // point is skipped at u.n = 0; a skin point adds k |u| u = 0). Skipping it is exact, so a
  // field of floes at rest in calm water costs nothing here. Linearised skin drag keeps its
  // Jacobian k U_ref I at u = 0, so it is never skipped.
  if (w != 0.0 || (kind_ == Kind::skin && settings_.reference_speed > 0.0)) return false;
  const Quiet& q = quiet_[i];
  if (q.one_flow) return q.flow.x == v.x && q.flow.y == v.y;
  for (const DragSlab& slab : entries_[i].slabs)
    if (slab.flow.x != v.x || slab.flow.y != v.y) return false;
  return true;
}

void DistributedDrag::add(const BodyStates& s, double, ForceSums& sums) const {
  // Entries are bodies, one each: blocks of them on the pool's threads write distinct bodies,
  // each in the same order as one thread would, so the sums do not depend on the threads.
  std::atomic<bool> any_jacobian{false};
  for_entries(sums, 512, [&](std::size_t i) {
    if (add_entry(i, s, sums) && !any_jacobian.load(std::memory_order_relaxed))
      any_jacobian.store(true, std::memory_order_relaxed);
  });
  if (any_jacobian.load(std::memory_order_relaxed)) sums.any_jacobian = true;
}

bool DistributedDrag::add_entry(std::size_t i, const BodyStates& s, ForceSums& sums) const {
  const std::size_t body = quiet_[i].body;
  const Vec2 v = s.velocity[body];
  const double w = s.angular_velocity[body];
  if (adds_nothing(i, v, w)) return false;
  const Entry& e = entries_[i];
  const Rot rot = sums.rotation[e.body];
  const bool jacobian = sums.jacobian[e.body] != 0;
  BodySum sum = sums.load(e.body);
  for (const DragSlab& slab : e.slabs) {
    if (kind_ == Kind::form)
      add_form_drag(sum, e.edges, slab.scale, slab.c, slab.flow, v, w, rot, settings_, jacobian);
    else
      add_skin_drag(sum, e.points, slab.scale, slab.c, slab.flow, v, w, rot, settings_, jacobian);
  }
  sums.store(e.body, sum);
  return jacobian;
}

}  // namespace floedem
