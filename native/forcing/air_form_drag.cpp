// Air form drag on the sail (docs/model.md 2; Bigg et al. 1997):
//   F = 1/2 rho_a C_a A_sail |V_a - v| (V_a - v),  A_sail = projected width x freeboard,
// integrated over the waterline polygon (drag.hpp), which gives its torque too.
#include "forcing/drag.hpp"

namespace floedem {

std::unique_ptr<ForceTerm> build_air_form_drag(const Scene& scene) {
  if (!scene.has_environment) return nullptr;
  const EnvironmentSpec& env = scene.environment;
  auto term = std::make_unique<DistributedDrag>("air_form_drag", DistributedDrag::Kind::form, env,
                                                DistributedDrag::Medium::air);
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    if (b.fixed || b.drag.air_form == 0.0 || b.freeboard <= 0.0 || env.air_density == 0.0) continue;
    term->add_body(i, b.local_polygon, {{0.5 * env.air_density * b.drag.air_form * b.freeboard, 1.0, env.wind}});
  }
  return if_used(std::move(term));
}

}  // namespace floedem
