// Applied load: a constant force at the centroid and a constant torque, per body
// ([[body]] applied_force, applied_torque). For pushing tests and prescribed loads.
#include "forcing/force_term.hpp"

namespace floedem {

namespace {

class AppliedLoad final : public ForceTerm {
 public:
  explicit AppliedLoad(const Scene& scene) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      if (!b.fixed && (b.applied_force != Vec2{} || b.applied_torque != 0.0))
        loaded_.push_back({i, b.applied_force, b.applied_torque});
    }
  }
  bool empty() const { return loaded_.empty(); }
  std::string_view name() const override { return "applied_load"; }
  bool add_rate_bound(const BodyStatesView&, ForceSums&) const override { return true; }  // no Jacobian
  void add(const BodyStatesView&, double, ForceSums& sums) const override {
    for (const Entry& e : loaded_) sums.add_force(e.body, e.force, e.torque);
  }

 private:
  struct Entry {
    std::size_t body;
    Vec2 force;
    double torque;
  };
  std::vector<Entry> loaded_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_applied_load(const Scene& scene) {
  auto term = std::make_unique<AppliedLoad>(scene);
  if (term->empty()) return nullptr;
  return term;
}

}  // namespace floedem
