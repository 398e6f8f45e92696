#include "forcing/drag.hpp"
#include "forcing/flow_grid.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "parallel/thread_pool.hpp"

namespace floedem {

std::vector<EdgePoint> edge_points(const std::vector<Vec2>& poly) {
  std::vector<EdgePoint> out;
  const std::size_t n = poly.size();
  const double g = gauss_offset();  // Gauss points at 1/2 -+ 1/(2 sqrt 3)
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

namespace {
// One quadrature point's drag law, shared by the point-by-point rule and the packed term (the
// same arithmetic, so the same sums to the bit). r: the point's offset (world), u: the flow
// relative to it, k: its weight.

// Form drag on an edge point of outward normal n, facing the flow (u.n < 0).
[[gnu::always_inline]] inline void add_form_point(BodySum& sum, Vec2 r, Vec2 n, Vec2 u, double un, double k,
                                                  const DragSettings& s, bool jacobian) {
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

// Skin drag on an area point; m = |u| (read only for quadratic drag).
[[gnu::always_inline]] inline void add_skin_point(BodySum& sum, Vec2 r, Vec2 u, double m, double k,
                                                  const DragSettings& s, bool jacobian) {
  std::array<double, 4> a{};  // dF/du, computed only when the body needs its Jacobian
  Vec2 f;
  if (s.reference_speed > 0.0) {
    f = (k * s.reference_speed) * u;
    if (jacobian) a = {k * s.reference_speed, 0.0, 0.0, k * s.reference_speed};
  } else {
    // dF = k |u| u,  dF/du = k (|u| I + u u^T / |u|).
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
}  // namespace

void add_form_drag(BodySum& sum, const std::vector<EdgePoint>& edges, double scale, double c, Vec2 flow, Vec2 v,
                   double w, Rot rot, const DragSettings& s, bool jacobian) {
  for (const EdgePoint& e : edges) {
    const Vec2 r = rot.apply(scale * e.r);
    const Vec2 n = rot.apply(e.normal);
    const Vec2 u = flow - (s.rotational ? v + cross(w, r) : v);
    const double un = dot(u, n);
    if (un >= 0.0) continue;  // the flow leaves this edge: no pressure on it
    add_form_point(sum, r, n, u, un, c * scale * e.length, s, jacobian);
  }
}

void add_skin_drag(BodySum& sum, const std::vector<AreaPoint>& points, double scale, double c, Vec2 flow, Vec2 v,
                   double w, Rot rot, const DragSettings& s, bool jacobian) {
  for (const AreaPoint& p : points) {
    const Vec2 r = rot.apply(scale * p.r);
    const Vec2 u = flow - (s.rotational ? v + cross(w, r) : v);
    add_skin_point(sum, r, u, s.reference_speed > 0.0 ? 0.0 : length(u), c * scale * scale * p.area, s, jacobian);
  }
}

DistributedDrag::DistributedDrag(std::string_view name, Kind kind, const EnvironmentSpec& environment, Medium medium)
    : name_(name),
      kind_(kind),
      settings_{environment.rotational_damping, environment.drag_reference_speed},
      environment_(environment),
      medium_(medium),
      varies_(medium == Medium::water ? environment.current_varies() : environment.wind_varies()),
      calm_(!varies_) {}

void DistributedDrag::set_time(double time) {
  if (!varies_) return;
  const Vec2 change = medium_ == Medium::water ? environment_.current_change(time) : environment_.wind_change(time);
  if (change.x == change_.x && change.y == change_.y) return;  // the flows hold it already
  change_ = change;
  // Every copy of a slab's flow: the slab's own, the rest test's, and its lane's (drag.hpp).
  for (std::size_t k = 0; k < slabs_.size(); ++k) slabs_[k].drag.flow = given_flow_[k] + change;
  for (std::size_t i = 0; i < entries_.size(); ++i)
    if (entries_[i].slab_count > 0) quiet_[i].flow = slabs_[entries_[i].first_slab].drag.flow;
  if (lanes_packed_)
    for (LaneGroup& g : groups_)
      for (std::uint32_t l = 0; l < g.lanes; ++l) {
        const Vec2 flow = slabs_[entries_[g.entry[l]].first_slab].drag.flow;
        g.flow_x[l] = flow.x;
        g.flow_y[l] = flow.y;
      }
}

void DistributedDrag::leave_to_pass(const std::vector<std::uint8_t>& shared) {
  passed_.assign(entries_.size(), 0);
  for (std::size_t i = 0; i < entries_.size(); ++i)
    passed_[i] = entries_[i].body < shared.size() && shared[entries_[i].body] != 0 ? 1 : 0;
  // The lanes are packed again, without them, at the next add (their slots are the pass's now).
  lanes_packed_ = false;
  groups_ = {};
  form_lanes_ = {};
  skin_lanes_ = {};
  lane_moments_ = {};
}

void DistributedDrag::add_body(std::size_t body, const std::vector<Vec2>& local_polygon, std::vector<DragSlab> slabs) {
  const std::vector<EdgePoint> edges = kind_ == Kind::form ? edge_points(local_polygon) : std::vector<EdgePoint>{};
  const std::vector<AreaPoint> points = kind_ == Kind::skin ? area_points(local_polygon) : std::vector<AreaPoint>{};
  const Entry e{body, static_cast<std::uint32_t>(slabs_.size()), static_cast<std::uint32_t>(slabs.size())};
  for (const DragSlab& drag : slabs) {
    Slab slab{drag, 0, 0, {}};
    // Moments sum |k_p| |r_p|^j (j = 0..3) of the slab's quadrature weights, for the rate bound.
    auto add = [&](double k, Vec2 r) {
      const double d = length(drag.scale * r);
      slab.moments[0] += std::abs(k);
      slab.moments[1] += std::abs(k) * d;
      slab.moments[2] += std::abs(k) * d * d;
      slab.moments[3] += std::abs(k) * d * d * d;
    };
    for (const EdgePoint& p : edges) add(drag.c * drag.scale * p.length, p.r);
    for (const AreaPoint& p : points) add(drag.c * drag.scale * drag.scale * p.area, p.r);
    // The packed points, each product as add_form_drag / add_skin_drag form it.
    if (kind_ == Kind::form) {
      slab.first = static_cast<std::uint32_t>(form_.size());
      for (std::size_t k = 0; k + 1 < edges.size(); k += 2)  // edge_points: two per edge
        form_.push_back({drag.scale * edges[k].r, drag.scale * edges[k + 1].r, edges[k].normal,
                         drag.c * drag.scale * edges[k].length});
      slab.count = static_cast<std::uint32_t>(form_.size()) - slab.first;
    } else {
      slab.first = static_cast<std::uint32_t>(skin_.size());
      for (std::size_t k = 0; k + 2 < points.size(); k += 3)  // area_points: a / 2, b / 2, (a + b) / 2
        skin_.push_back({drag.scale * points[k].r, drag.scale * points[k + 2].r,
                         drag.c * drag.scale * drag.scale * points[k].area});
      slab.count = static_cast<std::uint32_t>(skin_.size()) - slab.first;
    }
    slabs_.push_back(slab);
    if (varies_) given_flow_.push_back(drag.flow);
  }
  // What the rest test reads, packed: one flow when every slab shares it (a floe's one slab).
  Quiet q{body, slabs.empty() ? Vec2{} : slabs.front().flow, true, slabs.size() == 1,
          slabs.empty() ? std::array<double, 4>{} : slabs_[e.first_slab].moments};
  for (const DragSlab& slab : slabs) q.one_flow = q.one_flow && slab.flow.x == q.flow.x && slab.flow.y == q.flow.y;
  quiet_.push_back(q);
  for (const DragSlab& slab : slabs) calm_ = calm_ && slab.flow.x == 0.0 && slab.flow.y == 0.0;
  if (kind_ == Kind::skin && settings_.reference_speed > 0.0) calm_ = false;
  lanes_packed_ = false;
  if (entry_of_body_.size() <= body) entry_of_body_.resize(body + 1, -1);
  entry_of_body_[body] = static_cast<std::int32_t>(entries_.size());
  entries_.push_back(e);
}

void DistributedDrag::add_form_slab(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot, bool jacobian) const {
  const Vec2 flow = slab.drag.flow;
  add_form_slab_at(sum, slab, v, w, rot, jacobian, [flow](Vec2) { return flow; });
}

template <class FlowAt>
void DistributedDrag::add_form_slab_at(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot, bool jacobian,
                                       FlowAt flow_at) const {
  // add_form_drag, point by point in its order, each edge's normal turned once.
  const DragSettings& s = settings_;
  auto point = [&](Vec2 local, Vec2 n, double k) {
    const Vec2 r = rot.apply(local);
    const Vec2 u = flow_at(r) - (s.rotational ? v + cross(w, r) : v);
    const double un = dot(u, n);
    if (un >= 0.0) return;  // the flow leaves this edge: no pressure on it
    add_form_point(sum, r, n, u, un, k, s, jacobian);
  };
  const FormEdge* edge = form_.data() + slab.first;
  for (std::uint32_t j = 0; j < slab.count; ++j) {
    const Vec2 n = rot.apply(edge[j].normal);
    point(edge[j].first, n, edge[j].weight);
    point(edge[j].second, n, edge[j].weight);
  }
}

void DistributedDrag::add_skin_slab(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot, bool jacobian) const {
  const Vec2 flow = slab.drag.flow;
  add_skin_slab_at(sum, slab, v, w, rot, jacobian, [flow](Vec2) { return flow; });
}

template <class FlowAt>
void DistributedDrag::add_skin_slab_at(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot, bool jacobian,
                                       FlowAt flow_at) const {
  // add_skin_drag, point by point in its order; the relative velocity and its magnitude at a
  // half-vertex serve both triangles that share it.
  const DragSettings& s = settings_;
  struct Local {
    Vec2 r, u;
    double m;  // |u| (quadratic drag)
  };
  auto at = [&](Vec2 local) {
    const Vec2 r = rot.apply(local);
    const Vec2 u = flow_at(r) - (s.rotational ? v + cross(w, r) : v);
    return Local{r, u, s.reference_speed > 0.0 ? 0.0 : length(u)};
  };
  auto add = [&](const Local& p, double k) { add_skin_point(sum, p.r, p.u, p.m, k, s, jacobian); };
  if (slab.count == 0) return;
  const SkinTriangle* t = skin_.data() + slab.first;
  const Local first = at(t[0].half_vertex);
  Local a = first;
  for (std::uint32_t j = 0; j < slab.count; ++j) {
    const Local b = j + 1 < slab.count ? at(t[j + 1].half_vertex) : first;
    add(a, t[j].weight);
    add(b, t[j].weight);
    add(at(t[j].middle), t[j].weight);
    a = b;
  }
}

namespace {
// Two quadrature points side by side (GCC's vector extension: one SSE2 register on x86-64, two
// scalars elsewhere). Each lane takes the scalar rule's operations in its order, and IEEE
// arithmetic rounds each the same in a lane as alone (no fused multiply-add: the build says
// -ffp-contract=off), so the lanes hold the rule's values to the bit.
using Pair = double __attribute__((vector_size(16)));

[[gnu::always_inline]] inline Pair sqrt_of(Pair x) {
#if defined(__SSE2__)
  return _mm_sqrt_pd(x);  // correctly rounded, as std::sqrt
#else
  return Pair{std::sqrt(x[0]), std::sqrt(x[1])};
#endif
}

/// Two points of a body (body frame, scaled) turned into the world and the flow relative to
/// them, as add_form_drag / add_skin_drag form r = rot p and u = flow - (v + w k x r).
struct TwoPoints {
  Pair rx, ry, ux, uy;
};
class PointKinematics {
 public:
  PointKinematics(Rot rot, Vec2 flow, Vec2 v, double w, bool rotational)
      : c_{rot.c, rot.c}, s_{rot.s, rot.s}, fx_{flow.x, flow.x}, fy_{flow.y, flow.y}, vx_{v.x, v.x},
        vy_{v.y, v.y}, neg_w_{-w, -w}, w_{w, w}, rotational_(rotational) {}
  TwoPoints at(Vec2 p0, Vec2 p1) const {
    const Pair lx = {p0.x, p1.x}, ly = {p0.y, p1.y};
    TwoPoints t;
    t.rx = c_ * lx - s_ * ly;  // rot.apply
    t.ry = s_ * lx + c_ * ly;
    t.ux = rotational_ ? fx_ - (vx_ + neg_w_ * t.ry) : fx_ - vx_;
    t.uy = rotational_ ? fy_ - (vy_ + w_ * t.rx) : fy_ - vy_;
    return t;
  }

 private:
  Pair c_, s_, fx_, fy_, vx_, vy_, neg_w_, w_;
  bool rotational_;
};
}  // namespace

void DistributedDrag::add_form_slab_lean(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot) const {
  // add_form_drag without the Jacobian, for quadratic drag: an edge's two Gauss points as the
  // two lanes. A point the flow leaves (u.n >= 0) adds -0 in place of nothing: x + (-0) = x to
  // the bit for every x (a -0 sum included), so the sums are the rule's with no branch to
  // mispredict (half an outline's points face away from the flow).
  const PointKinematics kinematics(rot, slab.drag.flow, v, w, settings_.rotational);
  const Pair none = {-0.0, -0.0};
  const bool rotational = settings_.rotational;
  double q0 = sum.q[0], q1 = sum.q[1], q2 = sum.q[2];
  const FormEdge* edge = form_.data() + slab.first;
  for (std::uint32_t j = 0; j < slab.count; ++j) {
    const Vec2 n = rot.apply(edge[j].normal);
    const TwoPoints p = kinematics.at(edge[j].first, edge[j].second);
    const Pair un = p.ux * n.x + p.uy * n.y;
    const Pair kun = (-edge[j].weight) * un;  // -k u.n
    const auto leaves = un >= 0.0;
    const Pair f_x = leaves ? none : kun * p.ux, f_y = leaves ? none : kun * p.uy;
    const Pair t = leaves ? none : p.rx * f_y - p.ry * f_x;  // cross(r, f)
    q0 += f_x[0];
    q1 += f_y[0];
    if (rotational) q2 += t[0];
    q0 += f_x[1];
    q1 += f_y[1];
    if (rotational) q2 += t[1];
  }
  sum.q = {q0, q1, q2};
}

void DistributedDrag::add_skin_slab_lean(BodySum& sum, const Slab& slab, Vec2 v, double w, Rot rot) const {
  // add_skin_drag without the Jacobian, for quadratic drag: each triangle's next half-vertex and
  // its middle point as the two lanes (their two square roots in one instruction); the
  // half-vertex it shares with the previous triangle comes from that triangle's first lane.
  if (slab.count == 0) return;
  const PointKinematics kinematics(rot, slab.drag.flow, v, w, settings_.rotational);
  const bool rotational = settings_.rotational;
  double q0 = sum.q[0], q1 = sum.q[1], q2 = sum.q[2];
  // One point's k |u| u and its moment, added as add_skin_point adds them.
  auto add = [&](double rx, double ry, double ux, double uy, double m, double k) {
    const double km = k * m;
    const double f_x = km * ux, f_y = km * uy;
    q0 += f_x;
    q1 += f_y;
    if (rotational) q2 += rx * f_y - ry * f_x;
  };
  const SkinTriangle* t = skin_.data() + slab.first;
  const TwoPoints first = kinematics.at(t[0].half_vertex, t[0].half_vertex);
  double ax = first.rx[0], ay = first.ry[0], aux = first.ux[0], auy = first.uy[0];
  double am = std::sqrt(aux * aux + auy * auy);  // length(u)
  for (std::uint32_t j = 0; j < slab.count; ++j) {
    const Vec2 next = j + 1 < slab.count ? t[j + 1].half_vertex : t[0].half_vertex;
    const TwoPoints p = kinematics.at(next, t[j].middle);  // lane 0: b, lane 1: the middle
    const Pair m = sqrt_of(p.ux * p.ux + p.uy * p.uy);      // |u|
    const double k = t[j].weight;
    add(ax, ay, aux, auy, am, k);
    add(p.rx[0], p.ry[0], p.ux[0], p.uy[0], m[0], k);
    add(p.rx[1], p.ry[1], p.ux[1], p.uy[1], m[1], k);
    ax = p.rx[0], ay = p.ry[0], aux = p.ux[0], auy = p.uy[0], am = m[0];
  }
  sum.q = {q0, q1, q2};
}

template <class F>
void DistributedDrag::for_entries(const ForceSums& sums, std::size_t grain, F&& f) const {
  if (!calm_) {
    thread_pool().for_blocks(entries_.size(), grain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        if (!passed(i)) f(i);
    });
    return;
  }
  // Still water and air: an entry whose body is at rest is one adds_nothing skips, so visiting
  // the moving bodies alone gives the same sums to the bit (each entry writes its own body).
  thread_pool().for_blocks(sums.stirred.size(), grain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const auto body = static_cast<std::size_t>(sums.stirred[k]);
      if (body >= entry_of_body_.size() || entry_of_body_[body] < 0) continue;
      const auto i = static_cast<std::size_t>(entry_of_body_[body]);
      if (!passed(i)) f(i);
    }
  });
}

bool DistributedDrag::add_rate_bound(const BodyStatesView& s, ForceSums& sums) const {
  if (grid_) {
    // |u| <= |slab flow - v| + |grid's flow| + |w| |r|: the grid's largest speed bounds its part.
    const double extra = grid_->max_speed();
    thread_pool().for_blocks(entries_.size(), 2048, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const Entry& e = entries_[i];
        const Vec2 v = s.velocity[e.body];
        const double w = s.angular_velocity[e.body];
        for (std::uint32_t k = 0; k < e.slab_count; ++k) {
          const Slab& slab = slabs_[e.first_slab + k];
          add_slab_bound(sums.rate_bound[e.body], slab.moments, slab.drag.flow, v, w, extra);
        }
      }
    });
    return true;
  }
  if (!lanes_packed_) pack_lanes();
  if (!lanes_direct(sums)) {
    for_entries(sums, 2048, [&](std::size_t i) { add_entry_bound(i, s, sums); });
    return true;
  }
  // Direct (lanes_direct): the lanes' floes from their groups (each body's one slab: the body
  // and its flow from the group, its moments from lane_moments_, in the groups' order, in place
  // of the entry's records), the rest entry by entry. Each body is written by one of the two
  // loops, with add_entry_bound's arithmetic.
  thread_pool().for_blocks(unlaned_.size(), 2048, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) add_entry_bound(unlaned_[k], s, sums);
  });
  thread_pool().for_blocks(groups_.size(), 512, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const LaneGroup& g = groups_[k];
      for (std::uint32_t l = 0; l < g.lanes; ++l) {
        const std::uint32_t body = g.body[l];
        const Vec2 v = s.velocity[body];
        const double w = s.angular_velocity[body];
        if (lane_adds_nothing(g, l, v, w)) continue;
        add_slab_bound(sums.rate_bound[body], lane_moments_[kLanes * k + l], {g.flow_x[l], g.flow_y[l]}, v, w);
      }
    }
  });
  return true;
}

