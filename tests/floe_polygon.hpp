#pragma once
// A floe-like test polygon, shared by the tests (support.hpp) and the micro-benchmarks.
#include <cmath>
#include <random>
#include <vector>

#include "geometry/polygon.hpp"
#include "floedem/geometry/vec2.hpp"

namespace floedem::test {

/// A floe-like polygon about its centroid (the drag tests' and benchmarks' floes): corner k at
/// the angle 2 pi (k + 0.3 u) / corners and distance `size`, u uniform in [-1, 1) drawn from rng.
inline std::vector<Vec2> jittered_polygon(std::mt19937_64& rng, int corners, double size) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec2> poly;
  for (int k = 0; k < corners; ++k) {
    const double a = 2.0 * M_PI * (k + 0.3 * u(rng)) / corners;
    poly.push_back({size * std::cos(a), size * std::sin(a)});
  }
  const Vec2 c = area_moments(poly).centroid;
  for (Vec2& p : poly) p = p - c;
  return poly;
}

}  // namespace floedem::test
