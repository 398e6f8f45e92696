// The position projection (the `position_projection` stage): nonlinear Gauss-Seidel on
// positions, after Box2D v2.4's position solver. Per point, with the gap measured from the
// material points that made the contact (the reference face's normal n_ref and point, the
// incident point q: gap = (q - face).n_ref), the correction C = beta (gap + slop), clamped to
// [-max_correction, 0], is removed by the positional impulse dlambda = -C / K along n, with
// K = n.M^-1 n at the current configuration:
//   x_a -= m_a^-1 dlambda n,  angle_a -= I_a^-1 (r_a x dlambda n),  and the opposite on b.
// Positions only, never velocities, so drift correction adds no kinetic energy.
#include <algorithm>
#include <bit>
#include <cstdint>

#include "engine/headroom.hpp"
#include "engine/prefetch.hpp"
#include "parallel/thread_pool.hpp"
#include "solver/contact_solver.hpp"

namespace floedem {

namespace {

// One call of solve_positions. A manifold whose two bodies kept their poses, to the bit, since
// its gaps were last measured has the same gaps again, so it corrects nothing (had it
// corrected, its bodies would have moved) and its deepest gap is the one measured then: it is
// left as it was. Only the first sweep measures every manifold; a later one measures those near
// what the sweeps before it moved (in a packed field, the few deep contacts and their
// neighbours). The same positions and the same deepest overlap, to the bit, as measuring every
// manifold in every sweep.
//
// The later sweeps find those manifolds without a pass over all of them (at 10^5 floes each
// such pass read every manifold's bodies, out of cache, for a few hundred measured): a body
// that moves marks its manifolds stale (a bit each), and a sweep measures the stale ones in
// ascending order, marks set ahead of it this sweep, those behind it the next; a manifold's
// mark is cleared as it is measured, and set again if it moves its own bodies. That is the
// set of manifolds, in the same order, that the clocks (moved against evaluated) pick.
class Projection {
 public:
  Projection(std::span<const Manifold> manifolds, BodyArrays& s, const NativeSettings& settings, ProjectionWork& work)
      : manifolds_(manifolds), s_(s), settings_(settings), work_(work), start_(work.clock) {}

  double solve() {
    const std::size_t bodies = s_.position.size();
    const std::size_t nm = manifolds_.size();
    if (work_.moved.size() != bodies) work_.moved.assign(bodies, 0);
    resize_with_headroom(work_.evaluated, nm);
    resize_with_headroom(work_.depth, nm);
    reserve_with_headroom(work_.moved_bodies, bodies);
    work_.moved_bodies.clear();
    if (settings_.position_iterations <= 0) return 0.0;
    double deepest = first_sweep();
    ++work_.sweeps;
    if (settings_.position_iterations == 1 || deepest <= 1.5 * settings_.allowed_penetration) return deepest;
    list_stale();
    marking_ = true;
    for (int iteration = 1; iteration < settings_.position_iterations; ++iteration) {
      deepest = later_sweep();
      ++work_.sweeps;
      if (deepest <= 1.5 * settings_.allowed_penetration) break;
    }
    return deepest;
  }

 private:
  struct PointGap {
    Vec2 n_ref, q;
    double gap;
  };

  // Point k's gap at the current poses.
  PointGap point_gap(const Manifold& m, int k) const {
    const int ref = m.reference_is_b ? m.body_b : m.body_a;
    const int inc = m.reference_is_b ? m.body_a : m.body_b;
    const Vec2 n_ref = s_.rotation[ref].apply(m.local_normal);
    const Vec2 face = s_.position[ref] + s_.rotation[ref].apply(m.local_face_point);
    const Vec2 q = s_.position[inc] + s_.rotation[inc].apply(m.points[k].local_incident);
    return PointGap{n_ref, q, dot(q - face, n_ref)};
  }

  // C = beta (gap + slop), clamped to [-max_correction, 0]: a point corrects where C < 0.
  double correction(double gap) const {
    return std::clamp(settings_.position_correction * (gap + settings_.allowed_penetration),
                      -settings_.max_correction, 0.0);
  }