void DistributedDrag::add_slab_bound(std::array<double, 2>& b, const std::array<double, 4>& m, Vec2 flow, Vec2 v,
                                     double w, double extra) const {
  constexpr double kRow = 1.0 + 1.4142135623730951;  // add_entry_bound says why
  if (settings_.reference_speed > 0.0) {
    b[0] += settings_.reference_speed * m[0];
    b[1] += settings_.rotational ? settings_.reference_speed * m[2] : 0.0;
    return;
  }
  const double du = length(flow - v) + extra;
  const double spin = settings_.rotational ? std::abs(w) : 0.0;
  b[0] += kRow * (du * m[0] + spin * m[1]);
  b[1] += settings_.rotational ? 2.0 * (du * m[2] + spin * m[3]) : 0.0;
}

void DistributedDrag::add_entry_bound(std::size_t i, const BodyStatesView& s, ForceSums& sums) const {
  // Per quadrature point, with m = |u| <= |V - v| + |w| |r| and k its weight (docs/model.md 2):
  //   skin  a = k (m I + u u^T / m):    |a_00| + |a_01| <= (1 + sqrt 2) |k| m,  g^T a g <= 2 |k| m |r|^2
  //   form  a = k (-(u.n) I - u n^T):   the same two bounds (|u.n| <= m, |n_x| + |n_y| <= sqrt 2)
  //   linearised (m -> U_ref):          |k| U_ref and |k| U_ref |r|^2
  // where g = k x r maps the spin to the point's velocity, so summing over the points bounds
  // the row sums of D's translational block and |D_ww| (forcing.cpp's stiffness test).
  const std::size_t body = quiet_[i].body;
  const Vec2 v = s.velocity[body];
  const double w = s.angular_velocity[body];
  if (adds_nothing(i, v, w)) return;  // adds nothing to D either
  std::array<double, 2>& b = sums.rate_bound[body];
  const Quiet& q = quiet_[i];
  if (q.single) {  // one slab (a floe): all from the packed record, no trip to the entry
    add_slab_bound(b, q.moments, q.flow, v, w);
    return;
  }
  const Entry& e = entries_[i];
  for (std::uint32_t k = 0; k < e.slab_count; ++k) {
    const Slab& slab = slabs_[e.first_slab + k];
    add_slab_bound(b, slab.moments, slab.drag.flow, v, w);
  }
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
  const Entry& e = entries_[i];
  for (std::uint32_t k = 0; k < e.slab_count; ++k) {
    const Vec2 flow = slabs_[e.first_slab + k].drag.flow;
    if (flow.x != v.x || flow.y != v.y) return false;
  }
  return true;
}

