#include "forcing/drag.hpp"

#include <algorithm>
#include <cstring>

#include "engine/prefetch.hpp"
#include "geometry/lane_isa.hpp"
#include "geometry/lanes4.hpp"

// The drag terms' four-lane kernels (DistributedDrag::add's lean path for one-slab floes): the
// lanes' layout (pack_lanes) and one group's sums (add_group), apart from the scalar rules in
// drag.cpp whose operations they repeat in order.

namespace floedem {
namespace {
// Four floes side by side: lane l of every vector holds a floe of its own, which takes the
// scalar rule's operations (add_form_slab_lean, add_skin_slab_lean in drag.cpp) in their order on its
// own points, so each floe's sums are those of the point-by-point rule to the bit (IEEE
// arithmetic rounds each operation the same in a lane as alone; no fused multiply-add,
// -ffp-contract=off). A lane past its floe's last edge or triangle adds -0 (x + (-0) = x for
// every x). One floe's sums are chains of dependent additions (three per point); four floes
// give the core four chains and a quarter of the instructions per point.
// Four doubles in one vector (geometry/lanes4.hpp): two SSE2 registers on the x86-64
// baseline, one AVX register in the AVX2 and AVX-512 builds (picked at run time, as the
// coloured sweeps' builds).
using namespace lanes4;
constexpr int kQuad = 4;
static_assert(sizeof(v4d) == sizeof(double) * kQuad);

// The slots of a few edges or triangles on, asked for ahead of their loads: in the 16k field's
// step a drag term's slots (about 5 MB) come back from memory each step, after the rest of the
// step has moved them out of cache, and the loop's first load of each slot waited for them.
// The next group's slots follow this one's, so
// near a group's end this fetches the next one's first. A prefetch changes no value.
// BM_DragQuadrature, whose slots stay in cache between calls, does not show the gain.
template <class Slot>
FLOEDEM_LANES void prefetch_ahead(const Slot* slot, std::uint32_t j) {
  constexpr std::uint32_t kAhead = 4;  // slots
  prefetch_record(slot, std::size_t{j} + kAhead);
}

/// Where the four floes' state is (their bodies' entries in the state and the sums), and
/// their sums out, lane by lane.
struct LaneIo {
  const Vec2* v;
  const double* w;
  const Rot* rot;
  const std::array<double, 3>* q;
  std::size_t body[kQuad];
  double q0[kQuad], q1[kQuad], q2[kQuad];  // out
  template <class F>
  FLOEDEM_LANES v4d gather(F&& f) const {
    return lanes(f(body[0]), f(body[1]), f(body[2]), f(body[3]));
  }
};

/// A point's kinematics in four lanes: PointKinematics::at's operations.
struct LaneKinematics {
  v4d c, s, fx, fy, vx, vy, w, neg_w;
  template <class Group>
  LaneKinematics(const LaneIo& io, const Group& g)
      : c(io.gather([&](std::size_t b) { return io.rot[b].c; })),
        s(io.gather([&](std::size_t b) { return io.rot[b].s; })),
        fx(load(g.flow_x.data())),
        fy(load(g.flow_y.data())),
        vx(io.gather([&](std::size_t b) { return io.v[b].x; })),
        vy(io.gather([&](std::size_t b) { return io.v[b].y; })),
        w(io.gather([&](std::size_t b) { return io.w[b]; })),
        neg_w(-w) {}
  template <bool rotational>
  FLOEDEM_LANES void at(v4d lx, v4d ly, v4d& rx, v4d& ry, v4d& ux, v4d& uy) const {
    rx = c * lx - s * ly;  // rot.apply
    ry = s * lx + c * ly;
    ux = rotational ? fx - (vx + neg_w * ry) : fx - vx;
    uy = rotational ? fy - (vy + w * rx) : fy - vy;
  }
};

// add_form_slab_lean, four floes at once.
template <bool rotational, class Group, class Slot>
FLOEDEM_LANES void form_quad(LaneIo& io, const Group& g, const Slot* slot) {
  const LaneKinematics k(io, g);
  const v4d none = splat(-0.0), zero = splat(0.0);
  v4m count;
  std::memcpy(&count, g.count.data(), sizeof count);
  v4d q0 = io.gather([&](std::size_t b) { return io.q[b][0]; });
  v4d q1 = io.gather([&](std::size_t b) { return io.q[b][1]; });
  v4d q2 = io.gather([&](std::size_t b) { return io.q[b][2]; });
  for (std::uint32_t j = 0; j < g.slots; ++j) {
    prefetch_ahead(slot, j);
    const Slot& e = slot[j];
    const v4d nx0 = load(e.normal_x), ny0 = load(e.normal_y);
    const v4d nx = k.c * nx0 - k.s * ny0, ny = k.s * nx0 + k.c * ny0;  // rot.apply(normal)
    const v4m past = v4m{} + static_cast<std::int64_t>(j) >= count;
    const v4d weight = -load(e.weight);
    auto point = [&](v4d lx, v4d ly) FLOEDEM_LANES_LAMBDA {
      v4d rx, ry, ux, uy;
      k.template at<rotational>(lx, ly, rx, ry, ux, uy);
      const v4d un = ux * nx + uy * ny;
      const v4d kun = weight * un;  // -k u.n
      const v4m leaves = (v4m)(un >= zero) | past;
      const v4d f_x = select(leaves, none, kun * ux), f_y = select(leaves, none, kun * uy);
      q0 += f_x;
      q1 += f_y;
      if (rotational) q2 += select(leaves, none, rx * f_y - ry * f_x);  // cross(r, f)
    };
    point(load(e.first_x), load(e.first_y));
    point(load(e.second_x), load(e.second_y));
  }
  store(io.q0, q0);
  store(io.q1, q1);
  store(io.q2, q2);
}

// add_skin_slab_lean, four floes at once.
template <bool rotational, class Group, class Slot>
FLOEDEM_LANES void skin_quad(LaneIo& io, const Group& g, const Slot* slot) {
  const LaneKinematics k(io, g);
  const v4d none = splat(-0.0);
  v4m count;
  std::memcpy(&count, g.count.data(), sizeof count);
  v4d q0 = io.gather([&](std::size_t b) { return io.q[b][0]; });
  v4d q1 = io.gather([&](std::size_t b) { return io.q[b][1]; });
  v4d q2 = io.gather([&](std::size_t b) { return io.q[b][2]; });
  // One point's k |u| u and its moment, as add_skin_point adds them (-0 past the floe's end).
  auto add = [&](v4m in, v4d rx, v4d ry, v4d ux, v4d uy, v4d m, v4d weight) FLOEDEM_LANES_LAMBDA {
    const v4d km = weight * m;
    const v4d f_x = km * ux, f_y = km * uy;
    q0 += select(in, f_x, none);
    q1 += select(in, f_y, none);
    if (rotational) q2 += select(in, rx * f_y - ry * f_x, none);
  };
  v4d ax, ay, aux, auy;
  k.template at<rotational>(load(g.start_x.data()), load(g.start_y.data()), ax, ay, aux, auy);
  v4d am = sqrt4(aux * aux + auy * auy);  // length(u)
  for (std::uint32_t j = 0; j < g.slots; ++j) {
    prefetch_ahead(slot, j);
    const Slot& t = slot[j];
    const v4m in = v4m{} + static_cast<std::int64_t>(j) < count;
    v4d bx, by, bux, buy, mx, my, mux, muy;
    k.template at<rotational>(load(t.next_x), load(t.next_y), bx, by, bux, buy);
    k.template at<rotational>(load(t.middle_x), load(t.middle_y), mx, my, mux, muy);
    const v4d bm = sqrt4(bux * bux + buy * buy), mm = sqrt4(mux * mux + muy * muy);
    const v4d weight = load(t.weight);
    add(in, ax, ay, aux, auy, am, weight);
    add(in, bx, by, bux, buy, bm, weight);
    add(in, mx, my, mux, muy, mm, weight);
    ax = bx, ay = by, aux = bux, auy = buy, am = bm;
  }
  store(io.q0, q0);
  store(io.q1, q1);
  store(io.q2, q2);
}

// One group's sums: form or skin drag, with or without the torque (the term's settings).
template <class Group, class FormSlot, class SkinSlot>
FLOEDEM_LANES void quad(LaneIo& io, const Group& g, const FormSlot* form, const SkinSlot* skin, bool rotational) {
  if (form != nullptr)
    rotational ? form_quad<true>(io, g, form) : form_quad<false>(io, g, form);
  else
    rotational ? skin_quad<true>(io, g, skin) : skin_quad<false>(io, g, skin);
}
template <class Group, class FormSlot, class SkinSlot>
void quad_baseline(LaneIo& io, const Group& g, const FormSlot* form, const SkinSlot* skin, bool rotational) {
  quad(io, g, form, skin, rotational);
}
#if defined(__x86_64__)
#define FLOEDEM_HAS_AVX2_DRAG 1
template <class Group, class FormSlot, class SkinSlot>
[[gnu::target("avx2")]] void quad_avx2(LaneIo& io, const Group& g, const FormSlot* form, const SkinSlot* skin,
                                       bool rotational) {
  quad(io, g, form, skin, rotational);
}
// AVX-512's 32 vector registers (for the same 4-lane vectors) spare the AVX2 build's spills.
template <class Group, class FormSlot, class SkinSlot>
[[gnu::target("avx2,avx512f,avx512vl")]] void quad_avx512(LaneIo& io, const Group& g, const FormSlot* form,
                                                          const SkinSlot* skin, bool rotational) {
  quad(io, g, form, skin, rotational);
}
#endif
}  // namespace

void DistributedDrag::pack_lanes() const {
  groups_.clear();
  lane_moments_.clear();
  form_lanes_.clear();
  skin_lanes_.clear();
  in_lanes_.assign(entries_.size(), 0);
  laned_.assign(entries_.size(), 0);
  group_of_entry_.assign(entries_.size(), 0);
  unlaned_.clear();
  lanes_packed_ = true;
  auto list_unlaned = [&] {
    for (std::size_t i = 0; i < entries_.size(); ++i)
      if (laned_[i] == 0 && !passed(i)) unlaned_.push_back(static_cast<std::uint32_t>(i));
  };
  if (settings_.reference_speed > 0.0) {  // linearised drag never takes the lean path
    list_unlaned();
    return;
  }
  // The entries of one slab (floes), in windows of 64 in entry order (bodies near in memory),
  // each window sorted by its entries' points so that a group's lanes end about together.
  std::vector<std::uint32_t> single;
  for (std::size_t i = 0; i < entries_.size(); ++i)
    if (entries_[i].slab_count == 1 && !passed(i)) single.push_back(static_cast<std::uint32_t>(i));
  auto points = [&](std::uint32_t i) { return slabs_[entries_[i].first_slab].count; };
  sort_in_lane_windows(single, points);
  for (std::size_t k = 0; k < single.size(); k += kLanes) {
    LaneGroup g;
    lane_moments_.resize(lane_moments_.size() + kLanes);
    g.lanes = static_cast<std::uint32_t>(std::min<std::size_t>(kLanes, single.size() - k));
    for (std::uint32_t l = 0; l < g.lanes; ++l) g.slots = std::max(g.slots, points(single[k + l]));
    g.first = static_cast<std::uint32_t>(kind_ == Kind::form ? form_lanes_.size() : skin_lanes_.size());
    if (kind_ == Kind::form)
      form_lanes_.resize(form_lanes_.size() + g.slots, FormSlot{});
    else
      skin_lanes_.resize(skin_lanes_.size() + g.slots, SkinSlot{});
    for (std::uint32_t l = 0; l < kLanes; ++l) {
      const std::uint32_t i = single[k + (l < g.lanes ? l : 0)];
      g.entry[l] = i;
      g.body[l] = static_cast<std::uint32_t>(entries_[i].body);
      if (l >= g.lanes) continue;  // read as lane 0, never stored
      laned_[i] = 1;
      group_of_entry_[i] = static_cast<std::uint32_t>(groups_.size());
      const Slab& slab = slabs_[entries_[i].first_slab];
      lane_moments_[kLanes * groups_.size() + l] = slab.moments;
      g.count[l] = slab.count;
      g.flow_x[l] = slab.drag.flow.x;
      g.flow_y[l] = slab.drag.flow.y;
      for (std::uint32_t j = 0; j < slab.count; ++j) {
        if (kind_ == Kind::form) {
          const FormEdge& e = form_[slab.first + j];
          FormSlot& o = form_lanes_[g.first + j];
          o.first_x[l] = e.first.x, o.first_y[l] = e.first.y;
          o.second_x[l] = e.second.x, o.second_y[l] = e.second.y;
          o.normal_x[l] = e.normal.x, o.normal_y[l] = e.normal.y;
          o.weight[l] = e.weight;
        } else {
          const SkinTriangle* t = skin_.data() + slab.first;
          const Vec2 next = j + 1 < slab.count ? t[j + 1].half_vertex : t[0].half_vertex;
          SkinSlot& o = skin_lanes_[g.first + j];
          o.next_x[l] = next.x, o.next_y[l] = next.y;
          o.middle_x[l] = t[j].middle.x, o.middle_y[l] = t[j].middle.y;
          o.weight[l] = t[j].weight;
          if (j == 0) g.start_x[l] = t[0].half_vertex.x, g.start_y[l] = t[0].half_vertex.y;
        }
      }
    }
    groups_.push_back(g);
  }
  group_listed_.assign(groups_.size(), 0);
  list_unlaned();
}

void DistributedDrag::add_group(const LaneGroup& g, unsigned mask, const BodyStatesView& s, ForceSums& sums) const {
  LaneIo io{s.velocity.data(), s.angular_velocity.data(), sums.rotation.data(), sums.q.data(), {}, {}, {}, {}};
  for (int l = 0; l < kLanes; ++l) io.body[l] = g.body[l];
  const bool rotational = settings_.rotational;
  // The group's slots: in form_lanes_ for form drag, in skin_lanes_ for skin drag (the other empty).
  const FormSlot* form = kind_ == Kind::form ? form_lanes_.data() + g.first : nullptr;
  const SkinSlot* skin = kind_ == Kind::skin ? skin_lanes_.data() + g.first : nullptr;
  switch (lane_isa()) {
#ifdef FLOEDEM_HAS_AVX2_DRAG
    case LaneIsa::avx512: quad_avx512(io, g, form, skin, rotational); break;
    case LaneIsa::avx2: quad_avx2(io, g, form, skin, rotational); break;
#endif
    default: quad_baseline(io, g, form, skin, rotational);
  }
  for (int l = 0; l < kLanes; ++l)
    if (mask & (1u << l)) sums.q[io.body[l]] = {io.q0[l], io.q1[l], io.q2[l]};
}

}  // namespace floedem
