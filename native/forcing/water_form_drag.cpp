// Water form drag on the keel (docs/model.md 2; Bigg et al. 1997):
//   F = 1/2 rho_w C_w A_keel |V_w - v| (V_w - v),  A_keel = projected width x draft,
// by keel layer (each slab of the keel in the current of its depth), integrated over the
// waterline polygon (drag.hpp), which also gives the rotational damping torque.
#include "forcing/drag.hpp"

namespace floedem {

std::unique_ptr<ForceTerm> build_water_form_drag(const Scene& scene) {
  if (!scene.has_environment) return nullptr;
  const EnvironmentSpec& env = scene.environment;
  auto term = std::make_unique<DistributedDrag>("water_form_drag", DistributedDrag::Kind::form, env,
                                                DistributedDrag::Medium::water);
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    if (b.fixed || b.drag.water_form == 0.0 || b.draft <= 0.0) continue;
    const double half_rho_c = 0.5 * env.water_density * b.drag.water_form;
    // Each keel layer, split where the current profile changes.
    std::vector<DragSlab> slabs;
    for (const KeelLayer& k : b.keel) {
      std::vector<double> cuts{k.top};
      for (const CurrentLayer& c : env.current_profile)
        if (c.depth > k.top && c.depth < k.bottom) cuts.push_back(c.depth);
      cuts.push_back(k.bottom);
      for (std::size_t j = 1; j < cuts.size(); ++j)
        slabs.push_back({half_rho_c * (cuts[j] - cuts[j - 1]), k.width_scale, env.current_at(0.5 * (cuts[j] + cuts[j - 1])),
                         0.5 * (cuts[j] + cuts[j - 1])});
    }
    term->add_body(i, b.local_polygon, std::move(slabs));
  }
  return if_used(std::move(term));
}

}  // namespace floedem