void DistributedDrag::add(const BodyStatesView& s, double, ForceSums& sums) const {
  // Entries are bodies, one each: blocks of them on the pool's threads write distinct bodies,
  // each in the same order as one thread would, so the sums do not depend on the threads.
  // The floes that take the lean path are left to the lanes (add_entry marks them), which then
  // add them four at a time: each body's sums are written once, by one of the two loops.
  // Direct (lanes_direct: a moving flow, or many bodies moving): add_entry visits the entries
  // without a lane alone, and each group finds its own lanes to add, as add_entry would mark
  // them (the floe adds something and needs no Jacobian).
  if (grid_) {  // a gridded medium: point by point, every entry (no lanes)
    std::atomic<bool> any{false};
    thread_pool().for_blocks(entries_.size(), 256, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        if (!passed(i) && add_entry_grid(i, s, sums) && !any.load(std::memory_order_relaxed))
          any.store(true, std::memory_order_relaxed);
    });
    if (any.load(std::memory_order_relaxed)) sums.any_jacobian = true;
    return;
  }
  if (!lanes_packed_) pack_lanes();
  const bool direct = lanes_direct(sums);
  std::atomic<bool> any_jacobian{false};
  auto entry = [&](std::size_t i) {
    if (add_entry(i, s, sums) && !any_jacobian.load(std::memory_order_relaxed))
      any_jacobian.store(true, std::memory_order_relaxed);
  };
  if (direct) {
    thread_pool().for_blocks(unlaned_.size(), 512, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) entry(unlaned_[k]);
    });
  } else {
    for_entries(sums, 512, entry);
    // The groups that add_entry left a lane to, in group order: the others add nothing (each
    // of their floes is at rest, or was added entry by entry), and each group writes its own
    // floes, so leaving them out changes no sum.
    groups_to_add_.clear();
    if (!groups_.empty())
      for (const std::int32_t body : sums.stirred) {
        const auto b = static_cast<std::size_t>(body);
        if (b >= entry_of_body_.size() || entry_of_body_[b] < 0) continue;
        const auto i = static_cast<std::size_t>(entry_of_body_[b]);
        if (in_lanes_[i] == 0 || group_listed_[group_of_entry_[i]] != 0) continue;
        group_listed_[group_of_entry_[i]] = 1;
        groups_to_add_.push_back(group_of_entry_[i]);
      }
    std::sort(groups_to_add_.begin(), groups_to_add_.end());
    for (const std::uint32_t k : groups_to_add_) group_listed_[k] = 0;
  }
  const std::size_t group_count = direct ? groups_.size() : groups_to_add_.size();
  thread_pool().for_blocks(group_count, 128, [&](std::size_t begin, std::size_t end) {
    for (std::size_t n = begin; n < end; ++n) {
      const LaneGroup& g = groups_[direct ? n : groups_to_add_[n]];
      unsigned mask = 0;
      for (std::uint32_t l = 0; l < g.lanes; ++l) {
        const std::uint32_t i = g.entry[l];
        bool in = false;
        if (direct) {
          // add_entry's choice for a floe of one slab and one flow: nothing where it moves with
          // the flow without spin (adds_nothing), the lanes without the Jacobian, else
          // add_entry's own path.
          const std::uint32_t body = g.body[l];
          const bool adds = !lane_adds_nothing(g, l, s.velocity[body], s.angular_velocity[body]);
          in = adds && sums.jacobian[body] == 0;
          if (adds && !in) entry(i);
        } else {
          in = in_lanes_[i] != 0;
          in_lanes_[i] = 0;
        }
        if (in) mask |= 1u << l;
      }
      if (mask != 0) add_group(g, mask, s, sums);
    }
  });
  if (any_jacobian.load(std::memory_order_relaxed)) sums.any_jacobian = true;
}

