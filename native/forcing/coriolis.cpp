// Coriolis (docs/model.md 2): F = -m f k x v, f = 2 Omega sin(latitude). Contributes its rate f
// per body; forcing.cpp turns the velocity by exactly f' dt per step (trapezoidal rule with a
// tangent-corrected rate), so the inertial circle neither grows nor drifts in phase.
#include "forcing/force_term.hpp"

namespace floedem {

namespace {

class Coriolis final : public ForceTerm {
 public:
  explicit Coriolis(const Scene& scene) : f_(scene.environment.coriolis_parameter) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
      if (!scene.bodies[i].fixed) bodies_.push_back(i);
  }
  std::string_view name() const override { return "coriolis"; }
  bool constant_rotation_only() const override { return true; }
  bool idle_at_rest() const override { return true; }  // a rotation rate alone
  bool add_rate_bound(const BodyStatesView&, ForceSums&) const override { return true; }  // no Jacobian
  void add(const BodyStatesView&, double, ForceSums& sums) const override {
    for (const std::size_t i : bodies_) sums.rotation_rate[i] += f_;
    sums.any_rotation = true;
  }

 private:
  double f_;
  std::vector<std::size_t> bodies_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_coriolis(const Scene& scene) {
  if (!scene.has_environment || !scene.environment.coriolis || scene.environment.coriolis_parameter == 0.0)
    return nullptr;
  return std::make_unique<Coriolis>(scene);
}

}  // namespace floedem
