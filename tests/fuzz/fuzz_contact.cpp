// libFuzzer target: polygon-polygon contact on arbitrary polygons. The bytes give two simple
// polygons (convex or not: concave ones go through the convex partition) and a placement;
// every pair of their convex parts goes through the narrow phase, whose manifold must be
// sane: a unit normal, at most two finite points, separations no deeper than the parts are
// wide. A crash, a hang, a failed check or a sanitizer report is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <algorithm>
#include <vector>

#include "geometry/polygon.hpp"
#include "floedem/scene/input_error.hpp"
#include "collision/overlap.hpp"
#include "collision/part_set.hpp"

namespace {

struct Bytes {
  const std::uint8_t* p;
  std::size_t n;
  std::size_t at = 0;
  bool take(std::uint8_t& v) {
    if (at >= n) return false;
    v = p[at++];
    return true;
  }
  bool take(double& v, double scale) {
    std::uint8_t lo = 0, hi = 0;
    if (!take(lo) || !take(hi)) return false;
    v = static_cast<double>(static_cast<std::int16_t>(lo | (hi << 8))) * scale;
    return true;
  }
};

bool polygon(Bytes& in, std::vector<floedem::Vec2>& out) {
  std::uint8_t count = 0;
  if (!in.take(count)) return false;
  const int n = 3 + count % 10;
  for (int k = 0; k < n; ++k) {
    floedem::Vec2 v;
    if (!in.take(v.x, 0.01) || !in.take(v.y, 0.01)) return false;
    out.push_back(v);
  }
  if (floedem::find_self_intersection(out)) return false;
  const double a = floedem::signed_area(out);
  if (!(std::abs(a) > 1e-6)) return false;
  if (a < 0.0) std::reverse(out.begin(), out.end());
  return true;
}

void check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace floedem;
  Bytes in{data, size};
  Scene scene;
  for (int b = 0; b < 2; ++b) {
    BodySpec body;
    body.name = b == 0 ? "a" : "b";
    body.thickness = 1.0;
    if (!polygon(in, body.polygon)) return 0;
    scene.bodies.push_back(body);
  }
  double angle = 0.0, dx = 0.0, dy = 0.0;
  if (!in.take(angle, 1e-3) || !in.take(dx, 0.01) || !in.take(dy, 0.01)) return 0;
  try {
    scene.derive();
  } catch (const InputError&) {
    return 0;  // a polygon that could not be split into convex parts: refused, not a crash
  }
  (void)find_overlap(scene);
  PartSet parts(scene);
  const std::vector<Vec2> position{scene.bodies[0].centroid, scene.bodies[1].centroid + Vec2{dx, dy}};
  const std::vector<Rot> rotation{Rot{}, Rot::from_angle(angle)};
  parts.place(position, rotation);
  for (std::int32_t i = 0; i < static_cast<std::int32_t>(parts.size()); ++i) {
    for (std::int32_t j = i + 1; j < static_cast<std::int32_t>(parts.size()); ++j) {
      const std::int32_t bi = parts.body()[i], bj = parts.body()[j];
      if (bi == bj) continue;
      Manifold m;
      collide(parts.geometry(i, position[bi], rotation[bi]), parts.geometry(j, position[bj], rotation[bj]), 0.05, 1e-4, m);
      check(m.point_count >= 0 && m.point_count <= 2);
      if (m.point_count == 0) continue;
      check(std::abs(length(m.normal) - 1.0) < 1e-9);
      const double depth_limit = 2.0 * (parts.radius(i) + parts.radius(j)) + 1.0;
      for (int k = 0; k < m.point_count; ++k) {
        const ManifoldPoint& p = m.points[k];
        check(std::isfinite(p.point.x) && std::isfinite(p.point.y) && std::isfinite(p.separation));
        check(p.separation <= 0.05 + 1e-9 && p.separation >= -depth_limit);
      }
    }
  }
  return 0;
}
