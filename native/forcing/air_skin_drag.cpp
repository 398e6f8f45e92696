// Air skin drag on the top (docs/model.md 2): F = rho_a C_da A_top |V_a - v| (V_a - v),
// integrated over the waterline polygon (drag.hpp), which gives its torque too.
#include "forcing/drag.hpp"

namespace floedem {

std::unique_ptr<ForceTerm> build_air_skin_drag(const Scene& scene) {
  if (!scene.has_environment) return nullptr;
  const EnvironmentSpec& env = scene.environment;
  auto term = std::make_unique<DistributedDrag>("air_skin_drag", DistributedDrag::Kind::skin, env,
                                                DistributedDrag::Medium::air);
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    if (b.fixed || b.drag.air_skin == 0.0 || env.air_density == 0.0) continue;
    term->add_body(i, b.local_polygon, {{env.air_density * b.drag.air_skin, 1.0, env.wind}});
  }
  return if_used(std::move(term));
}

}  // namespace floedem
