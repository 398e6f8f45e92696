// Rope towing (docs/model.md 6): an elastic rope from a tug moving on a prescribed path to a point
// on the iceberg. Tension T = k (L - L0) + c dL/dt when taut (L > L0) and T > 0, else 0 (a
// rope cannot push); it acts along the rope at the attachment point (force and torque).
// The rope's stiffness and damping along its direction enter the Jacobian (stiffness as
// dt k, since the stretch grows by dt times the velocity), so that a stiff rope stays stable.
#include <cmath>

#include "forcing/force_term.hpp"
#include "towing/tow.hpp"

namespace floedem {

namespace {

class RopeTow final : public ForceTerm {
 public:
  explicit RopeTow(const Scene& scene) : tow_(scene.tow), dt_(scene.run.dt) {}
  std::string_view name() const override { return "rope_tow"; }
  void add(const BodyStatesView& s, double time, ForceSums& sums) const override {
    const RopeState r = rope_state(tow_, s, time);
    if (r.tension <= 0.0) return;
    const double k = tow_.damping + dt_ * tow_.stiffness;
    // Force on the body along e; dF/du with u = tug velocity - point velocity: k e e^T.
    const std::array<double, 4> a{k * r.direction.x * r.direction.x, k * r.direction.x * r.direction.y,
                                  k * r.direction.x * r.direction.y, k * r.direction.y * r.direction.y};
    sums.add_point_force(tow_.body, r.arm, r.tension * r.direction, a, true);
  }

 private:
  const TowSpec& tow_;
  double dt_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_rope_tow(const Scene& scene) {
  if (scene.tow.mode != TowSpec::Mode::rope) return nullptr;
  return std::make_unique<RopeTow>(scene);
}

}  // namespace floedem
