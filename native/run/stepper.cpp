#include "run/stepper.hpp"

#include "engine/registry.hpp"

namespace floedem {

Stepper::Stepper(const Scene& scene, const std::string& engine)
    : scene_(scene), dt_(scene.run.dt), engine_(make_engine(engine, scene)), forcing_(scene), tow_(scene) {}

void Stepper::step() {
  const double start = time();
  if (tow_.active()) tow_.before_step(engine_->state(), start);
  loads_ = forcing_.evaluate(engine_->state(), start);
  engine_->step(loads_);
  if (tow_.active()) tow_.after_step(engine_->contacts(), forcing_.environment_force(scene_.tow.body));
  ++steps_;
}

bool Stepper::save(StateWriter& out) const {
  StateWriter engine;
  if (!engine_->save_state(engine)) return false;
  out.tag("stepper");
  out.value(steps_);
  out.vector(engine.bytes());
  tow_.save(out);
  return true;
}

void Stepper::restore(StateReader& in) {
  in.tag("stepper");
  in.value(steps_);
  std::vector<std::uint8_t> engine;
  in.vector(engine);
  StateReader engine_in(engine.data(), engine.size());
  engine_->restore_state(engine_in);
  if (engine_in.left() != 0) throw StateError("checkpoint: the engine's state is longer than the engine reads");
  tow_.restore(in);
}

}  // namespace floedem
