// Sea-surface tilt, the pressure gradient that drives a geostrophic current (docs/model.md 2;
// Bigg et al. 1997): F = m (dV_w/dt + f k x V_w). The current is steady here, so
// F = m f k x V_w, with V_w the current averaged over the body's draft.
#include "forcing/force_term.hpp"

namespace floedem {

namespace {

class SeaSurfaceTilt final : public ForceTerm {
 public:
  explicit SeaSurfaceTilt(const Scene& scene) {
    const EnvironmentSpec& env = scene.environment;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      if (b.fixed) continue;
      Vec2 mean;  // draft-averaged current
      double total = 0.0;
      for (const KeelLayer& k : b.keel) {
        const int n = 16;
        for (int j = 0; j < n; ++j) {
          const double h = (k.bottom - k.top) / n;
          mean += h * env.current_at(k.top + (j + 0.5) * h);
          total += h;
        }
      }
      const Vec2 v = total > 0.0 ? (1.0 / total) * mean : env.current;
      const Vec2 f = (b.mass * env.coriolis_parameter) * cross(1.0, v);
      if (f != Vec2{}) entries_.push_back({i, f});
    }
  }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return "sea_surface_tilt"; }
  bool add_rate_bound(const BodyStatesView&, ForceSums&) const override { return true; }  // no Jacobian
  void add(const BodyStatesView&, double, ForceSums& sums) const override {
    for (const Entry& e : entries_) sums.add_force(e.body, e.force, 0.0);
  }

 private:
  struct Entry {
    std::size_t body;
    Vec2 force;
  };
  std::vector<Entry> entries_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_sea_surface_tilt(const Scene& scene) {
  if (!scene.has_environment || !scene.environment.sea_surface_tilt) return nullptr;
  auto t = std::make_unique<SeaSurfaceTilt>(scene);
  return t->empty() ? nullptr : std::move(t);
}

}  // namespace floedem
