#include "solver/coloured_sweeps.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "engine/prefetch.hpp"
#include "geometry/lane_isa.hpp"
#include "geometry/lanes4.hpp"
#include "parallel/thread_pool.hpp"
#include "solver/local_law.hpp"
#include "solver/sweep_row.hpp"
#include "solver/sweep_schedule.hpp"

// The conditions each point's local solve meets, and the Delassus block, are stated in
// contact_solver.cpp; the local solve is local_law (local_law.hpp), the one the sweeps in pair
// order make, on four lanes.

namespace floedem {

namespace {

// Four doubles in one vector (geometry/lanes4.hpp): a bundle's four manifolds, lane by lane.
using namespace lanes4;
static_assert(sizeof(v4d) == sizeof(double) * kBundleLanes);

// The velocities of the bundle's bodies on one side, held in registers over its points.
struct Side {
  v4d vx, vy, w;
};

FLOEDEM_LANES Side gather(const std::int32_t* body, const Vec2* v, const double* w) {
  static_assert(kBundleLanes == 4);
  return {lanes(v[body[0]].x, v[body[1]].x, v[body[2]].x, v[body[3]].x),
          lanes(v[body[0]].y, v[body[1]].y, v[body[2]].y, v[body[3]].y),
          lanes(w[body[0]], w[body[1]], w[body[2]], w[body[3]])};
}

// Writes back the lanes whose body moves (as apply_impulse: a fixed or towed body, and an
// empty lane, is never written; the same fixed body may be read by islands on other threads).
FLOEDEM_LANES void scatter(const std::int32_t* body, const double* inv_mass, const Side& s, Vec2* v, double* w) {
  for (int l = 0; l < kBundleLanes; ++l) {
    if (inv_mass[l] == 0.0) continue;
    v[body[l]] = {s.vx[l], s.vy[l]};
    w[body[l]] = s.w[l];
  }
}

// apply_impulse, lane by lane: P = (px, py) on b, -P on a.
FLOEDEM_LANES void apply(const SweepBundle& b, const BundlePoint& p, v4d px, v4d py, Side& a_side, Side& b_side) {
  const v4d ma = load(b.ma), ia = load(b.ia), mb = load(b.mb), ib = load(b.ib);
  a_side.vx = a_side.vx - ma * px;
  a_side.vy = a_side.vy - ma * py;
  a_side.w = a_side.w - ia * (load(p.rax) * py - load(p.ray) * px);
  b_side.vx = b_side.vx + mb * px;
  b_side.vy = b_side.vy + mb * py;
  b_side.w = b_side.w + ib * (load(p.rbx) * py - load(p.rby) * px);
}

// A point's Delassus block and the local solve's reciprocals, lane by lane, made as the point is
// swept rather than stored in its bundle: a bundle is 768 bytes instead of 1 280, and the sweeps
// stream every bundle ten times a step (out of cache at 16k floes, from memory at 100k). The
// block is delassus_block (contact_solver.hpp), prepare_contact's own, on the same lever arms,
// normal and inverse masses, and each reciprocal is correctly rounded, so every impulse is the
// same to the bit as with the values stored. The divisions run beside the sweep's chain of
// dependent operations. It pays where the bundles come from memory; in cache the divisions
// cost a little more than the loads they replace.
using Delassus = DelassusBlock<v4d>;
FLOEDEM_LANES Delassus delassus(const SweepBundle& b, const BundlePoint& p, v4d nx, v4d ny) {
  return delassus_block(load(b.ma), load(b.ia), load(b.mb), load(b.ib), load(p.rax), load(p.ray), load(p.rbx),
                        load(p.rby), nx, ny);
}

// local_law (local_law.hpp) on four lanes. A lane without a point (target -inf) is apart
// whatever its block: its impulse is zero.
FLOEDEM_LANES void local_lanes(const BundlePoint& p, const Delassus& d, v4d ufn, v4d uft, v4d mu, v4d& pn, v4d& pt) {
  local_law<lanes4::Ops>(ufn, uft, load(p.target), mu, d.wnn, d.wnt, d.wtt, pn, pt);
}

// What a sweep reports: its largest change |dP_n| + |dP_t| and impulse P_n + |P_t| (each
// lane's, reduced at the end), and |dP|^2 summed (NNCG).
struct SweepResult {
  double largest_change = 0.0, largest_impulse = 0.0, size = 0.0;
};

// A bundle under way in a sweep: its bodies' velocities, held in registers over its points.
struct BundleRun {
  Side a_side, b_side;
  v4d nx, ny, mu;  // t = perp(n) = (-ny, nx)
};

FLOEDEM_LANES BundleRun start(const SweepBundle& b, const Vec2* v, const double* w) {
  return {gather(b.body_a, v, w), gather(b.body_b, v, w), load(b.nx), load(b.ny), load(b.friction)};
}

// NNCG's step (ConjugateStep, sweep_schedule.hpp), taken by the sweep after the one that called
// for it (solve_coloured says why); r is the last sweep's change.
using PendingStep = ConjugateStep;

// The pending step at one point of a bundle (`change` and `direction` its n then t values, four
// lanes each): the step's impulse added to pn and pt, the point's impulses before its solve.
FLOEDEM_LANES void take_step(const PendingStep& pending, const double* change, double* direction, v4d& pn, v4d& pt) {
  switch (pending.kind) {
    case PendingStep::Kind::none: return;
    case PendingStep::Kind::start:
      store(direction, load(change));
      store(direction + kBundleLanes, load(change + kBundleLanes));
      return;
    case PendingStep::Kind::restart:
      store(direction, splat(0.0));
      store(direction + kBundleLanes, splat(0.0));
      return;
    case PendingStep::Kind::step: {
      const v4d beta = splat(pending.beta);
      const v4d xn = beta * load(direction), xt = beta * load(direction + kBundleLanes);
      store(direction, xn + load(change));
      store(direction + kBundleLanes, xt + load(change + kBundleLanes));
      pn = pn + xn;
      pt = pt + xt;
      return;
    }
  }
}

// NNCG's values of the bundle under way: kBundleNncg each (point, n or t, lane); null without NNCG.
struct BundleNncg {
  double* change = nullptr;
  double* direction = nullptr;
  // The values of the bundle `j` places on (none without NNCG).
  BundleNncg at(std::size_t j) const {
    return change == nullptr ? BundleNncg{} : BundleNncg{change + kBundleNncg * j, direction + kBundleNncg * j};
  }
};

// Point k of a bundle: its local solve and impulse. Returns |dP|^2 per lane (NNCG's merit: the
// caller adds it in point order); with NNCG, the pending step taken first and the lanes' impulse
// changes into `change`, n then t (an empty lane's is zero).
FLOEDEM_LANES v4d sweep_point(SweepBundle& b, int k, BundleRun& r, v4d& largest_change, v4d& largest_impulse,
                              const BundleNncg& nncg, const PendingStep& pending) {
  BundlePoint& p = b.point[k];
  const v4d nx = r.nx, ny = r.ny;
  // Relative velocity of b's point with respect to a's: (v_b + w_b k x r_b) - (v_a + w_a k x r_a).
  const v4d ux = (r.b_side.vx + -r.b_side.w * load(p.rby)) - (r.a_side.vx + -r.a_side.w * load(p.ray));
  const v4d uy = (r.b_side.vy + r.b_side.w * load(p.rbx)) - (r.a_side.vy + r.a_side.w * load(p.rax));
  v4d pn0 = load(p.normal_impulse), pt0 = load(p.tangent_impulse);
  double* const change = nncg.change == nullptr ? nullptr : nncg.change + 2 * kBundleLanes * k;
  if (change != nullptr) take_step(pending, change, nncg.direction + 2 * kBundleLanes * k, pn0, pt0);
  // Velocity without this point's own impulse.
  const Delassus d = delassus(b, p, nx, ny);
  const v4d ufn = (ux * nx + uy * ny) - (d.wnn * pn0 + d.wnt * pt0);
  const v4d uft = (ux * -ny + uy * nx) - (d.wnt * pn0 + d.wtt * pt0);
  v4d pn, pt;
  local_lanes(p, d, ufn, uft, r.mu, pn, pt);
  const v4d dpn = pn - pn0, dpt = pt - pt0;
  apply(b, p, dpn * nx + dpt * -ny, dpn * ny + dpt * nx, r.a_side, r.b_side);
  store(p.normal_impulse, pn);
  store(p.tangent_impulse, pt);
  largest_change = max(largest_change, abs(dpn) + abs(dpt));
  largest_impulse = max(largest_impulse, pn + abs(pt));
  if (change == nullptr) return splat(0.0);
  store(change, dpn);
  store(change + kBundleLanes, dpt);
  return dpn * dpn + dpt * dpt;
}

FLOEDEM_LANES void finish(const SweepBundle& b, const BundleRun& r, Vec2* v, double* w) {
  scatter(b.body_a, b.ma, r.a_side, v, w);
  scatter(b.body_b, b.mb, r.b_side, v, w);
}

// One Gauss-Seidel sweep over the bundles, in order; with NNCG (`nncg` the first bundle's values,
// kBundleNncg a bundle in the bundles' order), each point's pending step taken and its impulse
// change stored. The bundles are one colour's:
// no two share a moving body, so the order in which their points are solved does not change
// what any computes. Two are solved side by side, point k of one beside point k of the other:
// each bundle's points are one chain of dependent operations (its bodies' velocities), over
// 300 instructions long, and one chain alone leaves most of the core idle (two chains: see
// BM_ContactSweepsColoured). Every sum and maximum is formed as one bundle after the other
// would (|dP|^2 added in bundle and point order; a maximum does not depend on order), so the
// sweep is the same to the bit as one bundle at a time.
// The bundles are read and written in order, ten times a step, and at 100k floes they come
// from memory (some 50 MB): the sweep would wait on each bundle's first loads. Each pair of bundles
// asks for the pair two on (bundles four on, 3 KB ahead; eight on gave the same). A prefetch
// changes no value; in cache it costs a little.
constexpr std::size_t kSweepAhead = 4;

FLOEDEM_LANES SweepResult sweep_lanes(std::span<SweepBundle> bundles, Vec2* v, double* w, const BundleNncg& nncg,
                                      const PendingStep& pending) {
  v4d largest_change = splat(0.0), largest_impulse = splat(0.0), size = splat(0.0);
  const bool accelerate = nncg.change != nullptr;
  std::size_t i = 0;
  for (; i + 1 < bundles.size(); i += 2) {
    SweepBundle &b0 = bundles[i], &b1 = bundles[i + 1];
    // Near the span's end: the colour's next block, or past the array (never faults).
    prefetch_record(bundles.data(), i + kSweepAhead, 2 * sizeof(SweepBundle));
    BundleRun r0 = start(b0, v, w), r1 = start(b1, v, w);
    const BundleNncg c0 = nncg.at(i), c1 = nncg.at(i + 1);
    v4d sq0[2], sq1[2];
    const int both = std::min(b0.points, b1.points);
    for (int k = 0; k < both; ++k) {
      sq0[k] = sweep_point(b0, k, r0, largest_change, largest_impulse, c0, pending);
      sq1[k] = sweep_point(b1, k, r1, largest_change, largest_impulse, c1, pending);
    }
    for (int k = both; k < b0.points; ++k) sq0[k] = sweep_point(b0, k, r0, largest_change, largest_impulse, c0, pending);
    for (int k = both; k < b1.points; ++k) sq1[k] = sweep_point(b1, k, r1, largest_change, largest_impulse, c1, pending);
    if (accelerate) {
      for (int k = 0; k < b0.points; ++k) size = size + sq0[k];
      for (int k = 0; k < b1.points; ++k) size = size + sq1[k];
    }
    finish(b0, r0, v, w);
    finish(b1, r1, v, w);
  }
  if (i < bundles.size()) {
    SweepBundle& b = bundles[i];
    BundleRun r = start(b, v, w);
    const BundleNncg c = nncg.at(i);
    for (int k = 0; k < b.points; ++k) {
      const v4d sq = sweep_point(b, k, r, largest_change, largest_impulse, c, pending);
      if (accelerate) size = size + sq;
    }
    finish(b, r, v, w);
  }
  SweepResult r;
  for (int l = 0; l < kBundleLanes; ++l) {
    r.largest_change = std::max(r.largest_change, largest_change[l]);
    r.largest_impulse = std::max(r.largest_impulse, largest_impulse[l]);
    r.size += size[l];
  }
  return r;
}

// The sweep built three times: for the x86-64 baseline, for AVX2 and for AVX-512, the fastest
// the processor runs picked at run time. The same operations on each lane in each (no fused
// multiply-add: -ffp-contract=off), so the same impulses to the bit (tested).
SweepResult sweep_baseline(std::span<SweepBundle> bundles, Vec2* v, double* w, const BundleNncg& nncg,
                           const PendingStep& pending) {
  return sweep_lanes(bundles, v, w, nncg, pending);
}
#if defined(__x86_64__)
#define FLOEDEM_HAS_AVX2_SWEEP 1
[[gnu::target("avx2")]] SweepResult sweep_avx2(std::span<SweepBundle> bundles, Vec2* v, double* w,
                                               const BundleNncg& nncg, const PendingStep& pending) {
  return sweep_lanes(bundles, v, w, nncg, pending);
}
// AVX-512's 32 vector registers (for the same 4-lane vectors) spare the AVX2 build's spills.
[[gnu::target("avx2,avx512f,avx512vl")]] SweepResult sweep_avx512(std::span<SweepBundle> bundles, Vec2* v, double* w,
                                                                  const BundleNncg& nncg, const PendingStep& pending) {
  return sweep_lanes(bundles, v, w, nncg, pending);
}
#endif

SweepResult sweep_once(std::span<SweepBundle> bundles, Vec2* v, double* w, const BundleNncg& nncg,
                       const PendingStep& pending) {
  switch (lane_isa()) {
#ifdef FLOEDEM_HAS_AVX2_SWEEP
    case LaneIsa::avx512: return sweep_avx512(bundles, v, w, nncg, pending);
    case LaneIsa::avx2: return sweep_avx2(bundles, v, w, nncg, pending);
#endif
    default: return sweep_baseline(bundles, v, w, nncg, pending);
  }
}

// The largest amount by which a point approaches faster than its target (largest_shortfall).
double largest_shortfall_of(std::span<const SweepBundle> bundles, const BodyArrays& s) {
  double worst = 0.0;
  for (const SweepBundle& b : bundles)
    for (int k = 0; k < b.points; ++k)
      for (int l = 0; l < kBundleLanes; ++l) {
        const BundlePoint& p = b.point[k];
        if (p.target[l] == -std::numeric_limits<double>::infinity()) continue;
        const Vec2 u = relative_velocity(s, b.body_a[l], b.body_b[l], {p.rax[l], p.ray[l]}, {p.rbx[l], p.rby[l]});
        worst = std::max(worst, p.target[l] - dot(u, {b.nx[l], b.ny[l]}));
      }
  return worst;
}

// A lane's point that is not there: no impulse ever (need = -inf <= 0 selects zero, whatever
// else the lane computes: an empty lane's zero masses give a zero Delassus block, so infinities).
void empty_point(BundlePoint& p, int l) {
  p.rax[l] = p.ray[l] = p.rbx[l] = p.rby[l] = 0.0;
  p.target[l] = -std::numeric_limits<double>::infinity();
  p.normal_impulse[l] = p.tangent_impulse[l] = 0.0;
}

// A lane without a manifold (a colour's last bundle): lane 0's bodies, read and never written.
void empty_lane(SweepBundle& b, int l) {
  b.manifold[l] = -1;
  b.body_a[l] = b.body_a[0];
  b.body_b[l] = b.body_b[0];
  b.nx[l] = b.ny[l] = b.friction[l] = 0.0;
  b.ma[l] = b.ia[l] = b.mb[l] = b.ib[l] = 0.0;
  for (BundlePoint& p : b.point) empty_point(p, l);
}

// Manifold i of the solve (all of them, or the island's).
struct Selection {
  std::span<Manifold> manifolds;
  std::span<const std::int32_t> island;
  std::size_t size() const { return island.empty() ? manifolds.size() : island.size(); }
  Manifold& operator[](std::size_t i) const {
    return island.empty() ? manifolds[i] : manifolds[static_cast<std::size_t>(island[i])];
  }
};

constexpr int kColours = 63;  // colours 0..62 in the masks' bits; a manifold that finds none is swept as a row
// A manifold's colour as colour() writes it: the colour, plus this flag where it has two
// points, so that a solve given the colours counts each colour's two-point manifolds from the
// colours alone (reading each 384-byte manifold again for its point count was another pass
// over them, out of cache at 16k floes).
constexpr std::int32_t kTwoPoints = 128;
constexpr std::int32_t colour_of(std::int32_t written) { return written & (kTwoPoints - 1); }

// Colours the manifolds, packs them into bundles colour by colour (each colour's manifolds in
// the given order) and those beyond the colours into rows (space.rows, their manifolds listed
// in space.overflow), and with the warm start applies each point's accumulated impulse in the
// given order (gather_rows' arithmetic and order). Returns the bundles and the rows.
struct Gathered {
  std::size_t bundles = 0, rows = 0, overflow = 0;
  std::array<std::size_t, kColours + 1> colour_start{};  // each colour's first bundle
};
// Each manifold's colour into colours[i] (kColours: none left; kTwoPoints added where it has
// two points); the counts per colour, and with `two` those of two points. body_colours is all
// zero again on return (a fixed body's entry, shared across threads, is never written).
std::array<std::size_t, kColours + 1> colour(const Selection& m, const BodyArrays& s, std::span<std::int32_t> colours,
                                             std::span<std::uint64_t> taken,
                                             std::array<std::size_t, kColours + 1>* two = nullptr) {
  auto moving = [&](std::int32_t body) { return s.inv_mass[body] != 0.0; };  // as apply_impulse
  std::array<std::size_t, kColours + 1> count{};
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (i + 8 < m.size()) __builtin_prefetch(&m[i + 8].body_a);  // out of cache at 16k floes; changes no value
    const Manifold& c = m[i];
    const bool ma = moving(c.body_a), mb = moving(c.body_b);
    const std::uint64_t near = (ma ? taken[c.body_a] : 0) | (mb ? taken[c.body_b] : 0);
    const std::uint64_t free = ~near & ((std::uint64_t{1} << kColours) - 1);
    const int k = free == 0 ? kColours : std::countr_zero(free);
    if (k < kColours) {
      const std::uint64_t bit = std::uint64_t{1} << k;
      if (ma) taken[c.body_a] |= bit;
      if (mb) taken[c.body_b] |= bit;
    }
    colours[i] = k + (c.point_count == 2 ? kTwoPoints : 0);
    ++count[static_cast<std::size_t>(k)];
    if (two != nullptr) (*two)[static_cast<std::size_t>(k)] += c.point_count == 2;
  }
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (moving(m[i].body_a)) taken[m[i].body_a] = 0;
    if (moving(m[i].body_b)) taken[m[i].body_b] = 0;
  }
  return count;
}

