// Water skin drag on the bottom (docs/model.md 2): F = rho_w C_dw A_bottom |V_w - v| (V_w - v),
// integrated over the bottom (the waterline polygon, scaled as the lowest keel layer) in the
// current at the bottom's depth; the integral gives the rotational damping torque.
#include "forcing/drag.hpp"

namespace floedem {

std::unique_ptr<ForceTerm> build_water_skin_drag(const Scene& scene) {
  if (!scene.has_environment) return nullptr;
  const EnvironmentSpec& env = scene.environment;
  auto term = std::make_unique<DistributedDrag>("water_skin_drag", DistributedDrag::Kind::skin, env,
                                                DistributedDrag::Medium::water);
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    if (b.fixed || b.drag.water_skin == 0.0) continue;
    term->add_body(i, b.local_polygon,
                   {{env.water_density * b.drag.water_skin, b.keel.empty() ? 1.0 : b.keel.back().width_scale,
                     env.current_at(b.draft), b.draft}});
  }
  return if_used(std::move(term));
}

}  // namespace floedem
