// Sea-surface tilt, the pressure gradient that drives a geostrophic current (docs/model.md 2;
// Bigg et al. 1997): F = m (dV_w/dt + f k x V_w), with V_w the current averaged over the
// body's draft. A steady current gives F = m f k x V_w, computed once; a current that changes
// in time (tides, a series: uniform over the scene and over depth) adds its change and its
// rate at each step. In a geographic scene f is each body's own, at its centroid
// (coriolis_field.hpp).
#include "forcing/coriolis_field.hpp"
#include "forcing/flow_grid.hpp"
#include "forcing/force_term.hpp"

namespace floedem {

namespace {

class SeaSurfaceTilt final : public ForceTerm {
 public:
  explicit SeaSurfaceTilt(const Scene& scene) : environment_(scene.environment) {
    const EnvironmentSpec& env = scene.environment;
    varies_ = env.current_varies();
    const bool geographic = scene.geo.present;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      if (b.fixed) continue;
      const Vec2 v = draft_mean(b, env);
      const Vec2 f = (b.mass * env.coriolis_parameter) * cross(1.0, v);
      if (varies_ || f != Vec2{} || (geographic && v != Vec2{})) entries_.push_back({i, f, v, &b});
    }
  }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return "sea_surface_tilt"; }
  bool add_rate_bound(const BodyStatesView&, ForceSums&) const override { return true; }  // no Jacobian
  void add(const BodyStatesView& state, double time, ForceSums& sums) const override {
    if (!varies_) {
      if (coriolis_)
        for (const Entry& e : entries_)
          sums.add_force(e.body, (e.spec->mass * coriolis_->at(state.position[e.body])) * cross(1.0, e.current), 0.0);
      else
        for (const Entry& e : entries_) sums.add_force(e.body, e.force, 0.0);
      return;
    }
    const Vec2 change = environment_.current_change(time), rate = environment_.current_change_rate(time);
    for (const Entry& e : entries_) {
      Vec2 v, dv = rate;
      if (grid_) {  // the grid's current at the body's centroid, over its draft
        const Vec2 x = state.position[e.body];
        v = draft_mean(*e.spec, environment_, [&](double depth) { return change + grid_->at(x, depth); });
        // A grid without depth: its rate at the centroid as it is (a record's slope, to the bit).
        dv = rate + (grid_->spec().depth.empty()
                         ? grid_->rate_at(x, 0.0)
                         : draft_mean(*e.spec, EnvironmentSpec{}, [&](double depth) { return grid_->rate_at(x, depth); }));
      } else {
        v = draft_mean(*e.spec, environment_, [&](double) { return change; });
      }
      const double f = coriolis_ ? coriolis_->at(state.position[e.body]) : environment_.coriolis_parameter;
      sums.add_force(e.body, (e.spec->mass * f) * cross(1.0, v) + e.spec->mass * dv, 0.0);
    }
  }
  void attach_fields(const FlowFields& fields) override {
    grid_ = fields.current.get();
    coriolis_ = fields.coriolis.get();
  }

 private:
  /// The current averaged over the body's draft (16 samples a keel layer), plus `change` at
  /// every sample where given: sample by sample, so that a change added to a zero current
  /// gives the steady current's average to the bit (a steady series and a steady current
  /// then drive the same run). No draft: the surface current.
  template <class Change>
  static Vec2 draft_mean(const BodySpec& b, const EnvironmentSpec& env, Change change) {
    Vec2 mean;
    double total = 0.0;
    for (const KeelLayer& k : b.keel) {
      const int n = 16;
      for (int j = 0; j < n; ++j) {
        const double h = (k.bottom - k.top) / n;
        const double depth = k.top + (j + 0.5) * h;
        mean += h * (env.current_at(depth) + change(depth));
        total += h;
      }
    }
    if (total > 0.0) return (1.0 / total) * mean;
    return env.current + change(0.0);
  }
  /// The steady current's average: its samples plus +0 (x + 0 = x, and a sum that starts at
  /// +0 takes -0 as +0, so the same average to the bit).
  static Vec2 draft_mean(const BodySpec& b, const EnvironmentSpec& env) {
    return draft_mean(b, env, [](double) { return Vec2{}; });
  }
  struct Entry {
    std::size_t body;
    Vec2 force;    // m f k x V_w of a steady current
    Vec2 current;  // its V_w
    const BodySpec* spec;
  };
  const EnvironmentSpec& environment_;
  const FlowGrid* grid_ = nullptr;
  const CoriolisField* coriolis_ = nullptr;
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