std::size_t bundles_of(const std::array<std::size_t, kColours + 1>& count) {
  std::size_t bundles = 0;
  for (int c = 0; c < kColours; ++c) bundles += (count[static_cast<std::size_t>(c)] + kBundleLanes - 1) / kBundleLanes;
  return bundles;
}

// The warm start of point q of manifold c (t = perp(c.normal)): its accumulated impulse applied,
// as apply_accumulated_impulses with +1 (contact_solver.cpp).
void warm_point(BodyArrays& s, const Manifold& c, Vec2 t, const ManifoldPoint& q) {
  if (q.normal_impulse != 0.0 || q.tangent_impulse != 0.0)
    apply_impulse(s, c, q, 1.0 * (q.normal_impulse * c.normal + q.tangent_impulse * t));
}

// Every field of lane `lane` of bundle b from manifold i (c), but the bundle's point count; with
// `empty_second`, its second point as a lane without one (the bundle sweeps two points, the
// manifold has one). The rest of the lanes are written by empty_lane.
void pack_lane(SweepBundle& b, int lane, const Manifold& c, std::size_t i, const BodyArrays& s, bool empty_second) {
  b.manifold[lane] = static_cast<std::int32_t>(i);
  b.body_a[lane] = c.body_a;
  b.body_b[lane] = c.body_b;
  b.nx[lane] = c.normal.x;
  b.ny[lane] = c.normal.y;
  b.friction[lane] = c.friction;
  b.ma[lane] = s.inv_mass[c.body_a];
  b.ia[lane] = s.inv_inertia[c.body_a];
  b.mb[lane] = s.inv_mass[c.body_b];
  b.ib[lane] = s.inv_inertia[c.body_b];
  for (int k = 0; k < c.point_count; ++k) {
    const ManifoldPoint& q = c.points[k];
    BundlePoint& p = b.point[k];
    p.rax[lane] = q.ra.x;
    p.ray[lane] = q.ra.y;
    p.rbx[lane] = q.rb.x;
    p.rby[lane] = q.rb.y;
    p.target[lane] = q.target_velocity;
    p.normal_impulse[lane] = q.normal_impulse;
    p.tangent_impulse[lane] = q.tangent_impulse;
  }
  if (empty_second) empty_point(b.point[1], lane);
}

