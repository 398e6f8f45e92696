#pragma once
// The coloured sweeps' unit of work: up to four manifolds of one colour, lane by lane
// (coloured_sweeps.hpp says why and how it is swept).
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "engine/cache_line.hpp"
#include "floedem/geometry/vec2.hpp"

namespace floedem {

inline constexpr int kBundleLanes = 4;
/// The NNCG values of a bundle (change, direction or step): per point, n then t, four lanes each.
inline constexpr std::size_t kBundleNncg = 2 * 2 * kBundleLanes;

/// One contact point of each of a bundle's manifolds, lane by lane: what the sweeps read and
/// write ten times a step. The Delassus block and the local solve's reciprocals are made from
/// these and the bundle's normal and inverse masses as each point is swept (coloured_sweeps.cpp).
struct BundlePoint {
  double rax[kBundleLanes], ray[kBundleLanes], rbx[kBundleLanes], rby[kBundleLanes];  ///< lever arms
  double target[kBundleLanes];  ///< m/s; -inf where the lane has no such point (no impulse ever)
  double normal_impulse[kBundleLanes], tangent_impulse[kBundleLanes];  ///< accumulated, N s
};

/// Up to four manifolds of one colour (no two share a moving body), structure of arrays. An
/// empty lane reads lane 0's bodies, has zero inverse masses (never written back) and no impulse.
/// 768 bytes: 192 a manifold against two 112-byte rows in pair order.
struct alignas(kCacheLine) SweepBundle {
  std::int32_t body_a[kBundleLanes], body_b[kBundleLanes];
  std::int32_t manifold[kBundleLanes];  ///< each lane's manifold (its place in the solve), -1 if none
  std::int32_t points = 0;  ///< 1 or 2: the most points of its manifolds
  double nx[kBundleLanes], ny[kBundleLanes];  ///< normal, a to b
  double friction[kBundleLanes];
  double ma[kBundleLanes], ia[kBundleLanes], mb[kBundleLanes], ib[kBundleLanes];  ///< 1/m, 1/I; 0: not written
  BundlePoint point[2];
};
static_assert(sizeof(SweepBundle) == 768);

/// NNCG's values of one moving body of a coloured solve: its velocity when the last sweep
/// began, and the velocity that the conjugate direction p carries (M^-1 J^T p: the step beta p
/// moves it by beta times this). coloured_sweeps.cpp says why the step is made per body.
struct BodyStep {
  Vec2 v0;
  double w0 = 0.0;
  Vec2 dv;
  double dw = 0.0;
};

/// Room enough for the bundles of a coloured solve of `manifolds` manifolds: a colour of k
/// manifolds takes ceil(k / 4) bundles, at most k, over 63 colours (the rest are swept as rows):
/// sum ceil(k_c / 4) <= (n + 3 * 63) / 4.
constexpr std::size_t bundles_for(std::size_t manifolds) {
  return std::min(manifolds, (manifolds + 3 * 63) / kBundleLanes);
}

}  // namespace floedem
