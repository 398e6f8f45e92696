// Sea-surface tilt, the pressure gradient that drives a geostrophic current (docs/model.md 2;
// Bigg et al. 1997): F = m (dV_w/dt + f k x V_w), with V_w the current averaged over the
// body's draft. A steady current gives F = m f k x V_w, computed once; a current that changes
// in time (tides, a series: uniform over the scene and over depth) adds its change and its
// rate at each step.
#include "forcing/force_term.hpp"

namespace floedem {

namespace {

class SeaSurfaceTilt final : public ForceTerm {
 public:
  explicit SeaSurfaceTilt(const Scene& scene) : environment_(scene.environment) {
    const EnvironmentSpec& env = scene.environment;
    varies_ = env.current_varies();
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      if (b.fixed) continue;
      const Vec2 v = draft_mean(b, env, nullptr);
      const Vec2 f = (b.mass * env.coriolis_parameter) * cross(1.0, v);
      if (varies_ || f != Vec2{}) entries_.push_back({i, f, &b});
    }
  }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return "sea_surface_tilt"; }
  bool add_rate_bound(const BodyStatesView&, ForceSums&) const override { return true; }  // no Jacobian
  void add(const BodyStatesView&, double time, ForceSums& sums) const override {
    if (!varies_) {
      for (const Entry& e : entries_) sums.add_force(e.body, e.force, 0.0);
      return;
    }
    const Vec2 change = environment_.current_change(time), rate = environment_.current_change_rate(time);
    for (const Entry& e : entries_) {
      const Vec2 v = draft_mean(*e.spec, environment_, &change);
      sums.add_force(e.body, (e.spec->mass * environment_.coriolis_parameter) * cross(1.0, v) + e.spec->mass * rate, 0.0);
    }
  }

 private:
  /// The current averaged over the body's draft (16 samples a keel layer), plus `change` at
  /// every sample where given: sample by sample, so that a change added to a zero current
  /// gives the steady current's average to the bit (a steady series and a steady current
  /// then drive the same run). No draft: the surface current.
  static Vec2 draft_mean(const BodySpec& b, const EnvironmentSpec& env, const Vec2* change) {
    Vec2 mean;
    double total = 0.0;
    for (const KeelLayer& k : b.keel) {
      const int n = 16;
      for (int j = 0; j < n; ++j) {
        const double h = (k.bottom - k.top) / n;
        const Vec2 c = env.current_at(k.top + (j + 0.5) * h);
        mean += h * (change ? c + *change : c);
        total += h;
      }
    }
    if (total > 0.0) return (1.0 / total) * mean;
    return change ? env.current + *change : env.current;
  }
  struct Entry {
    std::size_t body;
    Vec2 force;  // m f k x V_w of a steady current
    const BodySpec* spec;
  };
  const EnvironmentSpec& environment_;
  bool varies_ = false;
  std::vector<Entry> entries_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_sea_surface_tilt(const Scene& scene) {
  if (!scene.has_environment || !scene.environment.sea_surface_tilt) return nullptr;
  auto t = std::make_unique<SeaSurfaceTilt>(scene);
  return t->empty() ? nullptr : std::move(t);
}

}  // namespace floedem