constexpr std::size_t kThreadedPackingMost = std::size_t{1} << 27;  // slots (4 a bundle) below kEmptiesSecond
constexpr std::size_t kPackingBlock = 1024;            // manifolds a block of the threaded packing
constexpr std::int32_t kEmptiesSecond = 1 << 30;       // in a slot: empty_second for pack_lane

// gather_bundles' loop on the pool's threads, the same bundles and velocities to the bit: first,
// on this thread, each manifold's slot (its bundle and lane, from `place` as the loop takes
// them) into its colour's place in `space.overflow` (read already; a solve may overwrite the
// colours); then the lanes, blocks of manifolds on the pool's threads, while one of them
// applies the warm start manifold by manifold in the given order (it writes only the bodies'
// velocities, which the lanes do not read: the same velocities as the loop's, whatever the
// threads). `place` keeps each bundle's point count in `points` (a byte a bundle, in cache:
// written into each 768-byte bundle, it would be a miss a manifold on this one thread, a
// serial part of a large solve on two threads), and the lane 0 of each bundle,
// always taken, writes it into its bundle.
template <class Place, class EmptiesSecond>
void gather_on_threads(const Selection& m, BodyArrays& s, bool warm_start, const SweepSpace& space,
                       const std::array<std::size_t, kColours>& first, Place&& place, EmptiesSecond&& empties_second,
                       std::span<const std::uint8_t> points) {
  for (std::size_t i = 0; i < m.size(); ++i) {
    const std::int32_t written = space.overflow[i];
    const auto colour = static_cast<std::size_t>(colour_of(written));
    const bool two = (written & kTwoPoints) != 0;
    const std::size_t n = place(colour, two ? 2 : 1);
    space.overflow[i] = static_cast<std::int32_t>(kBundleLanes * first[colour] + n) +
                        (!two && empties_second(colour, n) ? kEmptiesSecond : 0);
  }
  const std::size_t blocks = (m.size() + kPackingBlock - 1) / kPackingBlock;
  thread_pool().for_blocks(blocks + 1, 1, [&](std::size_t block, std::size_t) {
    if (block == 0) {  // the warm start, in the given order
      for (std::size_t i = 0; warm_start && i < m.size(); ++i) {
        const Manifold& c = m[i];
        const Vec2 t = perp(c.normal);
        for (int k = 0; k < c.point_count; ++k) warm_point(s, c, t, c.points[k]);
      }
      return;
    }
    const std::size_t begin = (block - 1) * kPackingBlock, end = std::min(m.size(), begin + kPackingBlock);
    for (std::size_t i = begin; i < end; ++i) {
      const std::int32_t slot = space.overflow[i] & (kEmptiesSecond - 1);
      const auto bundle = static_cast<std::size_t>(slot / kBundleLanes);
      pack_lane(space.bundles[bundle], slot % kBundleLanes, m[i], i, s, (space.overflow[i] & kEmptiesSecond) != 0);
      if (slot % kBundleLanes == 0) space.bundles[bundle].points = points[bundle];
    }
  });
}

