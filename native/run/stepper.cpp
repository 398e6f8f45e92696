#include "run/stepper.hpp"

#include "floedem/engine/registry.hpp"

namespace floedem {

Stepper::Stepper(const Scene& scene, const std::string& engine)
    : scene_(scene), dt_(scene.run.dt), engine_(make_engine(engine, scene)), forcing_(scene), tow_(scene) {}

void Stepper::step() {
  const double start = time();
  if (tow_.active()) stages_.time(kTowing, [&] { tow_.before_step(engine_->state(), start); });
  stages_.time(kForcing, [&] { loads_ = forcing_.evaluate(engine_->state(), start, engine_->rotations()); });
  engine_->step(loads_);
  if (tow_.active())
    stages_.time(kTowing, [&] { tow_.after_step(engine_->contacts(), forcing_.environment_force(scene_.tow.body)); });
  ++steps_;
}

void Stepper::time_stages(bool on) {
  stages_.enable(on);
  engine_->time_stages(on);
}

std::vector<StageTime> Stepper::stage_times() const {
  std::vector<StageTime> own, out;
  stages_.add_to(own);
  out.push_back(own[kForcing]);
  engine_->add_stage_times(out);
  out.push_back(own[kTowing]);
  return out;
}

bool Stepper::save(StateWriter& out) const {
  const std::size_t start = out.size();
  out.tag("stepper");
  out.value(steps_);
  if (!engine_->save_state(out)) {
    out.truncate(start);
    return false;
  }
  tow_.save(out);  // its tag also tells, on reading, where the engine's state must have ended
  return true;
}

void Stepper::restore(StateReader& in) {
  in.tag("stepper");
  in.value(steps_);
  engine_->restore_state(in);
  tow_.restore(in);
}

}  // namespace floedem
