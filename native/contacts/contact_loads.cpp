#include "contacts/contact_loads.hpp"

namespace floedem {

Vec2 contact_impulse_on(std::int32_t body, std::span<const ContactRecord> contacts) {
  Vec2 impulse;
  for (const ContactRecord& c : contacts) {
    if (c.body_a != body && c.body_b != body) continue;
    const Vec2 p = c.impulse();
    if (c.body_b == body) impulse += p;
    if (c.body_a == body) impulse -= p;
  }
  return impulse;
}

ContactLoads::ContactLoads(const Scene& scene) : dt_(scene.run.dt) {
  for (const std::size_t i : scene.output.load_bodies) bodies_.push_back(static_cast<std::int32_t>(i));
  sum_.assign(bodies_.size(), Vec2{});
  row_.assign(bodies_.size(), Vec2{});
}

void ContactLoads::after_step(std::span<const ContactRecord> contacts) {
  for (std::size_t k = 0; k < bodies_.size(); ++k) sum_[k] += contact_impulse_on(bodies_[k], contacts);
  ++steps_;
}

const std::vector<Vec2>& ContactLoads::take_row() {
  // Mean force over the row's steps: the impulses' sum over the time they took.
  const double span = static_cast<double>(steps_) * dt_;
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    row_[k] = steps_ > 0 ? (1.0 / span) * sum_[k] : Vec2{};
    sum_[k] = {};
  }
  steps_ = 0;
  return row_;
}

void ContactLoads::save(StateWriter& out) const {
  out.tag("contact_loads");
  out.vector(sum_);
  out.value(steps_);
}

void ContactLoads::restore(StateReader& in) {
  in.tag("contact_loads");
  in.vector(sum_, bodies_.size(), "contact load sums");
  in.value(steps_);
}

}  // namespace floedem