void DistributedDrag::attach_fields(const FlowFields& fields) {
  grid_ = medium_ == Medium::water ? fields.current.get() : fields.wind.get();
}

bool DistributedDrag::add_entry_grid(std::size_t i, const BodyStatesView& s, ForceSums& sums) const {
  const Entry& e = entries_[i];
  const Vec2 v = s.velocity[e.body], x = s.position[e.body];
  const double w = s.angular_velocity[e.body];
  const bool jacobian = sums.jacobian[e.body] != 0;
  const Rot rot = sums.rotation[e.body];
  BodySum sum = sums.load(e.body);
  for (std::uint32_t k = 0; k < e.slab_count; ++k) {
    const Slab& slab = slabs_[e.first_slab + k];
    // The slab's flow (the tides' change) plus the grid's at the point: 0 + V = V where the
    // grid alone drives it. The cell of the body's centroid serves the points inside it (most
    // floes lie within one cell); the others ask the grid.
    const FlowGrid::Cell cell = grid_->cell(x, slab.drag.depth);
    auto flow_at = [&](Vec2 r) {
      const Vec2 p = x + r;
      return slab.drag.flow + (cell.contains(p) ? cell.value(p) : grid_->at(p, slab.drag.depth));
    };
    if (kind_ == Kind::form)
      add_form_slab_at(sum, slab, v, w, rot, jacobian, flow_at);
    else
      add_skin_slab_at(sum, slab, v, w, rot, jacobian, flow_at);
  }
  sums.store(e.body, sum);
  return jacobian;
}

