#include "forcing/flow_grid.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "io/netcdf_grid.hpp"

namespace floedem {

namespace {
/// The cell of `axis` that holds x (clamped to the axis) and x's weight within it; `outside`
/// set when x is off the axis.
std::size_t locate(const std::vector<double>& axis, double x, double& weight, bool& outside) {
  if (axis.size() < 2) {
    weight = 0.0;
    return 0;
  }
  if (!(x >= axis.front() && x <= axis.back())) {
    outside = true;
    x = std::clamp(x, axis.front(), axis.back());  // NaN: the first
    if (std::isnan(x)) x = axis.front();
  }
  std::size_t i = static_cast<std::size_t>(std::upper_bound(axis.begin(), axis.end(), x) - axis.begin());
  i = std::clamp<std::size_t>(i, 1, axis.size() - 1) - 1;
  weight = (x - axis[i]) / (axis[i + 1] - axis[i]);
  return i;
}

/// a + w (b - a): exact where a == b, so that a field constant in space, depth or time gives its
/// value to the bit.
inline double mix(double a, double b, double w) { return a + w * (b - a); }
}  // namespace

FlowGrid::FlowGrid(const FlowGridSpec& spec) : spec_(spec), file_(std::make_unique<NetcdfSlices>(spec)) {}

FlowGrid::~FlowGrid() = default;

const FlowGrid::Slice& FlowGrid::slice(std::size_t k) {
  for (Slice& s : slices_)
    if (s.index == k) return s;
  // Replace the slot that holds neither k nor the slice the step still needs (the one before).
  Slice& s = (before_ == &slices_[0]) ? slices_[1] : slices_[0];
  file_->read(k, s.u, s.v);
  s.index = k;
  return s;
}

void FlowGrid::prepare(double t) {
  const std::vector<double>& time = spec_.time;
  std::size_t k = 0;
  if (time.size() >= 2) {
    k = static_cast<std::size_t>(std::upper_bound(time.begin(), time.end(), t) - time.begin());
    k = std::clamp<std::size_t>(k, 1, time.size() - 1) - 1;
  }
  const std::size_t next = std::min(k + 1, time.size() - 1);
  // Keep the slot of a slice that stays (k, or k + 1 becoming k) and fill the other.
  before_ = nullptr;
  for (Slice& s : slices_)
    if (s.index == k) before_ = &s;
  if (!before_) before_ = &slice(k);
  after_ = &slice(next);
  weight_ = next == k ? 0.0 : (t - time[k]) / (time[next] - time[k]);
  span_ = next == k ? 1.0 : time[next] - time[k];
  // The largest speed of the two slices bounds every value between them (each is a convex
  // blend of grid values): found again only when the slices change.
  if (before_->index != speed_of_[0] || after_->index != speed_of_[1]) {
    speed_of_[0] = before_->index;
    speed_of_[1] = after_->index;
    max_speed_ = 0.0;
    for (const Slice* s : {before_, after_})
      for (std::size_t i = 0; i < s->u.size(); ++i)
        if (std::isfinite(s->u[i]) && std::isfinite(s->v[i])) max_speed_ = std::max(max_speed_, std::hypot(s->u[i], s->v[i]));
  }
  time_ = t;
}

double FlowGrid::corner_value(std::size_t base0, std::size_t base1, double wz, double wt, std::size_t index,
                              int comp) const {
  // One corner: blended in time, then between the two depth levels around the depth.
  const std::vector<double>& a = comp == 0 ? before_->u : before_->v;
  const std::vector<double>& b = comp == 0 ? after_->u : after_->v;
  const double upper = mix(a[base0 + index], b[base0 + index], wt);
  if (base1 == base0) return upper;
  return mix(upper, mix(a[base1 + index], b[base1 + index], wt), wz);
}

FlowGrid::Cell FlowGrid::cell(Vec2 p, double depth) const { return cell_at(p, depth, weight_); }

FlowGrid::Cell FlowGrid::cell_at(Vec2 p, double depth, double wt) const {
  const std::size_t nx = spec_.x.size(), ny = spec_.y.size();
  bool outside = false;
  double wx = 0.0, wy = 0.0, wz = 0.0;
  const std::size_t i = locate(spec_.x, p.x, wx, outside), j = locate(spec_.y, p.y, wy, outside);
  if (outside && off_grid_.fetch_add(1, std::memory_order_relaxed) == 0) {
    off_x_.store(p.x, std::memory_order_relaxed);
    off_y_.store(p.y, std::memory_order_relaxed);
  }
  bool below = false;  // beyond the depth axis: its first or last level, which is allowed
  const std::size_t l = spec_.depth.empty() ? 0 : locate(spec_.depth, depth, wz, below);
  const std::size_t base0 = l * nx * ny, base1 = spec_.depth.empty() ? base0 : (l + 1) * nx * ny;
  Cell c{spec_.x[i], spec_.x[i + 1], spec_.y[j], spec_.y[j + 1], {}, {}, {}, {}};
  Vec2* corners[4] = {&c.c00, &c.c10, &c.c01, &c.c11};
  const std::size_t index[4] = {j * nx + i, j * nx + i + 1, (j + 1) * nx + i, (j + 1) * nx + i + 1};
  bool missing = false;
  for (int k = 0; k < 4; ++k) {
    *corners[k] = {corner_value(base0, base1, wz, wt, index[k], 0), corner_value(base0, base1, wz, wt, index[k], 1)};
    missing = missing || !std::isfinite(corners[k]->x) || !std::isfinite(corners[k]->y);
  }
  if (missing) {
    if (no_value_.fetch_add(1, std::memory_order_relaxed) == 0) {
      off_x_.store(p.x, std::memory_order_relaxed);
      off_y_.store(p.y, std::memory_order_relaxed);
    }
    c.c00 = c.c10 = c.c01 = c.c11 = {};
  }
  if (outside) c.x0 = c.x1 = c.y0 = c.y1 = std::nan("");  // contains() nothing: each point asks at()
  return c;
}

Vec2 FlowGrid::Cell::value(Vec2 p) const {
  const double wx = x1 > x0 ? (p.x - x0) / (x1 - x0) : 0.0, wy = y1 > y0 ? (p.y - y0) / (y1 - y0) : 0.0;
  return {mix(mix(c00.x, c10.x, wx), mix(c01.x, c11.x, wx), wy), mix(mix(c00.y, c10.y, wx), mix(c01.y, c11.y, wx), wy)};
}

Vec2 FlowGrid::at(Vec2 p, double depth) const { return at_weight(p, depth, weight_); }

Vec2 FlowGrid::at_weight(Vec2 p, double depth, double wt) const {
  const Cell c = cell_at(p, depth, wt);
  if (!c.contains(p)) {  // off the grid (noted by cell_at): the nearest point on it
    const Vec2 q{std::clamp(p.x, spec_.x.front(), spec_.x.back()), std::clamp(p.y, spec_.y.front(), spec_.y.back())};
    return cell_at(q, depth, wt).value(q);
  }
  return c.value(p);
}

Vec2 FlowGrid::rate_at(Vec2 p, double depth) const {
  if (after_ == before_) return {};
  // (V(t_1) - V(t_0)) / (t_1 - t_0), the two slices around the prepared time.
  return (1.0 / span_) * (at_weight(p, depth, 1.0) - at_weight(p, depth, 0.0));
}

std::string FlowGrid::take_problem() {
  const int off = off_grid_.exchange(0), none = no_value_.exchange(0);
  if (off == 0 && none == 0) return "";
  std::ostringstream o;
  o << "at t = " << time_ << " s a body's point (" << off_x_.load() << ", " << off_y_.load() << ") m is "
    << (off > 0 ? "off the grid, which spans x " : "on a fill value of the grid (x ")
    << "[" << spec_.x.front() << ", " << spec_.x.back() << "], y [" << spec_.y.front() << ", " << spec_.y.back()
    << "]" << (off > 0 ? "" : ")") << "; allowed a grid that holds a value wherever the bodies go";
  return o.str();
}

}  // namespace floedem
