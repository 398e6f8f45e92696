#pragma once
// Plane vectors and rotations. The plane is (x, y), z points up, angles are counter-clockwise.
#include <bit>
#include <cmath>
#include <cstdint>

namespace floedem {

/// Whether x and y are the same double to the bit: == takes -0 for +0 (a sign a later result
/// can keep) and a NaN for nothing, so the shortcuts that keep a result when its inputs have
/// not changed compare so.
inline bool same_bits(double x, double y) { return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y); }

struct Vec2 {
  double x = 0.0;
  double y = 0.0;

  constexpr Vec2() = default;
  constexpr Vec2(double x_, double y_) : x(x_), y(y_) {}

  constexpr Vec2& operator+=(Vec2 o) { x += o.x; y += o.y; return *this; }
  constexpr Vec2& operator-=(Vec2 o) { x -= o.x; y -= o.y; return *this; }
  constexpr Vec2& operator*=(double s) { x *= s; y *= s; return *this; }
  friend constexpr bool operator==(Vec2, Vec2) = default;
};

constexpr Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
constexpr Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
constexpr Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
constexpr Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
constexpr Vec2 operator*(Vec2 a, double s) { return {s * a.x, s * a.y}; }

constexpr double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
/// z component of the 3-D cross product a x b.
constexpr double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
/// w k x r: the velocity of point r on a body spinning at w about the origin.
constexpr Vec2 cross(double w, Vec2 r) { return {-w * r.y, w * r.x}; }
/// Left perpendicular (k x a).
constexpr Vec2 perp(Vec2 a) { return {-a.y, a.x}; }
/// sqrt(x^2 + y^2) directly: hypot guards against overflow above 1e154, which no physical
/// quantity here reaches, at several times the cost (it was a tenth of a step).
inline double length(Vec2 a) { return std::sqrt(a.x * a.x + a.y * a.y); }
constexpr double length_squared(Vec2 a) { return dot(a, a); }
inline Vec2 normalized(Vec2 a) {
  const double l = length(a);
  return l > 0.0 ? Vec2{a.x / l, a.y / l} : Vec2{};
}

/// A rotation by angle q, stored as (cos q, sin q).
struct Rot {
  double c = 1.0;
  double s = 0.0;
  static Rot from_angle(double q) { return {std::cos(q), std::sin(q)}; }
  constexpr Vec2 apply(Vec2 v) const { return {c * v.x - s * v.y, s * v.x + c * v.y}; }
  constexpr Vec2 apply_inverse(Vec2 v) const { return {c * v.x + s * v.y, -s * v.x + c * v.y}; }
};

/// Rigid placement of a body: centroid position and rotation.
struct Transform {
  Vec2 p;
  Rot q;
  constexpr Vec2 apply(Vec2 local) const { return p + q.apply(local); }
  constexpr Vec2 apply_inverse(Vec2 world) const { return q.apply_inverse(world - p); }
};

struct Aabb {
  Vec2 lo;
  Vec2 hi;
  constexpr bool overlaps(const Aabb& o) const {
    return lo.x <= o.hi.x && o.lo.x <= hi.x && lo.y <= o.hi.y && o.lo.y <= hi.y;
  }
  /// overlaps() with all four comparisons made (no short-circuit), the same answer: for a loop
  /// that counts overlaps without a branch on the data (PairCache::find_pairs).
  constexpr bool overlaps_unbranched(const Aabb& o) const {
    return (lo.x <= o.hi.x) & (o.lo.x <= hi.x) & (lo.y <= o.hi.y) & (o.lo.y <= hi.y);
  }
};

}  // namespace floedem
