// An engine of your own, joined to floedem's cross-checks. `PointImpulseEngine` is a minimal
// rigid-body engine written against the public interface alone (floedem/engine/engine.hpp):
// semi-implicit Euler, and at most one contact point per pair of convex bodies, found by
// separating axes, with Newton's restitution and Coulomb friction solved exactly for that point.
// It is registered under the name "point-impulse" beside floedem's engines, and run with
// floedem's driver on the impact suite's head-on and oblique cases; its velocities after each
// impact are held against the native engine's.
//   own_engine [IMPACTS_DIR]   (default: the installed share/floedem/scenarios/impacts)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "floedem/engine/registry.hpp"
#include "floedem/io/output.hpp"
#include "floedem/run/simulation.hpp"
#include "floedem/scenario/scenario.hpp"
#include "floedem/scene/input_error.hpp"

using floedem::Vec2;

namespace {

class PointImpulseEngine final : public floedem::Engine {
 public:
  explicit PointImpulseEngine(const floedem::Scene& scene) : scene_(scene) {
    const std::size_t n = scene.bodies.size();
    state_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const floedem::BodySpec& b = scene.bodies[i];
      if (b.local_parts.size() != 1)
        throw floedem::InputError(scene.source_path + ": body '" + b.name + "': point-impulse takes convex bodies only");
      state_.position[i] = b.centroid;
      state_.velocity[i] = b.velocity;
      state_.angular_velocity[i] = b.angular_velocity;
      inverse_mass_.push_back(scene.engine_inverse_mass(i));  // 0 for fixed and prescribed bodies
      inverse_inertia_.push_back(scene.engine_inverse_inertia(i));
    }
  }

  void step(const floedem::Loads* loads) override {
    const double dt = scene_.run.dt;
    const std::size_t n = state_.position.size();
    // Non-contact loads, as velocity changes over the step (the forcing is computed by floedem).
    if (loads) {
      for (std::size_t i = 0; i < loads->velocity_turn.size(); ++i)
        state_.velocity[i] = loads->velocity_turn[i].apply(state_.velocity[i]);
      if (loads->any)
        for (std::size_t i = 0; i < n; ++i) {
          state_.velocity[i] += dt * inverse_mass_[i] * loads->force[i];
          state_.angular_velocity[i] += dt * inverse_inertia_[i] * loads->torque[i];
        }
      for (const floedem::PrescribedMotion& p : loads->prescribed) {
        state_.velocity[static_cast<std::size_t>(p.body)] = p.velocity;
        state_.angular_velocity[static_cast<std::size_t>(p.body)] = p.angular_velocity;
      }
    }
    contacts_.clear();
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = a + 1; b < n; ++b) collide(a, b, dt);
    for (std::size_t i = 0; i < n; ++i) {
      state_.position[i] += dt * state_.velocity[i];
      state_.angle[i] += dt * state_.angular_velocity[i];
    }
  }

  const floedem::BodyStates& state() const override { return state_; }
  std::span<const floedem::ContactRecord> contacts() const override { return contacts_; }
  floedem::EngineInfo info() const override {
    return {"point-impulse", "example", {{"contact_points", "1 per pair"}},
            {"convex bodies only", "one contact point per pair: the mean of the incident vertices on the reference face"}};
  }

 private:
  std::vector<Vec2> world_polygon(std::size_t i) const {
    const floedem::Transform x{state_.position[i], floedem::Rot::from_angle(state_.angle[i])};
    std::vector<Vec2> p;
    for (const Vec2 v : scene_.bodies[i].local_parts[0]) p.push_back(x.apply(v));
    return p;
  }

  /// The separating axis of least overlap among the edge normals of `ref` against `inc`:
  /// returns the separation (< 0: overlap), the face normal (out of ref) and the face's index.
  static double least_overlap(const std::vector<Vec2>& ref, const std::vector<Vec2>& inc, Vec2& normal, std::size_t& face) {
    double best = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < ref.size(); ++k) {
      const Vec2 e = ref[(k + 1) % ref.size()] - ref[k];
      const Vec2 nk = floedem::normalized(Vec2{e.y, -e.x});  // outward for counter-clockwise ref
      double d = std::numeric_limits<double>::infinity();
      for (const Vec2 v : inc) d = std::min(d, dot(v - ref[k], nk));
      if (d > best) {
        best = d;
        normal = nk;
        face = k;
      }
    }
    return best;
  }

  void collide(std::size_t a, std::size_t b, double dt) {
    if (inverse_mass_[a] == 0.0 && inverse_mass_[b] == 0.0) return;
    const std::vector<Vec2> pa = world_polygon(a), pb = world_polygon(b);
    Vec2 na, nb;
    std::size_t fa = 0, fb = 0;
    const double sa = least_overlap(pa, pb, na, fa), sb = least_overlap(pb, pa, nb, fb);
    // Reference face on the body with the larger separation; the normal points from a to b.
    const bool a_ref = sa >= sb;
    const double separation = a_ref ? sa : sb;
    const Vec2 normal = a_ref ? na : -nb;
    const std::vector<Vec2>& ref = a_ref ? pa : pb;
    const std::vector<Vec2>& inc = a_ref ? pb : pa;
    const std::size_t face = a_ref ? fa : fb;
    // The contact point: the mean of the incident vertices within 1 mm of the deepest one
    // (a face on a face: the middle of the touching span; a corner on a face: the corner).
    const Vec2 face_normal = a_ref ? normal : -normal;
    double deepest = std::numeric_limits<double>::infinity();
    for (const Vec2 v : inc) deepest = std::min(deepest, dot(v - ref[face], face_normal));
    Vec2 point;
    int count = 0;
    for (const Vec2 v : inc)
      if (dot(v - ref[face], face_normal) <= deepest + 1e-3) {
        point += v;
        ++count;
      }
    point = (1.0 / count) * point;
    const Vec2 ra = point - state_.position[a], rb = point - state_.position[b];
    auto relative = [&] {  // velocity of b's point relative to a's
      return state_.velocity[b] + cross(state_.angular_velocity[b], rb) - state_.velocity[a] -
             cross(state_.angular_velocity[a], ra);
    };
    const Vec2 t = perp(normal);
    const double vn = dot(relative(), normal), vt = dot(relative(), t);
    // Speculative: act only when the gap closes within this step.
    if (separation > 0.0 && separation + dt * vn > 0.0) return;
    if (vn >= 0.0) return;
    // Effective-mass matrix of the point, K = sum over bodies of m^-1 I + I^-1 (r x .)(r x .):
    // K_xy = sum (m^-1 x.y + I^-1 (r x x)(r x y)) for x, y in {n, t}.
    auto k = [&](Vec2 x, Vec2 y) {
      return inverse_mass_[a] * dot(x, y) + inverse_inertia_[a] * cross(ra, x) * cross(ra, y) +
             inverse_mass_[b] * dot(x, y) + inverse_inertia_[b] * cross(rb, x) * cross(rb, y);
    };
    const double knn = k(normal, normal), knt = k(normal, t), ktt = k(t, t);
    const double e = scene_.contact.restitution, mu = scene_.contact.friction;
    // Newton's law with sticking: K [jn, jt] = [-(1 + e) vn, -vt].
    const double det = knn * ktt - knt * knt;
    double jn = (-(1.0 + e) * vn * ktt + vt * knt) / det;
    double jt = (-vt * knn + (1.0 + e) * vn * knt) / det;
    if (std::abs(jt) > mu * jn) {
      // Sliding: jt = s mu jn against the slip, and the normal row alone gives jn.
      const double s = vt > 0.0 ? -1.0 : 1.0;
      jn = -(1.0 + e) * vn / (knn + s * mu * knt);
      jt = s * mu * jn;
    }
    const Vec2 impulse = jn * normal + jt * t;  // on b; its opposite on a
    state_.velocity[a] -= inverse_mass_[a] * impulse;
    state_.angular_velocity[a] -= inverse_inertia_[a] * cross(ra, impulse);
    state_.velocity[b] += inverse_mass_[b] * impulse;
    state_.angular_velocity[b] += inverse_inertia_[b] * cross(rb, impulse);
    floedem::ContactRecord c;
    c.body_a = static_cast<std::int32_t>(a);
    c.body_b = static_cast<std::int32_t>(b);
    c.point = point;
    c.normal = normal;
    c.normal_impulse = jn;
    c.tangent_impulse = jt;
    c.approach_velocity = vn;
    c.separation = separation;
    c.kind = -vn > scene_.contact.collision_threshold ? floedem::ContactKind::collision : floedem::ContactKind::resting;
    contacts_.push_back(c);
  }

  const floedem::Scene& scene_;
  floedem::BodyStates state_;
  std::vector<double> inverse_mass_, inverse_inertia_;
  std::vector<floedem::ContactRecord> contacts_;
};