// With `two_points_first`, each colour's manifolds of two points are placed before those of
// one, each kind in the given order: a bundle sweeps as many points as its manifold with the
// most, so bundles of one kind sweep fewer (the 1k field's packed contacts: 62 % have one
// point, and 85 % of bundles in the given order have a lane of two). The bundles of a colour
// share no moving body, so which lane or bundle a manifold takes changes no impulse or velocity;
// only NNCG's merit, |dP|^2 summed lane by lane, would round otherwise, so with `accelerate`
// the solve keeps the given order.
Gathered gather_bundles(const Selection& m, BodyArrays& s, bool warm_start, bool two_points_first,
                        const SweepSpace& space, bool threads) {
  // Each manifold's colour in overflow[i], made here unless colour_manifolds made it.
  std::array<std::size_t, kColours + 1> count{}, two{};
  if (space.colours_given) {
    for (std::size_t i = 0; i < m.size(); ++i) {
      const auto c = static_cast<std::size_t>(colour_of(space.overflow[i]));
      ++count[c];
      two[c] += (space.overflow[i] & kTwoPoints) != 0;
    }
  } else {
    count = colour(m, s, space.overflow, space.body_colours, &two);
  }
  if (!two_points_first) two.fill(0);
  // Each colour's first bundle, and where its next manifold of two points and of one go (every
  // manifold in the second list without two_points_first).
  std::array<std::size_t, kColours> first{}, next_two{}, next_one{};
  Gathered g;
  for (int c = 0; c < kColours; ++c) {
    first[c] = g.colour_start[c] = g.bundles;
    next_one[c] = two[c];
    g.bundles += (count[static_cast<std::size_t>(c)] + kBundleLanes - 1) / kBundleLanes;
  }
  g.colour_start[kColours] = g.bundles;
  if (g.bundles > space.bundles.size()) throw std::logic_error("solve_velocities: no room for the coloured bundles");
  // A one-point manifold's second point is emptied only in a bundle that sweeps two points:
  // placed two-point first, a bundle past the colour's two-point manifolds sweeps point 0
  // alone, and its second point is left as it was (16 doubles a lane, not written or read).
  auto empties_second = [&](std::size_t colour, std::size_t n) {
    return n - n % kBundleLanes < (two_points_first ? two[colour] : count[colour]);
  };
  // A large solve swept on the threads (and nothing beyond the colours) is packed on them too.
  const bool on_threads = threads && count[kColours] == 0 && m.size() >= kColouredOnThreads &&
                          m.size() < kThreadedPackingMost && thread_pool().size() > 1;
  thread_local std::vector<std::uint8_t> bundle_points;  // on threads: each bundle's point count (grown, never shrunk)
  if (on_threads && bundle_points.size() < g.bundles) bundle_points.resize(g.bundles + g.bundles / 2);
  // The next place in its colour (n: bundle first[colour] + n / 4, lane n % 4) of a manifold of
  // `points` points, taken in the manifolds' order; its bundle's point count kept. Lane 0 resets
  // it. Where the two lists meet, lane 0 (two points) may be taken after a later lane (one
  // point): its count, 2, is the bundle's either way.
  auto place = [&](std::size_t colour, int points) {
    const std::size_t n = two_points_first && points == 2 ? next_two[colour]++ : next_one[colour]++;
    const std::size_t j = first[colour] + n / kBundleLanes;
    if (on_threads) {
      if (n % kBundleLanes == 0) bundle_points[j] = 0;
      bundle_points[j] = std::max(bundle_points[j], static_cast<std::uint8_t>(points));
      return n;
    }
    SweepBundle& b = space.bundles[j];
    if (n % kBundleLanes == 0) b.points = 0;
    b.points = std::max(b.points, static_cast<std::int32_t>(points));
    return n;
  };
  if (on_threads) gather_on_threads(m, s, warm_start, space, first, place, empties_second, bundle_points);
  for (std::size_t i = 0; !on_threads && i < m.size(); ++i) {
    // What pack_lane reads of the manifold four on (its first 320 bytes; the colouring's
    // prefetch warmed only the first line). A prefetch changes no value.
    if (i + 4 < m.size()) prefetch_lines(&m[i + 4], 320);
    const Manifold& c = m[i];
    const Vec2 t = perp(c.normal);
    auto warm = [&](const ManifoldPoint& q) {
      if (warm_start) warm_point(s, c, t, q);
    };
    const auto colour = static_cast<std::size_t>(colour_of(space.overflow[i]));
    if (colour == kColours) {  // no colour left: rows, swept after the bundles
      space.overflow[g.overflow++] = static_cast<std::int32_t>(i);  // i >= g.overflow: read already
      for (int k = 0; k < c.point_count; ++k) {
        const ManifoldPoint& q = c.points[k];
        space.rows[g.rows++] = {c.body_a, c.body_b, c.normal, q.ra, q.rb, q.wnn, q.wnt, q.wtt, q.target_velocity,
                                c.friction, q.normal_impulse, q.tangent_impulse};
        warm(q);
      }
      continue;
    }
    const std::size_t n = place(colour, c.point_count);
    pack_lane(space.bundles[first[colour] + n / kBundleLanes], static_cast<int>(n % kBundleLanes), c, i, s,
              c.point_count == 1 && empties_second(colour, n));
    for (int k = 0; k < c.point_count; ++k) warm(c.points[k]);
  }
  for (int c = 0; c < kColours; ++c) {  // the lanes left in each colour's last bundle
    const std::size_t n = count[static_cast<std::size_t>(c)];
    if (n % kBundleLanes == 0) continue;
    SweepBundle& b = space.bundles[first[c] + n / kBundleLanes];
    for (auto l = static_cast<int>(n % kBundleLanes); l < kBundleLanes; ++l) empty_lane(b, l);
  }
  return g;
}