  void mark(int body) {
    const auto b = static_cast<std::size_t>(body);
    for (std::int32_t k = work_.body_first[b]; k < work_.body_first[b + 1]; ++k) {
      const auto i = static_cast<std::size_t>(work_.body_manifolds[static_cast<std::size_t>(k)]);
      work_.stale[i / 64] |= std::uint64_t{1} << (i % 64);
    }
  }

  // A pose written back with other bits (however small the change) makes the body moved.
  void move(int body, Vec2 position, double angle) {
    if (same_bits(position.x, s_.position[body].x) && same_bits(position.y, s_.position[body].y) &&
        same_bits(angle, s_.angle[body]))
      return;
    s_.position[body] = position;
    s_.angle[body] = angle;
    s_.rotation[body] = Rot::from_angle(angle);
    if (marking_)
      mark(body);
    else if (work_.moved[static_cast<std::size_t>(body)] <= start_)
      work_.moved_bodies.push_back(body);  // its first move in this call
    work_.moved[static_cast<std::size_t>(body)] = work_.clock;
  }

  // Measures manifold i's gaps and corrects them; returns its deepest gap.
  double measure(std::size_t i) {
    const Manifold& m = manifolds_[i];
    const int a = m.body_a, b = m.body_b;
    work_.evaluated[i] = ++work_.clock;
    double depth = 0.0;
    const double ma = s_.inv_mass[a], mb = s_.inv_mass[b];
    const double ia = s_.inv_inertia[a], ib = s_.inv_inertia[b];
    for (int k = 0; k < m.point_count; ++k) {
      const auto [n_ref, q, gap] = point_gap(m, k);
      depth = std::max(depth, -gap);
      const double c = correction(gap);
      if (c >= 0.0) continue;
      const Vec2 n = m.reference_is_b ? -n_ref : n_ref;
      const Vec2 point = q - 0.5 * gap * n_ref;
      const Vec2 ra = point - s_.position[a];
      const Vec2 rb = point - s_.position[b];
      const double rna = cross(ra, n), rnb = cross(rb, n);
      const double k_eff = ma + mb + ia * rna * rna + ib * rnb * rnb;
      if (k_eff == 0.0) continue;  // two sleeping bodies, or a sleeping and a fixed one: held as they are
      const Vec2 impulse = (-c / k_eff) * n;
      move(a, s_.position[a] - ma * impulse, s_.angle[a] - ia * cross(ra, impulse));
      move(b, s_.position[b] + mb * impulse, s_.angle[b] + ib * cross(rb, impulse));
    }
    work_.depth[i] = depth;
    return depth;
  }

  // The first sweep: every manifold. Its gaps are measured over the threads first, at the poses
  // the sweep starts from, with each manifold's two bodies noted (for the lists below, which
  // then need not read the manifolds again) and whether any point would correct. The sweep
  // proper then goes in order and measures again only a manifold that corrects or whose bodies
  // an earlier one moved; any other's gaps are those measured (same poses, same expressions,
  // same bits), and it moves nothing. So the poses and depths are those of measuring every
  // manifold in turn, on any thread count; in a settled field few manifolds correct, and the
  // sweep's cost (reading every manifold and its bodies' poses) is shared by the threads.
  double first_sweep() {
    const std::size_t nm = manifolds_.size();
    resize_with_headroom(work_.ends, 2 * nm);
    resize_with_headroom(work_.corrects, nm);
    thread_pool().for_blocks(nm, 4096, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        // The manifold four on, every line of it asked for ahead: this pass reads the first
        // line, each point's and the reference face's (the last), out of cache in a large
        // field. A prefetch changes no value.
        if (i + 4 < end) prefetch_lines(&manifolds_[i + 4], sizeof(Manifold));
        const Manifold& m = manifolds_[i];
        work_.ends[2 * i] = m.body_a;
        work_.ends[2 * i + 1] = m.body_b;
        double depth = 0.0;
        bool corrects = false;
        for (int k = 0; k < m.point_count; ++k) {
          const double gap = point_gap(m, k).gap;
          depth = std::max(depth, -gap);
          corrects = corrects || correction(gap) < 0.0;
        }
        work_.depth[i] = depth;
        work_.corrects[i] = corrects;
      }
    });
    double deepest = 0.0;
    for (std::size_t i = 0; i < nm; ++i) {
      const auto a = static_cast<std::size_t>(work_.ends[2 * i]), b = static_cast<std::size_t>(work_.ends[2 * i + 1]);
      if (work_.corrects[i] || work_.moved[a] > start_ || work_.moved[b] > start_) {
        deepest = std::max(deepest, measure(i));
      } else {
        work_.evaluated[i] = ++work_.clock;  // as measure() would stamp it
        deepest = std::max(deepest, work_.depth[i]);
      }
    }
    return deepest;
  }

