#include "forcing/drag_pass.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <span>

#include "engine/prefetch.hpp"
#include "geometry/lane_isa.hpp"
#include "geometry/lanes4.hpp"
#include "parallel/thread_pool.hpp"

namespace floedem {

namespace {
using namespace lanes4;
constexpr int kLanes = DragPass::kLanes;
constexpr int kMaxTerms = DragPass::kMaxTerms;

// edge_points' Gauss points (drag.cpp): a + (1/2 -+ g) (b - a), formed as it forms them.
double gauss_first() { return 0.5 - gauss_offset(); }
double gauss_second() { return 0.5 + gauss_offset(); }

/// A point's force and moment, held until its term's turn to add (terms after the first).
struct Held {
  v4d x, y, t;
};
constexpr std::size_t kHeld = DragPass::kMaxCorners * 3 * (kMaxTerms - 1);  // 3 points an edge at most

struct PassIo {
  const Vec2* v;
  const double* w;
  const Rot* rot;
  std::array<double, 3>* q;
};

/// The end of pass_group: the later terms' points, each term in its turn and its points in
/// order (the first term's went straight into q), then each lane's sums to its body.
template <bool rotational, int kTerms, unsigned kForm>
FLOEDEM_LANES void finish_group(const DragPass::Shape& shape, const DragPass::Group& g, const PassIo& io,
                                unsigned mask, const Held* held, const std::uint32_t* base, std::uint32_t edges,
                                v4d q0, v4d q1, v4d q2) {
  const int terms = kTerms > 0 ? kTerms : shape.terms;
  auto is_form = [&](int t) { return kTerms > 0 ? ((kForm >> t) & 1u) != 0 : shape.form[static_cast<std::size_t>(t)]; };
#pragma GCC unroll 4
  for (int t = 1; t < terms; ++t) {
    const std::uint32_t n = edges * (is_form(t) ? 2 : 3);
    for (std::uint32_t k = 0; k < n; ++k) {
      const Held& h = held[base[t] + k];
      q0 += h.x;
      q1 += h.y;
      if (rotational) q2 += h.t;
    }
  }
  double out0[kLanes], out1[kLanes], out2[kLanes];
  store(out0, q0);
  store(out1, q1);
  store(out2, q2);
  for (int l = 0; l < kLanes; ++l)
    if (mask & (1u << l)) io.q[g.body[l]] = {out0[l], out1[l], out2[l]};
}

/// One group of four floes, every term of the run (drag_pass.hpp): the operations of
/// form_quad and skin_quad (drag_lanes.cpp), each point formed from the corners as edge_points and
/// area_points form it, turned into the world once for every term.
// kTerms > 0: the run's shape fixed at compile time (kForm: bit t set where term t is form
// drag), so that the loops over the terms unroll and their values stay in registers; 0: read
// from `shape`.
template <bool rotational, int kTerms, unsigned kForm>
FLOEDEM_LANES void pass_group(const DragPass::Shape& shape, const DragPass::Group& g, const DragPass::Slot* slot,
                              const PassIo& io, unsigned mask, v4d c0, v4d c1) {
  const int terms = kTerms > 0 ? kTerms : shape.terms;
  auto is_form = [&](int t) { return kTerms > 0 ? ((kForm >> t) & 1u) != 0 : shape.form[static_cast<std::size_t>(t)]; };
  const bool any_form = kTerms > 0 ? (kForm & ((1u << kTerms) - 1u)) != 0 : shape.any_form;
  const bool any_skin = kTerms > 0 ? (~kForm & ((1u << kTerms) - 1u)) != 0 : shape.any_skin;
  auto gather = [&](auto f) FLOEDEM_LANES_LAMBDA { return lanes(f(g.body[0]), f(g.body[1]), f(g.body[2]), f(g.body[3])); };
  const v4d c = gather([&](std::uint32_t b) { return io.rot[b].c; });
  const v4d s = gather([&](std::uint32_t b) { return io.rot[b].s; });
  const v4d vx = gather([&](std::uint32_t b) { return io.v[b].x; });
  const v4d vy = gather([&](std::uint32_t b) { return io.v[b].y; });
  const v4d w = gather([&](std::uint32_t b) { return io.w[b]; });
  const v4d neg_w = -w;
  const v4d none = splat(-0.0), zero = splat(0.0), half = splat(0.5);
  v4m count;
  std::memcpy(&count, g.count.data(), sizeof count);
  // Per term: its flow, and the lanes whose body moves with it without spin (the term adds
  // nothing there: lane_adds_nothing), which add -0.
  v4d fx[kMaxTerms]{}, fy[kMaxTerms]{};  // zeroed: GCC cannot see that only terms < `terms` are read
  v4m still[kMaxTerms]{};
#pragma GCC unroll 4
  for (int t = 0; t < terms; ++t) {
    fx[t] = load(g.flow_x[t].data());
    fy[t] = load(g.flow_y[t].data());
    still[t] = (v4m)(w == zero) & (v4m)(fx[t] == vx) & (v4m)(fy[t] == vy);
  }
  v4d q0 = gather([&](std::uint32_t b) { return io.q[b][0]; });
  v4d q1 = gather([&](std::uint32_t b) { return io.q[b][1]; });
  v4d q2 = gather([&](std::uint32_t b) { return io.q[b][2]; });
  // A body-frame point turned into the world (rot.apply) and the velocity there (v + w k x r).
  auto place = [&](v4d lx, v4d ly, v4d& rx, v4d& ry, v4d& px, v4d& py) FLOEDEM_LANES_LAMBDA {
    rx = c * lx - s * ly;
    ry = s * lx + c * ly;
    px = rotational ? vx + neg_w * ry : vx;
    py = rotational ? vy + w * rx : vy;
  };
  const std::uint32_t edges = g.slots - 1;
  // Where each later term's points wait: term by term, edge by edge, point by point.
  Held held[kHeld];
  std::uint32_t base[kMaxTerms] = {};
#pragma GCC unroll 4
  for (int t = 1, at = 0; t < terms; ++t) {
    base[t] = static_cast<std::uint32_t>(at);
    at += static_cast<int>(edges * (is_form(t) ? 2 : 3));
  }
  auto keep = [&](int t, std::uint32_t k, v4d f_x, v4d f_y, v4d tq) FLOEDEM_LANES_LAMBDA {
    if (t == 0) {
      q0 += f_x;
      q1 += f_y;
      if (rotational) q2 += tq;
    } else {
      held[base[t] + k] = {f_x, f_y, tq};
    }
  };
  // Skin: the half-vertex an edge shares with the one before (area_points' a / 2), carried:
  // its place, and per term its relative flow and |u|.
  v4d ax{}, ay{};
  v4d aux[kMaxTerms]{}, auy[kMaxTerms]{}, am[kMaxTerms]{};  // set for the skin terms when any_skin
  if (any_skin) {
    v4d px, py;
    place(half * load(slot[0].corner_x), half * load(slot[0].corner_y), ax, ay, px, py);
#pragma GCC unroll 4
    for (int t = 0; t < terms; ++t) {
      if (is_form(t)) continue;
      aux[t] = fx[t] - px;
      auy[t] = fy[t] - py;
      am[t] = sqrt4(aux[t] * aux[t] + auy[t] * auy[t]);
    }
  }
  for (std::uint32_t j = 0; j < edges; ++j) {
    // The slots a few edges on, asked for ahead of their loads (as drag.cpp's prefetch_ahead:
    // the step evicts them; the next group's follow this one's). A prefetch changes no value.
    prefetch_record(slot, j + 4);
    const DragPass::Slot& e = slot[j];
    const DragPass::Slot& next = slot[j + 1];
    const v4m past = v4m{} + static_cast<std::int64_t>(j) >= count;
    const v4d cx = load(e.corner_x), cy = load(e.corner_y), dx = load(next.corner_x), dy = load(next.corner_y);
    v4d r1x{}, r1y{}, p1x{}, p1y{}, r2x{}, r2y{}, p2x{}, p2y{}, nx{}, ny{};
    if (any_form) {  // the edge's two Gauss points and its normal
      const v4d ex = dx - cx, ey = dy - cy;
      place(cx + c0 * ex, cy + c0 * ey, r1x, r1y, p1x, p1y);
      place(cx + c1 * ex, cy + c1 * ey, r2x, r2y, p2x, p2y);
      const v4d nx0 = load(e.normal_x), ny0 = load(e.normal_y);
      nx = c * nx0 - s * ny0;
      ny = s * nx0 + c * ny0;
    }
    v4d bx{}, by{}, pbx{}, pby{}, mx{}, my{}, pmx{}, pmy{};
    if (any_skin) {  // the triangle's next half-vertex and its middle
      place(half * dx, half * dy, bx, by, pbx, pby);
      place(half * (cx + dx), half * (cy + dy), mx, my, pmx, pmy);
    }
#pragma GCC unroll 4
    for (int t = 0; t < terms; ++t) {
      if (is_form(t)) {
        // form_quad: -k (u.n) u where the flow meets the edge (u.n < 0), else -0.
        const v4d weight = -load(e.weight[t]);
        const v4m skip = past | still[t];
        auto point = [&](std::uint32_t p, v4d rx, v4d ry, v4d px, v4d py) FLOEDEM_LANES_LAMBDA {
          const v4d ux = fx[t] - px, uy = fy[t] - py;
          const v4d un = ux * nx + uy * ny;
          const v4d kun = weight * un;
          const v4m leaves = (v4m)(un >= zero) | skip;
          const v4d f_x = select(leaves, none, kun * ux), f_y = select(leaves, none, kun * uy);
          keep(t, 2 * j + p, f_x, f_y, select(leaves, none, rx * f_y - ry * f_x));
        };
        point(0, r1x, r1y, p1x, p1y);
        point(1, r2x, r2y, p2x, p2y);
      } else {
        // skin_quad: k |u| u at the shared half-vertex, the next one and the middle.
        const v4d weight = load(e.weight[t]);
        const v4m in = ~(past | still[t]);
        auto point = [&](std::uint32_t p, v4d rx, v4d ry, v4d ux, v4d uy, v4d m) FLOEDEM_LANES_LAMBDA {
          const v4d km = weight * m;
          const v4d f_x = km * ux, f_y = km * uy;
          keep(t, 3 * j + p, select(in, f_x, none), select(in, f_y, none), select(in, rx * f_y - ry * f_x, none));
        };
        const v4d bux = fx[t] - pbx, buy = fy[t] - pby, mux = fx[t] - pmx, muy = fy[t] - pmy;
        const v4d bm = sqrt4(bux * bux + buy * buy), mm = sqrt4(mux * mux + muy * muy);
        point(0, ax, ay, aux[t], auy[t], am[t]);
        point(1, bx, by, bux, buy, bm);
        point(2, mx, my, mux, muy, mm);
        aux[t] = bux, auy[t] = buy, am[t] = bm;
      }
    }
    if (any_skin) ax = bx, ay = by;
  }
  finish_group<rotational, kTerms, kForm>(shape, g, io, mask, held, base, edges, q0, q1, q2);
}

/// One group's rate bounds, term by term: DistributedDrag::add_slab_bound for quadratic drag
/// (linearised drag never shares a pass) in each lane, -0 where the body moves with the
/// term's flow without spin (lane_adds_nothing: the terms add nothing there).
FLOEDEM_LANES void bound(const DragPass::Shape& shape, const DragPass::Group& g, const DragPass::Moments& m,
                         const PassIo& io, std::array<double, 2>* rate_bound) {
  auto gather = [&](auto f) FLOEDEM_LANES_LAMBDA { return lanes(f(g.body[0]), f(g.body[1]), f(g.body[2]), f(g.body[3])); };
  const v4d vx = gather([&](std::uint32_t b) { return io.v[b].x; });
  const v4d vy = gather([&](std::uint32_t b) { return io.v[b].y; });
  const v4d w = gather([&](std::uint32_t b) { return io.w[b]; });
  v4d b0 = gather([&](std::uint32_t b) { return rate_bound[b][0]; });
  v4d b1 = gather([&](std::uint32_t b) { return rate_bound[b][1]; });
  const v4d none = splat(-0.0), zero = splat(0.0);
  const v4d row = splat(1.0 + 1.4142135623730951), two = splat(2.0);  // add_slab_bound's constants
  const v4d spin = shape.rotational ? abs(w) : zero;
  for (int t = 0; t < shape.terms; ++t) {
    const v4d fx = load(g.flow_x[static_cast<std::size_t>(t)].data()), fy = load(g.flow_y[static_cast<std::size_t>(t)].data());
    const v4m still = (v4m)(w == zero) & (v4m)(fx == vx) & (v4m)(fy == vy);
    const v4d dx = fx - vx, dy = fy - vy;
    const v4d du = sqrt4(dx * dx + dy * dy);  // length(flow - v)
    const v4d m0 = load(m.m[t][0]), m1 = load(m.m[t][1]), m2 = load(m.m[t][2]), m3 = load(m.m[t][3]);
    b0 += select(still, none, row * (du * m0 + spin * m1));
    b1 += select(still, none, shape.rotational ? two * (du * m2 + spin * m3) : zero);
  }
  double out0[kLanes], out1[kLanes];
  store(out0, b0);
  store(out1, b1);
  for (std::uint32_t l = 0; l < g.lanes; ++l) rate_bound[g.body[l]] = {out0[l], out1[l]};
}
void bound_baseline(const DragPass::Shape& shape, const DragPass::Group& g, const DragPass::Moments& m,
                    const PassIo& io, std::array<double, 2>* rate_bound) {
  bound(shape, g, m, io, rate_bound);
}

FLOEDEM_LANES void pass(const DragPass::Shape& shape, const DragPass::Group& g, const DragPass::Slot* slot,
                        const PassIo& io, unsigned mask) {
  const v4d c0 = splat(gauss_first()), c1 = splat(gauss_second());
  // Water form, water skin, air form, air skin (Forcing's order): a drifting field's floes.
  constexpr unsigned kFormSkinFormSkin = 0b0101;
  const bool four = shape.terms == 4 && shape.form[0] && !shape.form[1] && shape.form[2] && !shape.form[3];
  if (four)
    shape.rotational ? pass_group<true, 4, kFormSkinFormSkin>(shape, g, slot, io, mask, c0, c1)
                     : pass_group<false, 4, kFormSkinFormSkin>(shape, g, slot, io, mask, c0, c1);
  else
    shape.rotational ? pass_group<true, 0, 0>(shape, g, slot, io, mask, c0, c1)
                     : pass_group<false, 0, 0>(shape, g, slot, io, mask, c0, c1);
}
void pass_baseline(const DragPass::Shape& shape, const DragPass::Group& g, const DragPass::Slot* slot,
                   const PassIo& io, unsigned mask) {
  pass(shape, g, slot, io, mask);
}
#if defined(__x86_64__)
#define FLOEDEM_HAS_AVX2_PASS 1
[[gnu::target("avx2")]] void pass_avx2(const DragPass::Shape& shape, const DragPass::Group& g,
                                       const DragPass::Slot* slot, const PassIo& io, unsigned mask) {
  pass(shape, g, slot, io, mask);
}
[[gnu::target("avx2")]] void bound_avx2(const DragPass::Shape& shape, const DragPass::Group& g,
                                        const DragPass::Moments& m, const PassIo& io,
                                        std::array<double, 2>* rate_bound) {
  bound(shape, g, m, io, rate_bound);
}
[[gnu::target("avx2,avx512f,avx512vl")]] void bound_avx512(const DragPass::Shape& shape, const DragPass::Group& g,
                                                           const DragPass::Moments& m, const PassIo& io,
                                                           std::array<double, 2>* rate_bound) {
  bound(shape, g, m, io, rate_bound);
}
[[gnu::target("avx2,avx512f,avx512vl")]] void pass_avx512(const DragPass::Shape& shape, const DragPass::Group& g,
                                                          const DragPass::Slot* slot, const PassIo& io,
                                                          unsigned mask) {
  pass(shape, g, slot, io, mask);
}
#endif
}  // namespace

DragPass::DragPass(const std::vector<DistributedDrag*>& terms,
                   const std::function<const std::vector<Vec2>&(std::size_t)>& polygon)
    : terms_(terms.begin(), terms.end()) {
  if (terms_.size() < 2 || terms_.size() > static_cast<std::size_t>(kMaxTerms)) return;
  shape_.terms = static_cast<int>(terms_.size());
  shape_.rotational = terms_.front()->settings_.rotational;
  std::size_t bodies = 0;
  for (int t = 0; t < shape_.terms; ++t) {
    const DistributedDrag& d = *terms_[static_cast<std::size_t>(t)];
    // Quadratic drag with one rotational setting (linearised drag never takes the lanes).
    if (d.settings_.reference_speed > 0.0 || d.settings_.rotational != shape_.rotational) return;
    shape_.form[static_cast<std::size_t>(t)] = d.kind_ == DistributedDrag::Kind::form;
    shape_.any_form = shape_.any_form || shape_.form[static_cast<std::size_t>(t)];
    shape_.any_skin = shape_.any_skin || !shape_.form[static_cast<std::size_t>(t)];
    bodies = std::max(bodies, d.entry_of_body_.size());
  }
  const double g0 = gauss_first(), g1 = gauss_second();
  // A body the pass can take: one slab of scale 1 in every term, and each term's packed points
  // those the pass forms from its corners, to the bit.
  auto takes = [&](std::size_t body) {
    const std::vector<Vec2>& poly = polygon(body);
    const std::size_t n = poly.size();
    if (n < 3 || n > kMaxCorners) return false;
    const DistributedDrag::FormEdge* normals = nullptr;
    for (const DistributedDrag* d : terms_) {
      if (body >= d->entry_of_body_.size() || d->entry_of_body_[body] < 0) return false;
      const auto i = static_cast<std::size_t>(d->entry_of_body_[body]);
      if (d->entries_[i].slab_count != 1) return false;  // one slab (quadratic drag: checked above)
      const DistributedDrag::Slab& slab = d->slabs_[d->entries_[i].first_slab];
      if (!same_bits(slab.drag.scale, 1.0) || slab.count != n) return false;
      for (std::size_t k = 0; k < n; ++k) {
        const Vec2 a = poly[k], b = poly[(k + 1) % n];
        if (d->kind_ == DistributedDrag::Kind::form) {
          const DistributedDrag::FormEdge& e = d->form_[slab.first + k];
          const Vec2 first{a.x + g0 * (b.x - a.x), a.y + g0 * (b.y - a.y)};
          const Vec2 second{a.x + g1 * (b.x - a.x), a.y + g1 * (b.y - a.y)};
          const DistributedDrag::FormEdge& n0 = normals != nullptr ? normals[k] : e;
          if (!same_bits(e.first.x, first.x) || !same_bits(e.first.y, first.y) || !same_bits(e.second.x, second.x) ||
              !same_bits(e.second.y, second.y) || !same_bits(e.normal.x, n0.normal.x) ||
              !same_bits(e.normal.y, n0.normal.y))
            return false;
        } else {
          const DistributedDrag::SkinTriangle& tri = d->skin_[slab.first + k];
          if (!same_bits(tri.half_vertex.x, 0.5 * a.x) || !same_bits(tri.half_vertex.y, 0.5 * a.y) ||
              !same_bits(tri.middle.x, 0.5 * (a.x + b.x)) || !same_bits(tri.middle.y, 0.5 * (a.y + b.y)))
            return false;
        }
      }
      if (d->kind_ == DistributedDrag::Kind::form && normals == nullptr) normals = d->form_.data() + slab.first;
    }
    return true;
  };
  std::vector<std::uint32_t> taken;
  shared_.assign(bodies, 0);
  for (std::size_t b = 0; b < bodies; ++b)
    if (takes(b)) {
      taken.push_back(static_cast<std::uint32_t>(b));
      shared_[b] = 1;
    }
  floes_ = taken.size();
  // Groups as the terms' lanes make them (pack_lanes).
  auto corners = [&](std::uint32_t b) { return polygon(b).size(); };
  sort_in_lane_windows(taken, corners);
  for (std::size_t k = 0; k < taken.size(); k += kLanes) {
    Group g;
    g.lanes = static_cast<std::uint32_t>(std::min<std::size_t>(kLanes, taken.size() - k));
    std::size_t most = 0;
    for (std::uint32_t l = 0; l < g.lanes; ++l) most = std::max(most, corners(taken[k + l]));
    g.slots = static_cast<std::uint32_t>(most + 1);
    g.first = static_cast<std::uint32_t>(slots_.size());
    moments_.push_back(Moments{});
    slots_.resize(slots_.size() + g.slots, Slot{});
    for (std::uint32_t l = 0; l < kLanes; ++l) {
      const std::uint32_t body = taken[k + (l < g.lanes ? l : 0)];
      g.body[l] = body;
      if (l >= g.lanes) continue;  // read as lane 0, never stored
      const std::vector<Vec2>& poly = polygon(body);
      const std::size_t n = poly.size();
      g.count[l] = static_cast<std::int64_t>(n);
      for (std::size_t j = 0; j <= n; ++j) {
        Slot& o = slots_[g.first + j];
        o.corner_x[l] = poly[j % n].x;
        o.corner_y[l] = poly[j % n].y;
      }
      for (int t = 0; t < shape_.terms; ++t) {
        const DistributedDrag& d = *terms_[static_cast<std::size_t>(t)];
        const DistributedDrag::Slab& slab =
            d.slabs_[d.entries_[static_cast<std::size_t>(d.entry_of_body_[body])].first_slab];
        g.entry[static_cast<std::size_t>(t)][l] = static_cast<std::uint32_t>(d.entry_of_body_[body]);
        for (int j = 0; j < 4; ++j) moments_.back().m[t][j][l] = slab.moments[static_cast<std::size_t>(j)];
        g.flow_x[static_cast<std::size_t>(t)][l] = slab.drag.flow.x;
        g.flow_y[static_cast<std::size_t>(t)][l] = slab.drag.flow.y;
        for (std::size_t j = 0; j < n; ++j) {
          Slot& o = slots_[g.first + j];
          if (d.kind_ == DistributedDrag::Kind::form) {
            const DistributedDrag::FormEdge& e = d.form_[slab.first + j];
            o.normal_x[l] = e.normal.x;
            o.normal_y[l] = e.normal.y;
            o.weight[t][l] = e.weight;
          } else {
            o.weight[t][l] = d.skin_[slab.first + j].weight;
          }
        }
      }
    }
    groups_.push_back(g);
  }
  // From here on the terms leave these floes to the pass, and their lanes no longer hold them.
  for (DistributedDrag* d : terms) d->leave_to_pass(shared_);
  calm_ = std::all_of(terms_.begin(), terms_.end(), [](const DistributedDrag* d) { return d->calm_; });
  group_of_body_.assign(bodies, -1);
  for (std::size_t k = 0; k < groups_.size(); ++k)
    for (std::uint32_t l = 0; l < groups_[k].lanes; ++l) group_of_body_[groups_[k].body[l]] = static_cast<std::int32_t>(k);
  listed_.assign(groups_.size(), 0);
  if (!calm_)  // every group, every step (groups_to_visit)
    for (std::size_t k = 0; k < groups_.size(); ++k) visit_.push_back(static_cast<std::uint32_t>(k));
}

void DragPass::refresh_flows() {
  for (Group& g : groups_)
    for (int t = 0; t < shape_.terms; ++t) {
      const DistributedDrag& d = *terms_[static_cast<std::size_t>(t)];
      if (!d.flow_varies()) continue;
      const auto k = static_cast<std::size_t>(t);
      for (std::uint32_t l = 0; l < g.lanes; ++l) {
        const Vec2 flow = d.slabs_[d.entries_[g.entry[k][l]].first_slab].drag.flow;
        g.flow_x[k][l] = flow.x;
        g.flow_y[k][l] = flow.y;
      }
    }
}

std::span<const std::uint32_t> DragPass::groups_to_visit(const ForceSums& sums) const {
  // In still water and air (every term calm) a floe at rest adds exactly nothing in any term
  // (DistributedDrag::adds_nothing; the kernels add -0), so only the groups with a moving floe
  // are visited, in group order (the towing case's field: some 300 of 5 000 floes move).
  if (!calm_) return visit_;  // every group, listed once by the constructor
  visit_.clear();
  for (const std::int32_t body : sums.stirred) {
    const auto b = static_cast<std::size_t>(body);
    if (b >= group_of_body_.size() || group_of_body_[b] < 0) continue;
    const auto k = static_cast<std::size_t>(group_of_body_[b]);
    if (listed_[k] != 0) continue;
    listed_[k] = 1;
    visit_.push_back(static_cast<std::uint32_t>(k));
  }
  std::sort(visit_.begin(), visit_.end());
  for (const std::uint32_t k : visit_) listed_[k] = 0;
  return visit_;
}

void DragPass::add_rate_bound(const BodyStatesView& s, ForceSums& sums) const {
  // The terms bound the bodies they keep; here each shared floe's bound, term by term as the
  // terms' lanes would add it.
  for (const DistributedDrag* d : terms_) d->add_rate_bound(s, sums);
  const std::span<const std::uint32_t> visit = groups_to_visit(sums);
  const PassIo io{s.velocity.data(), s.angular_velocity.data(), sums.rotation.data(), sums.q.data()};
  thread_pool().for_blocks(visit.size(), 512, [&](std::size_t begin, std::size_t end) {
    for (std::size_t n = begin; n < end; ++n) {
      const std::size_t k = visit[n];
      switch (lane_isa()) {
#ifdef FLOEDEM_HAS_AVX2_PASS
        case LaneIsa::avx512: bound_avx512(shape_, groups_[k], moments_[k], io, sums.rate_bound.data()); break;
        case LaneIsa::avx2: bound_avx2(shape_, groups_[k], moments_[k], io, sums.rate_bound.data()); break;
#endif
        default: bound_baseline(shape_, groups_[k], moments_[k], io, sums.rate_bound.data());
      }
    }
  });
}

void DragPass::add(const BodyStatesView& s, double time, ForceSums& sums) const {
  // The terms add the bodies they keep (no body is added by both), then the shared floes here.
  for (const DistributedDrag* d : terms_) d->add(s, time, sums);
  const std::span<const std::uint32_t> visit = groups_to_visit(sums);
  const PassIo io{s.velocity.data(), s.angular_velocity.data(), sums.rotation.data(), sums.q.data()};
  std::atomic<bool> any_jacobian{false};
  thread_pool().for_blocks(visit.size(), 128, [&](std::size_t begin, std::size_t end) {
    for (std::size_t n = begin; n < end; ++n) {
      const Group& g = groups_[visit[n]];
      unsigned mask = 0;  // the lanes whose body takes Q alone (as the terms' lanes choose)
      for (std::uint32_t l = 0; l < g.lanes; ++l) {
        if (sums.jacobian[g.body[l]] == 0) {
          mask |= 1u << l;
          continue;
        }
        // A floe that needs the Jacobian: each term's own path (add_entry), in term order.
        for (int t = 0; t < shape_.terms; ++t)
          if (terms_[static_cast<std::size_t>(t)]->add_entry(g.entry[static_cast<std::size_t>(t)][l], s, sums))
            any_jacobian.store(true, std::memory_order_relaxed);
      }
      if (mask == 0) continue;
      const Slot* slot = slots_.data() + g.first;
      switch (lane_isa()) {
#ifdef FLOEDEM_HAS_AVX2_PASS
        case LaneIsa::avx512: pass_avx512(shape_, g, slot, io, mask); break;
        case LaneIsa::avx2: pass_avx2(shape_, g, slot, io, mask); break;
#endif
        default: pass_baseline(shape_, g, slot, io, mask);
      }
    }
  });
  if (any_jacobian.load(std::memory_order_relaxed)) sums.any_jacobian = true;
}

}  // namespace floedem