// The impulses of the bundles [begin, end) back into their manifolds' points.
void scatter_lanes(const Selection& m, std::span<const SweepBundle> bundles, std::size_t begin, std::size_t end) {
  // A bundle's manifolds are anywhere in the list (out of cache at 16k floes): the lines this
  // writes of those of the bundle two on are asked for ahead. A prefetch changes no value.
  constexpr std::size_t kAhead = 2;
  for (std::size_t j = begin; j < end; ++j) {
    const SweepBundle& b = bundles[j];
    if (j + kAhead < end)
      for (const std::int32_t i : bundles[j + kAhead].manifold) {
        if (i < 0) continue;
        const Manifold& c = m[static_cast<std::size_t>(i)];
        __builtin_prefetch(&c.point_count, 1);
        __builtin_prefetch(&c.points[0].normal_impulse, 1);
        __builtin_prefetch(&c.points[1].normal_impulse, 1);
      }
    for (int l = 0; l < kBundleLanes; ++l) {
      if (b.manifold[l] < 0) continue;
      Manifold& c = m[static_cast<std::size_t>(b.manifold[l])];
      for (int k = 0; k < c.point_count; ++k) {
        c.points[k].normal_impulse = b.point[k].normal_impulse[l];
        c.points[k].tangent_impulse = b.point[k].tangent_impulse[l];
      }
    }
  }
}

