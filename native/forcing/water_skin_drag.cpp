// Water skin drag on the bottom (MODEL.md 2): F = rho_w C_dw A_bottom |V_w - v| (V_w - v),
// integrated over the bottom (the waterline polygon, scaled as the lowest keel layer) in the
// current at the bottom's depth; the integral gives the rotational damping torque.
#include "forcing/drag.hpp"

namespace floedem {

namespace {

class WaterSkinDrag final : public ForceTerm {
 public:
  explicit WaterSkinDrag(const Scene& scene)
      : settings_{scene.environment.rotational_damping, scene.environment.drag_reference_speed} {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodySpec& b = scene.bodies[i];
      if (b.fixed || b.drag.water_skin == 0.0) continue;
      entries_.push_back({i, scene.environment.water_density * b.drag.water_skin, area_points(b.local_polygon),
                          b.keel.empty() ? 1.0 : b.keel.back().width_scale, scene.environment.current_at(b.draft)});
    }
  }
  bool empty() const { return entries_.empty(); }
  std::string_view name() const override { return "water_skin_drag"; }
  void add(const BodyStates& s, double, ForceSums& sums) const override {
    for (const Entry& e : entries_)
      add_skin_drag(sums, e.body, e.points, e.scale, e.rho_c, e.current, s.velocity[e.body], s.angular_velocity[e.body],
                    Rot::from_angle(s.angle[e.body]), settings_);
  }

 private:
  struct Entry {
    std::size_t body;
    double rho_c;
    std::vector<AreaPoint> points;
    double scale;
    Vec2 current;
  };
  DragSettings settings_;
  std::vector<Entry> entries_;
};

}  // namespace

std::unique_ptr<ForceTerm> build_water_skin_drag(const Scene& scene) {
  if (!scene.has_environment) return nullptr;
  auto t = std::make_unique<WaterSkinDrag>(scene);
  return t->empty() ? nullptr : std::move(t);
}

}  // namespace floedem
