// Wave radiation force (docs/model.md 2; Bigg et al. 1997): F = 1/2 rho_w C_r g a^2 L along the
// wave direction, L the waterline length facing the waves: the polygon's width normal to
// the wave direction, measured each step on the turned polygon. Applied at the centroid.
#include <algorithm>
#include <cmath>

#include "forcing/force_term.hpp"

namespace floedem {

namespace {

class WaveRadiation final : public ForceTerm {
 public:
  explicit WaveRadiation(const Scene& scene) {
    const EnvironmentSpec& env = scene.environment;
    direction_ = {std::cos(env.waves.direction), std::sin(env.waves.direction)};
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      const double k = 0.5 * env.water_density * b.drag.wave_radiation * env.gravity * env.waves.amplitude * env.waves.amplitude;
      if (b.fixed || k == 0.0) continue;
      entries_.push_back({i, k, b.local_polygon});
    }
  }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return "wave_radiation"; }
  bool add_rate_bound(const BodyStatesView&, ForceSums&) const override { return true; }  // no Jacobian
  void add(const BodyStatesView&, double, ForceSums& sums) const override {
    for (const Entry& e : entries_) {
      // Facing length = extent of the polygon across the wave direction.
      const Vec2 across = sums.rotation[e.body].apply_inverse(perp(direction_));
      double lo = 1e300, hi = -1e300;
      for (const Vec2 p : e.polygon) {
        lo = std::min(lo, dot(p, across));
        hi = std::max(hi, dot(p, across));
      }
      sums.add_force(e.body, (e.k * (hi - lo)) * direction_, 0.0);
    }
  }

 private:
  struct Entry {
    std::size_t body;
    double k;  ///< 1/2 rho_w C_r g a^2
    std::vector<Vec2> polygon;
  };
  Vec2 direction_;
  std::vector<Entry> entries_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_wave_radiation(const Scene& scene) {
  if (!scene.has_environment || !scene.environment.waves.present) return nullptr;
  auto t = std::make_unique<WaveRadiation>(scene);
  return t->empty() ? nullptr : std::move(t);
}

}  // namespace floedem