  // Each body's manifolds (counting sort), then the manifolds stale after the first sweep: those
  // with a body it moved at or after their measurement (moved >= evaluated, as the clocks say).
  void list_stale() {
    const std::size_t bodies = s_.position.size();
    const std::size_t nm = manifolds_.size();
    work_.body_first.assign(bodies + 1, 0);
    for (std::size_t e = 0; e < 2 * nm; ++e) ++work_.body_first[static_cast<std::size_t>(work_.ends[e]) + 1];
    for (std::size_t b = 0; b < bodies; ++b) work_.body_first[b + 1] += work_.body_first[b];
    resize_with_headroom(work_.body_manifolds, 2 * nm);
    for (std::size_t e = 0; e < 2 * nm; ++e)
      work_.body_manifolds[static_cast<std::size_t>(work_.body_first[static_cast<std::size_t>(work_.ends[e])]++)] =
          static_cast<std::int32_t>(e / 2);
    for (std::size_t b = bodies; b > 0; --b) work_.body_first[b] = work_.body_first[b - 1];  // back to the starts
    work_.body_first[0] = 0;
    words_ = (nm + 63) / 64;
    resize_with_headroom(work_.stale, words_);
    std::fill(work_.stale.begin(), work_.stale.begin() + static_cast<std::ptrdiff_t>(words_), 0);
    for (const std::int32_t body : work_.moved_bodies) {
      const auto b = static_cast<std::size_t>(body);
      for (std::int32_t k = work_.body_first[b]; k < work_.body_first[b + 1]; ++k) {
        const auto i = static_cast<std::size_t>(work_.body_manifolds[static_cast<std::size_t>(k)]);
        if (work_.moved[b] >= work_.evaluated[i]) work_.stale[i / 64] |= std::uint64_t{1} << (i % 64);
      }
    }
  }

  // A later sweep: the stale manifolds in ascending order; returns the deepest gap of all.
  double later_sweep() {
    for (std::size_t w = 0; w < words_; ++w) {
      // The word is read again after each measure: marks set in it ahead of the one measured
      // are this sweep's; those behind it wait for the next.
      std::uint64_t ahead = ~std::uint64_t{0};
      while (const std::uint64_t bits = work_.stale[w] & ahead) {
        const int j = std::countr_zero(bits);
        const std::uint64_t bit = std::uint64_t{1} << j;
        work_.stale[w] &= ~bit;
        ahead = j == 63 ? 0 : ~std::uint64_t{0} << (j + 1);
        measure(64 * w + static_cast<std::size_t>(j));
      }
    }
    // The deepest gap of every manifold: those not measured keep theirs (max is exact in any order).
    double deepest = 0.0;
    for (std::size_t i = 0; i < manifolds_.size(); ++i) deepest = std::max(deepest, work_.depth[i]);
    return deepest;
  }

  std::span<const Manifold> manifolds_;
  BodyArrays& s_;
  const NativeSettings& settings_;
  ProjectionWork& work_;
  const std::uint64_t start_;  // the clock at the call's start
  bool marking_ = false;       // after the first sweep: moves mark their manifolds stale
  std::size_t words_ = 0;      // of the stale bits
};

}  // namespace

double solve_positions(std::span<const Manifold> manifolds, BodyArrays& bodies, const NativeSettings& settings,
                       ProjectionWork& work) {
  return Projection(manifolds, bodies, settings, work).solve();
}

}  // namespace floedem
