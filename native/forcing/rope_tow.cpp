// Rope towing (docs/model.md 6, docs/towing.md): an elastic rope from a tug to a point on the
// iceberg; the tug moves on a prescribed path (mode rope) or pulls with what it has (mode tug,
// towing/tow.cpp). Tension T = k (L - L0) + c dL/dt when taut (L > L0) and T > 0, else 0 (a
// rope cannot push), and 0 once the rope has parted; it acts along the rope at the attachment
// point (force and torque). The rope's stiffness and damping along its direction enter the
// Jacobian (stiffness as dt k, since the stretch grows by dt times the velocity), so that a
// stiff rope stays stable.
#include <cmath>
#include <stdexcept>

#include "forcing/force_term.hpp"
#include "towing/tow.hpp"

namespace floedem {

namespace {

class RopeTow final : public ForceTerm {
 public:
  explicit RopeTow(const Scene& scene)
      : tow_(scene.tow),
        water_(scene.has_environment ? &scene.environment : nullptr),
        dt_(scene.run.dt),
        own_(scene.tow),
        line_(&own_) {}
  std::string_view name() const override { return "rope_tow"; }
  void attach_tow(const TowLine& line) override { line_ = &line; }
  void add(const BodyStatesView& s, double time, ForceSums& sums) const override {
    // Mode tug's tug moves with the run (TowMonitor): a term that was never handed the run's
    // line would pull from where the tug started, for ever.
    if (tow_.mode == TowSpec::Mode::tug && line_ == &own_)
      throw std::logic_error("rope_tow: mode tug needs the run's tow line (Forcing::attach_tow)");
    const RopeState r = rope_state(tow_, *line_, water_, s, time);
    if (r.tension <= 0.0) return;
    const double k = tow_.damping + dt_ * tow_.stiffness;
    // Force on the body along e; dF/du with u = tug velocity - point velocity: k e e^T.
    const std::array<double, 4> a{k * r.direction.x * r.direction.x, k * r.direction.x * r.direction.y,
                                  k * r.direction.x * r.direction.y, k * r.direction.y * r.direction.y};
    sums.add_point_force(tow_.body, r.arm, r.tension * r.direction, a, true);
  }

 private:
  const TowSpec& tow_;
  const EnvironmentSpec* water_;
  double dt_;
  TowLine own_;  ///< mode rope without a run (the tug on its path, the rope whole)
  const TowLine* line_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_rope_tow(const Scene& scene) {
  if (!scene.tow.has_rope()) return nullptr;
  return std::make_unique<RopeTow>(scene);
}

}  // namespace floedem