// The impulses back into their manifolds' points; with `threads`, the bundles in blocks on the
// pool's threads (each manifold is one lane's: the same stores on any number of threads).
void scatter_bundles(const Selection& m, std::span<const SweepBundle> bundles, std::span<const SweepRow> rows,
                     std::span<const std::int32_t> overflow, bool threads) {
  constexpr std::size_t kScatterBlock = 512;  // bundles
  if (threads)
    thread_pool().for_blocks(bundles.size(), kScatterBlock,
                             [&](std::size_t begin, std::size_t end) { scatter_lanes(m, bundles, begin, end); });
  else
    scatter_lanes(m, bundles, 0, bundles.size());
  std::size_t x = 0;
  for (const std::int32_t i : overflow) {
    Manifold& c = m[static_cast<std::size_t>(i)];
    for (int k = 0; k < c.point_count; ++k, ++x) {
      c.points[k].normal_impulse = rows[x].normal_impulse;
      c.points[k].tangent_impulse = rows[x].tangent_impulse;
    }
  }
}

// One sweep over the bundles, colour by colour, each colour in blocks of kBlock bundles: the
// blocks of a colour share no moving body, so with `threads` they run on the pool's threads
// (the pool returns when a colour's blocks are all done: the next colour reads what they
// wrote). Each block reduces its own maxima and |dP|^2, and the sweep adds the blocks' sums in
// block order on any number of threads: the same sweep to the bit.
constexpr std::size_t kBlock = 64;  // bundles: 256 manifolds, many times the pool's hand-over
// A colour goes to the pool only with this many blocks or more: the pool's join per colour and
// sweep costs more than half of a colour of two or three blocks saves (the packed 4k field's
// colours of about 100 bundles made its contact solve slower on two threads than on one).
// Which thread sweeps a block changes no result, so neither does this bound.
constexpr std::size_t kPoolBlocks = 4;

