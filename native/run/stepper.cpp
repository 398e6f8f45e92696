#include "run/stepper.hpp"

#include "engine/registry.hpp"

namespace floedem {

Stepper::Stepper(const Scene& scene, const std::string& engine)
    : scene_(scene), dt_(scene.run.dt), engine_(make_engine(engine, scene)), forcing_(scene), tow_(scene) {}

void Stepper::step() {
  const double start = time();
  if (tow_.active()) tow_.before_step(engine_->state(), start);
  engine_->step(forcing_.evaluate(engine_->state(), start));
  if (tow_.active()) tow_.after_step(engine_->contacts(), forcing_.environment_force(scene_.tow.body));
  ++steps_;
}

}  // namespace floedem