bool DistributedDrag::add_entry(std::size_t i, const BodyStatesView& s, ForceSums& sums) const {
  const std::size_t body = quiet_[i].body;
  const Vec2 v = s.velocity[body];
  const double w = s.angular_velocity[body];
  if (adds_nothing(i, v, w)) return false;
  const Entry& e = entries_[i];
  const bool jacobian = sums.jacobian[e.body] != 0;
  if (!jacobian && laned_[i] != 0) {  // quadratic drag on a floe, Q alone: four at a time (add)
    in_lanes_[i] = 1;
    return false;
  }
  const Rot rot = sums.rotation[e.body];
  BodySum sum = sums.load(e.body);
  for (std::uint32_t k = 0; k < e.slab_count; ++k) {
    const Slab& slab = slabs_[e.first_slab + k];
    if (!jacobian && settings_.reference_speed == 0.0)  // a floe of a drifting field: Q alone
      kind_ == Kind::form ? add_form_slab_lean(sum, slab, v, w, rot) : add_skin_slab_lean(sum, slab, v, w, rot);
    else if (kind_ == Kind::form)
      add_form_slab(sum, slab, v, w, rot, jacobian);
    else
      add_skin_slab(sum, slab, v, w, rot, jacobian);
  }
  sums.store(e.body, sum);
  return jacobian;
}

}  // namespace floedem