// fn(begin, end) over the blocks of kBlock bundles of one colour of `count` bundles, in order on
// this thread, or on the pool's threads with `threads` and kPoolBlocks blocks or more.
template <class F>
void colour_blocks(std::size_t count, bool threads, F&& fn) {
  if (threads && count >= kPoolBlocks * kBlock) {
    thread_pool().for_blocks(count, kBlock, fn);
    return;
  }
  for (std::size_t b = 0; b < count; b += kBlock) fn(b, std::min(count, b + kBlock));
}
SweepResult sweep_colours(std::span<SweepBundle> bundles, const Gathered& g, BodyArrays& s, const BundleNncg& nncg,
                          const PendingStep& pending, bool threads) {
  // A colour's blocks' results: the calling thread's list (grown, never shrunk), named by a
  // reference for the workers (a thread_local named inside their lambda would be their own).
  thread_local std::vector<SweepResult> caller_blocks;
  std::vector<SweepResult>& blocks = caller_blocks;
  Vec2* const v = s.velocity.data();
  double* const w = s.angular_velocity.data();
  SweepResult total;
  auto add = [&](const SweepResult& r) {
    total.largest_change = std::max(total.largest_change, r.largest_change);
    total.largest_impulse = std::max(total.largest_impulse, r.largest_impulse);
    total.size += r.size;
  };
  for (int c = 0; c < kColours; ++c) {
    const std::span<SweepBundle> colour =
        bundles.subspan(g.colour_start[c], g.colour_start[c + 1] - g.colour_start[c]);
    if (colour.empty()) break;  // colours are taken lowest first: none after an empty one
    const std::size_t count = (colour.size() + kBlock - 1) / kBlock;
    if (blocks.size() < count) blocks.resize(count + count / 2);  // no allocation per step once grown
    colour_blocks(colour.size(), threads, [&](std::size_t begin, std::size_t end) {
      blocks[begin / kBlock] =
          sweep_once(colour.subspan(begin, end - begin), v, w, nncg.at(g.colour_start[c] + begin), pending);
    });
    for (std::size_t b = 0; b < count; ++b) add(blocks[b]);
  }
  return total;
}

// NNCG's step per body. The step beta p moves each body's velocity by beta M^-1 J^T p, and
// M^-1 J^T p obeys the direction's own update: with p <- beta p + r, it becomes
// beta M^-1 J^T p + M^-1 J^T r, and M^-1 J^T r, the velocity the last sweep's changes r
// carried, is what that sweep did to the body: its velocity after the colours less its
// velocity before. So each moving body keeps v0 (its velocity as the sweep began) and
// dv = M^-1 J^T p (BodyStep), and the step is one pass over the bodies; each bundle's share
// (P += beta p, p <- beta p + r) is taken by the next sweep as it reaches the bundle, before its
// points' solves (take_step): the same order as a step made apart after the sweep. A step
// made apart reads and writes every bundle once more each sweep, and its values twice: at 100k
// floes, where the bundles come from memory, half as much traffic again as the sweep.
// The velocities differ from a step made point by point only by rounding (a difference of
// velocities instead of a sum of increments, some 1e-16 of a speed a sweep).

// The solve's moving bodies (listed once each, in the bundles' order, marked meanwhile with
// body_colours' bit above the colours), each one's v0 its velocity now and its dv zero.
constexpr std::uint64_t kListed = std::uint64_t{1} << kColours;
std::span<const std::int32_t> list_moving_bodies(std::span<const SweepBundle> bundles, const BodyArrays& s,
                                                 const SweepSpace& space) {
  std::size_t n = 0;
  auto list = [&](std::int32_t body) {
    std::uint64_t& mark = space.body_colours[static_cast<std::size_t>(body)];
    if (s.inv_mass[body] == 0.0 || (mark & kListed) != 0) return;
    mark |= kListed;
    space.moving_bodies[n++] = body;
    space.body_steps[static_cast<std::size_t>(body)] = {s.velocity[body], s.angular_velocity[body], {}, 0.0};
  };
  for (const SweepBundle& b : bundles)
    for (int l = 0; l < kBundleLanes; ++l) {
      if (b.manifold[l] < 0) continue;
      list(b.body_a[l]);
      list(b.body_b[l]);
    }
  for (std::size_t i = 0; i < n; ++i) space.body_colours[static_cast<std::size_t>(space.moving_bodies[i])] = 0;
  return space.moving_bodies.first(n);
}

// fn(begin, end) over the moving bodies, in blocks on the pool's threads with `threads` (each
// body's values are its own: the same on any number of threads).
template <class F>
void body_blocks(std::size_t count, bool threads, F&& fn) {
  constexpr std::size_t kBodyBlock = 4096;
  if (threads && count >= 2 * kBodyBlock) {
    thread_pool().for_blocks(count, kBodyBlock, fn);
    return;
  }
  fn(std::size_t{0}, count);
}

