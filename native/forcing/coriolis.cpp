// Coriolis (docs/model.md 2): F = -m f k x v, f = 2 Omega sin(latitude). Contributes its rate f
// per body; forcing.cpp turns the velocity by exactly f' dt per step (trapezoidal rule with a
// tangent-corrected rate), so the inertial circle neither grows nor drifts in phase. In a
// geographic scene (docs/geography.md) f is each body's own, at its position at the step's
// start (coriolis_field.hpp); otherwise one f for the scene, and the rotation is precomputed.
#include "forcing/coriolis_field.hpp"
#include "forcing/force_term.hpp"

namespace floedem {

namespace {

class Coriolis final : public ForceTerm {
 public:
  explicit Coriolis(const Scene& scene) : f_(scene.environment.coriolis_parameter), geographic_(scene.geo.present) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
      if (!scene.bodies[i].fixed) bodies_.push_back(i);
  }
  std::string_view name() const override { return "coriolis"; }
  bool constant_rotation_only() const override { return !geographic_; }
  bool idle_at_rest() const override { return true; }  // a rotation rate alone
  bool add_rate_bound(const BodyStatesView&, ForceSums&) const override { return true; }  // no Jacobian
  void add(const BodyStatesView& state, double, ForceSums& sums) const override {
    if (field_)
      for (const std::size_t i : bodies_) sums.rotation_rate[i] += field_->at(state.position[i]);
    else
      for (const std::size_t i : bodies_) sums.rotation_rate[i] += f_;
    sums.any_rotation = true;
  }
  void attach_fields(const FlowFields& fields) override { field_ = fields.coriolis.get(); }

 private:
  double f_;
  bool geographic_;
  const CoriolisField* field_ = nullptr;
  std::vector<std::size_t> bodies_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_coriolis(const Scene& scene) {
  if (!scene.has_environment || !scene.environment.coriolis) return nullptr;
  // One f of zero turns nothing; a geographic scene's bodies each have their own.
  if (!scene.geo.present && scene.environment.coriolis_parameter == 0.0) return nullptr;
  return std::make_unique<Coriolis>(scene);
}

}  // namespace floedem
