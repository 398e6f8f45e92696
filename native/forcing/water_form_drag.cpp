// Water form drag on the keel (MODEL.md 2; Bigg et al. 1997):
//   F = 1/2 rho_w C_w A_keel |V_w - v| (V_w - v),  A_keel = projected width x draft,
// by keel layer (each slab of the keel in the current of its depth), integrated over the
// waterline polygon (drag.hpp), which also gives the rotational damping torque.
#include <algorithm>

#include "forcing/drag.hpp"

namespace floedem {

namespace {

struct Slab {
  double height;  ///< m
  double scale;   ///< outline scale
  Vec2 current;   ///< m/s
};

class WaterFormDrag final : public ForceTerm {
 public:
  explicit WaterFormDrag(const Scene& scene)
      : settings_{scene.environment.rotational_damping, scene.environment.drag_reference_speed} {
    const EnvironmentSpec& env = scene.environment;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      if (b.fixed || b.drag.water_form == 0.0 || b.draft <= 0.0) continue;
      Entry e{i, 0.5 * env.water_density * b.drag.water_form, edge_points(b.local_polygon), {}};
      // Split each keel layer where the current profile changes.
      for (const KeelLayer& k : b.keel) {
        std::vector<double> cuts{k.top};
        for (const CurrentLayer& c : env.current_profile)
          if (c.depth > k.top && c.depth < k.bottom) cuts.push_back(c.depth);
        cuts.push_back(k.bottom);
        for (std::size_t j = 1; j < cuts.size(); ++j)
          e.slabs.push_back({cuts[j] - cuts[j - 1], k.width_scale, env.current_at(0.5 * (cuts[j] + cuts[j - 1]))});
      }
      entries_.push_back(std::move(e));
    }
  }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return "water_form_drag"; }
  void add(const BodyStates& s, double, ForceSums& sums) const override {
    for (const Entry& e : entries_) {
      const Rot rot = Rot::from_angle(s.angle[e.body]);
      for (const Slab& slab : e.slabs)
        add_form_drag(sums, e.body, e.edges, slab.scale, e.half_rho_c * slab.height, slab.current, s.velocity[e.body],
                      s.angular_velocity[e.body], rot, settings_);
    }
  }

 private:
  struct Entry {
    std::size_t body;
    double half_rho_c;
    std::vector<EdgePoint> edges;
    std::vector<Slab> slabs;
  };
  DragSettings settings_;
  std::vector<Entry> entries_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_water_form_drag(const Scene& scene) {
  if (!scene.has_environment) return nullptr;
  auto t = std::make_unique<WaterFormDrag>(scene);
  return t->empty() ? nullptr : std::move(t);
}

}  // namespace floedem