// What the colours' sweep did to each moving body's velocity, into its v0 (the rows beyond the
// colours are swept next, and take no step: what they do is not the direction's).
void measure_sweep(std::span<const std::int32_t> moving, const BodyArrays& s, std::span<BodyStep> steps,
                   bool threads) {
  body_blocks(moving.size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::int32_t b = moving[i];
      BodyStep& d = steps[static_cast<std::size_t>(b)];
      d.v0 = s.velocity[b] - d.v0;
      d.w0 = s.angular_velocity[b] - d.w0;
    }
  });
}

// The pending step's share on the bodies, before the sweep that takes the bundles' share: with
// `measured`, the last sweep's change is in v0 already (measure_sweep). Each body's v0 is then
// its velocity as the next sweep begins.
void step_bodies(std::span<const std::int32_t> moving, BodyArrays& s, std::span<BodyStep> steps,
                 const PendingStep& pending, bool measured, bool threads) {
  body_blocks(moving.size(), threads, [&](std::size_t begin, std::size_t end) {
    const double beta = pending.beta;
    for (std::size_t i = begin; i < end; ++i) {
      const std::int32_t b = moving[i];
      BodyStep& d = steps[static_cast<std::size_t>(b)];
      Vec2 v = s.velocity[b];
      double w = s.angular_velocity[b];
      const Vec2 rv = measured ? d.v0 : v - d.v0;  // M^-1 J^T r
      const double rw = measured ? d.w0 : w - d.w0;
      switch (pending.kind) {
        case PendingStep::Kind::none: break;
        case PendingStep::Kind::start:
          d.dv = rv;
          d.dw = rw;
          break;
        case PendingStep::Kind::restart:
          d.dv = {};
          d.dw = 0.0;
          break;
        case PendingStep::Kind::step:
          v = v + beta * d.dv;
          w = w + beta * d.dw;
          d.dv = beta * d.dv + rv;
          d.dw = beta * d.dw + rw;
          s.velocity[b] = v;
          s.angular_velocity[b] = w;
          break;
      }
      d.v0 = v;
      d.w0 = w;
    }
  });
}

}  // namespace

std::size_t colour_manifolds(std::span<Manifold> manifolds, std::span<const std::int32_t> island,
                             const BodyArrays& bodies, std::span<std::int32_t> colours,
                             std::span<std::uint64_t> body_colours) {
  return bundles_of(colour(Selection{manifolds, island}, bodies, colours, body_colours));
}


int solve_coloured(std::span<Manifold> manifolds, std::span<const std::int32_t> island, BodyArrays& s,
                   const SweepLimits& limits, const SweepSpace& space, const SweepOptions& options) {
  const bool warm_start = options.warm_start, accelerate = options.accelerate, threads = options.threads;
  const bool given_order = options.given_order;
  const Selection m{manifolds, island};
  if (space.rows.size() < 2 * m.size() || space.overflow.size() < m.size() ||
      space.body_colours.size() < s.inv_mass.size())
    throw std::logic_error("solve_velocities: the sweep space has no room for the coloured sweeps");
  const Gathered g = gather_bundles(m, s, warm_start, /*two_points_first=*/!accelerate && !given_order, space, threads);
  const std::span<SweepBundle> bundles = space.bundles.first(g.bundles);
  const std::span<SweepRow> rows = space.rows.first(g.rows);
  std::span<double> change, direction;
  std::span<const std::int32_t> moving;
  if (accelerate) {
    const std::size_t values = kBundleNncg * g.bundles;
    if (space.bundle_change.size() < values || space.bundle_direction.size() < values ||
        space.moving_bodies.size() < 2 * m.size() || space.body_steps.size() < s.inv_mass.size())
      throw std::logic_error("solve_velocities: the sweep space has no room for the coloured NNCG values");
    // Each is written before it is read: r by the first sweep, p by the first step (start).
    change = space.bundle_change.first(values);
    direction = space.bundle_direction.first(values);
    moving = list_moving_bodies(bundles, s, space);
  }
  const BundleNncg nncg = accelerate ? BundleNncg{change.data(), direction.data()} : BundleNncg{};
  // run_sweeps' loop (contact_solver.cpp) on the same SweepSchedule, over the bundles and then the
  // rows beyond the colours, NNCG's step made by the sweep after the one that calls for it
  // (step_bodies' comment).
  SweepSchedule schedule(limits);
  PendingStep pending;
  while (schedule.next()) {
    if (pending.kind != PendingStep::Kind::none)
      step_bodies(moving, s, space.body_steps, pending, /*measured=*/!rows.empty(), threads);
    SweepResult r = sweep_colours(bundles, g, s, nncg, pending, threads);
    pending = {};
    if (accelerate && !rows.empty()) measure_sweep(moving, s, space.body_steps, threads);
    for (SweepRow& row : rows) {
      const RowChange d = sweep_row(row, s);
      r.largest_change = std::max(r.largest_change, std::abs(d.normal) + std::abs(d.tangent));
      r.largest_impulse = std::max(r.largest_impulse, row.normal_impulse + std::abs(row.tangent_impulse));
    }
    if (schedule.done(r.largest_change, r.largest_impulse,
                      [&] { return std::max(largest_shortfall_of(bundles, s), largest_shortfall_of(rows, s)); }))
      break;
    if (accelerate && !schedule.last()) pending = schedule.conjugate_step(r.size);
  }
  scatter_bundles(m, bundles, rows, space.overflow.first(g.overflow), threads);
  return schedule.sweeps();
}

}  // namespace floedem