/// The velocities of both bodies after the run, read back from its output.
floedem::BodyFrame run_case(const floedem::Scene& scene, const std::string& engine, const std::string& out) {
  floedem::RunOptions options;
  options.engine = engine;
  options.output = out;
  floedem::run_scene(scene, options);
  return floedem::read_body_frame(out);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : IMPACTS_DIR;
  try {
    floedem::register_engine({"point-impulse", "example: one exact Newton-Coulomb point per pair (examples/own_engine.cpp)",
                              [](const floedem::Scene& s) { return std::make_unique<PointImpulseEngine>(s); }});
    // The cross-check: after the impact, each body's velocity within 1 mm/s of native's and its
    // rim speed (angular velocity times 10 m, the floe's side) within 1 mm/s: 0.2 % of the 0.5 m/s
    // closing speed, the tolerance of floedem's own cross-engine test.
    constexpr double kTolerance = 1e-3;  // m/s
    bool agree = true;
    for (const char* name : {"floe_floe_headon", "floe_floe_oblique"}) {
      const floedem::Scene scene = floedem::load_scenario(dir + "/" + name + ".toml");
      const floedem::BodyFrame native = run_case(scene, "native", std::string(name) + ".native.h5");
      const floedem::BodyFrame mine = run_case(scene, "point-impulse", std::string(name) + ".point-impulse.h5");
      double worst = 0.0;
      for (std::size_t i = 0; i < native.velocity.size(); ++i) {
        worst = std::max(worst, length(mine.velocity[i] - native.velocity[i]));
        worst = std::max(worst, 10.0 * std::abs(mine.angular_velocity[i] - native.angular_velocity[i]));
      }
      const bool ok = worst <= kTolerance;
      agree = agree && ok;
      std::printf("%-18s point-impulse against native: largest velocity difference %.3g m/s (tolerance %g): %s\n",
                  name, worst, kTolerance, ok ? "agrees" : "DISAGREES");
      for (std::size_t i = 0; i < native.velocity.size(); ++i)
        std::printf("  %-7s native (%.5f, %.5f) m/s %.6f rad/s   point-impulse (%.5f, %.5f) m/s %.6f rad/s\n",
                    native.names[i].c_str(), native.velocity[i].x, native.velocity[i].y, native.angular_velocity[i],
                    mine.velocity[i].x, mine.velocity[i].y, mine.angular_velocity[i]);
    }
    return agree ? 0 : 5;
  } catch (const floedem::InputError& e) {
    std::fprintf(stderr, "own_engine: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "own_engine: %s\n", e.what());
    return 1;
  }
}
