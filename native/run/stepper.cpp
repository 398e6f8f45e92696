#include "run/stepper.hpp"

#include <algorithm>
#include <numeric>

#include "floedem/engine/registry.hpp"
#include "geometry/polygon.hpp"

namespace floedem {

namespace {

// The bodies taken as touching on the first step, before any engine has found a contact: each
// body whose bounding box, grown by its reach in one step (|v| dt) and a centimetre, overlaps
// another's. A superset of the touching bodies (boxes, not polygons), so that a body that
// starts in contact gets its whole first step of force, as every step after (forcing.cpp).
// Boxes sorted along the axis over which the scene spreads more, then swept: each box meets
// those that start before it ends.
std::vector<std::uint8_t> touching_at_start(const Scene& scene) {
  const std::size_t n = scene.bodies.size();
  std::vector<Aabb> box(n);
  Aabb all{{1e300, 1e300}, {-1e300, -1e300}};
  for (std::size_t i = 0; i < n; ++i) {
    const BodySpec& b = scene.bodies[i];
    const double grow = length(b.velocity) * scene.run.dt + 0.01;
    box[i] = b.polygon.empty() ? Aabb{b.centroid, b.centroid} : bounds_of(b.polygon);
    box[i].lo -= Vec2{grow, grow};
    box[i].hi += Vec2{grow, grow};
    all = {{std::min(all.lo.x, box[i].lo.x), std::min(all.lo.y, box[i].lo.y)},
           {std::max(all.hi.x, box[i].hi.x), std::max(all.hi.y, box[i].hi.y)}};
  }
  const bool along_x = all.hi.x - all.lo.x >= all.hi.y - all.lo.y;
  auto lo = [&](std::size_t i) { return along_x ? box[i].lo.x : box[i].lo.y; };
  auto hi = [&](std::size_t i) { return along_x ? box[i].hi.x : box[i].hi.y; };
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return lo(a) < lo(b); });
  std::vector<std::uint8_t> touching(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = order[k];
    for (std::size_t j = k + 1; j < n && lo(order[j]) <= hi(a); ++j)
      if (box[a].overlaps(box[order[j]])) touching[a] = touching[order[j]] = 1;
  }
  return touching;
}

}  // namespace

Stepper::Stepper(const Scene& scene, const std::string& engine)
    : scene_(scene), dt_(scene.run.dt), engine_(make_engine(engine, scene)), forcing_(scene), tow_(scene) {
  if (!forcing_.empty()) touching_ = touching_at_start(scene);
  forcing_.attach_tow(tow_.line());
}

void Stepper::frame_state(BodyStates& out) const {
  const BodyStates& s = engine_->state();
  out.position.assign(s.position.begin(), s.position.end());
  out.angle.assign(s.angle.begin(), s.angle.end());
  out.velocity.assign(s.velocity.begin(), s.velocity.end());
  out.angular_velocity.assign(s.angular_velocity.begin(), s.angular_velocity.end());
  if (steps_ > 0 && !forcing_.empty()) forcing_.velocities_at_step_end(out.velocity, out.angular_velocity);
}

void Stepper::step() {
  const double start = time();
  if (tow_.active()) stages_.time(kTowing, [&] { tow_.before_step(engine_->state(), start); });
  stages_.time(kForcing, [&] {
    loads_ = forcing_.evaluate(engine_->state(), start, engine_->rotations(), touching_);
  });
  engine_->step(loads_);
  if (tow_.active())
    stages_.time(kTowing, [&] { tow_.after_step(engine_->state(), engine_->contacts(), forcing_.environment_force(scene_.tow.body)); });
  // Which bodies the next step's forcing takes as touching (a contact with an impulse in this
  // step, on any engine: Engine::contacts): their step stays first order, the others' second.
  if (!forcing_.empty()) {
    touching_.assign(engine_->state().position.size(), 0);
    for (const ContactRecord& c : engine_->contacts()) {
      touching_[static_cast<std::size_t>(c.body_a)] = 1;
      touching_[static_cast<std::size_t>(c.body_b)] = 1;
    }
  }
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
  out.tag("touching");
  out.vector(touching_);
  forcing_.save(out);
  return true;
}

void Stepper::restore(StateReader& in) {
  in.tag("stepper");
  in.value(steps_);
  engine_->restore_state(in);
  tow_.restore(in);
  in.tag("touching");
  in.vector(touching_);
  forcing_.restore(in);
}

}  // namespace floedem
