#include <algorithm>

#include "forcing/force_term.hpp"

namespace floedem {

namespace {
// Every term floedem has, in the order they are added.
constexpr ForceTermBuilder kTerms[] = {
    build_applied_load,
};
}  // namespace

Forcing::Forcing(const Scene& scene) {
  for (const ForceTermBuilder build : kTerms)
    if (auto term = build(scene)) terms_.push_back(std::move(term));
  loads_.force.resize(scene.bodies.size());
  loads_.torque.resize(scene.bodies.size());
}

std::vector<std::string_view> Forcing::names() const {
  std::vector<std::string_view> out;
  for (const auto& t : terms_) out.push_back(t->name());
  return out;
}

const Loads* Forcing::evaluate(const BodyStates& state, double time) {
  if (terms_.empty()) return nullptr;
  std::fill(loads_.force.begin(), loads_.force.end(), Vec2{});
  std::fill(loads_.torque.begin(), loads_.torque.end(), 0.0);
  for (const auto& t : terms_) t->add(state, time, loads_);
  loads_.any = true;
  return &loads_;
}

}  // namespace floedem
